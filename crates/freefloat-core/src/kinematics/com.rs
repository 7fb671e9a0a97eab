use super::forward_kinematics_unchecked;
use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::model::Model;
use crate::spatial::V3;

/// Centre of mass of the whole system in the inertial frame (runs forward kinematics).
pub fn center_of_mass(m: &Model, d: &mut Data, q: &[f64]) -> Result<V3> {
    let fix = check_args(m, Some(d), &Args::q(q))?;
    Ok(with_unit_q(m, d, q, fix, |d, q| center_of_mass_unchecked(m, d, q)))
}

fn center_of_mass_unchecked(m: &Model, d: &mut Data, q: &[f64]) -> V3 {
    forward_kinematics_unchecked(m, d, q);
    center_of_mass_from_placements(m, d)
}

/// Centre of mass from the placements already in `d` (after forward kinematics).
pub(crate) fn center_of_mass_from_placements(m: &Model, d: &Data) -> V3 {
    let mut s = V3::zeros();
    for i in 0..m.nbodies() {
        let inr = &m.inertias[i];
        s += d.o_mi[i].rot * inr.h + d.o_mi[i].trans * inr.mass;
    }
    s / m.total_mass()
}
