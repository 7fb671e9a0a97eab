use crate::data::Data;
use crate::kinematics::{forward_kinematics, world_composite_inertias};
use crate::model::Model;
use crate::spatial::Motion;

/// Joint-space inertia matrix by the composite-rigid-body algorithm, into `d.mass_matrix` (full,
/// symmetric). Works in inertial-frame coordinates: composite inertias of subtrees add without a
/// change of frame, and entry (j, i) for an ancestor j of i is `oSⱼᵀ oIcᵢ oSᵢ` with no force
/// transport along the path.
pub fn crba(m: &Model, d: &mut Data, q: &[f64]) {
    forward_kinematics(m, d, q);
    world_composite_inertias(m, d);
    let n = m.nbodies();
    d.mass_matrix.fill(0.0);
    for i in 0..n {
        let ni = m.nvs[i];
        let ci = m.idx_v[i];
        for c in 0..ni {
            let f = d.ic[i].mul_motion(&Motion::from_v6(&d.os[i].column(c).into_owned())).to_v6();
            let mut j = Some(i);
            while let Some(jj) = j {
                let cj = m.idx_v[jj];
                for r in 0..m.nvs[jj] {
                    let x = d.os[jj].column(r).dot(&f);
                    d.mass_matrix[(cj + r, ci + c)] = x;
                    d.mass_matrix[(ci + c, cj + r)] = x;
                }
                j = m.parents[jj];
            }
        }
    }
}
