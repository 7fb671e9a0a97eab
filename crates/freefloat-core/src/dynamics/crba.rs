use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::kinematics::{forward_kinematics_unchecked, world_composite_inertias_unchecked};
use crate::model::Model;
use crate::spatial::Motion;

/// Joint-space inertia matrix by the composite-rigid-body algorithm, into `d.mass_matrix` (full,
/// symmetric). Works in inertial-frame coordinates: composite inertias of subtrees add without a
/// change of frame, and entry (j, i) for an ancestor j of i is `oSⱼᵀ oIcᵢ oSᵢ` with no force
/// transport along the path.
/// Checks `q` and that `d` belongs to `m`.
pub fn crba(m: &Model, d: &mut Data, q: &[f64]) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::q(q))?;
    d.ensure_mass_matrix(m)?;
    with_unit_q(m, d, q, fix, |d, q| crba_unchecked(m, d, q));
    Ok(())
}

/// `crba` without the argument check; `d.mass_matrix` must be nv × nv (`Data::ensure_mass_matrix`).
pub(crate) fn crba_unchecked(m: &Model, d: &mut Data, q: &[f64]) {
    forward_kinematics_unchecked(m, d, q);
    world_composite_inertias_unchecked(m, d);
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
