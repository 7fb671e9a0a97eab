use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::kinematics::{forward_kinematics_unchecked, world_composite_inertias_unchecked};
use crate::model::{JointType, Model};
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

/// `crba` without the argument check (allocates `d.mass_matrix` infallibly if `crba` has not).
pub(crate) fn crba_unchecked(m: &Model, d: &mut Data, q: &[f64]) {
    forward_kinematics_unchecked(m, d, q);
    world_composite_inertias_unchecked(m, d);
    let n = m.nbodies();
    let nv = m.nv;
    if d.mass_matrix.shape() != (nv, nv) {
        // Internal callers (derivatives, post-capture control) come here without `crba`'s fallible allocation; the
        // writes below rely on the nv × nv shape, so make sure of it.
        d.mass_matrix = nalgebra::DMatrix::zeros(nv, nv);
    }
    d.mass_matrix.fill(0.0);
    let mm = d.mass_matrix.as_mut_slice();
    // Entry (r, c) of the column-major nv × nv matrix. SAFETY: every index below is idx_v[j] + k with k < nvs[j],
    // and the model's layout guarantees idx_v[j] + nvs[j] <= nv; the caller made the matrix nv × nv.
    let mut put = |r: usize, c: usize, x: f64| unsafe {
        *mm.get_unchecked_mut(c * nv + r) = x;
        *mm.get_unchecked_mut(r * nv + c) = x;
    };
    let free_root = m.joint_types[0] == JointType::Free;
    for i in 0..n {
        let ni = m.nvs[i];
        let ci = m.idx_v[i];
        if i == 0 && free_root {
            // Base block: X₀ᵀ oIc₀ X₀ is the whole system's inertia in base coordinates, one change of frame of
            // the composite inertia instead of six columns of 6×6 work.
            let ib = d.ic[0].transformed(&d.o_mi[0].inverse()).to_matrix();
            for c in 0..6 {
                for r in 0..6 {
                    put(ci + r, ci + c, ib[(r, c)]);
                }
            }
            continue;
        }
        for c in 0..ni {
            let f = d.ic[i].mul_motion(&Motion::from_v6(&d.os[i].column(c).into_owned()));
            let f6 = f.to_v6();
            let mut j = Some(i);
            while let Some(jj) = j {
                let cj = m.idx_v[jj];
                if jj == 0 && free_root {
                    // oS₀ = X₀: X₀ᵀ f is f expressed in base coordinates (a force transform, not 6 dot products)
                    let fb = d.o_mi[0].inv_act_force(&f).to_v6();
                    for r in 0..6 {
                        put(cj + r, ci + c, fb[r]);
                    }
                    break;
                }
                for r in 0..m.nvs[jj] {
                    put(cj + r, ci + c, d.os[jj].column(r).dot(&f6));
                }
                j = m.parents[jj];
            }
        }
    }
}
