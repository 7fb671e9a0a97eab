use super::forward_kinematics;
use crate::data::Data;
use crate::model::Model;
use crate::spatial::V3;

/// Centre of mass of the whole system in the inertial frame (runs forward kinematics).
pub fn center_of_mass(m: &Model, d: &mut Data, q: &[f64]) -> V3 {
    forward_kinematics(m, d, q);
    let mut s = V3::zeros();
    for i in 0..m.nbodies() {
        let inr = &m.inertias[i];
        s += d.o_mi[i].rot * inr.h + d.o_mi[i].trans * inr.mass;
    }
    s / m.total_mass()
}
