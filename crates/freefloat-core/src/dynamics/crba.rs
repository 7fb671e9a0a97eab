use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::kinematics::{forward_kinematics_unchecked, world_subspace_column};
use crate::model::{JointType, Model};
use crate::spatial::{Motion, V3};

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
///
/// One pass root to leaves (placements, each body's inertia oIᵢ and joint subspace oSᵢ in inertial coordinates),
/// one pass leaves to root: body i's composite inertia oIcᵢ is complete when its turn comes (children have larger
/// indices and were added already), its columns Fᵢ = oIcᵢ oSᵢ are formed once, and entry (j, i) for i and each
/// ancestor j is oSⱼᵀ Fᵢ (Featherstone, RBDA §6.2, Table 6.2, in inertial coordinates: no force transport along
/// the path). Leaves `d.ic` holding the composite inertias, as `world_composite_inertias` does; `d.os` is written
/// for every joint but a free root (whose oS is the base placement itself, used directly).
pub(crate) fn crba_unchecked(m: &Model, d: &mut Data, q: &[f64]) {
    forward_kinematics_unchecked(m, d, q);
    let n = m.nbodies();
    let nv = m.nv;
    if d.mass_matrix.shape() != (nv, nv) {
        // Internal callers (derivatives, post-capture control) come here without `crba`'s fallible allocation; the
        // writes below rely on the nv × nv shape, so make sure of it.
        d.mass_matrix = nalgebra::DMatrix::zeros(nv, nv);
    }
    let free_root = n > 0 && m.joint_types[0] == JointType::Free;
    for i in 0..n {
        d.ic[i] = m.inertias[i].transformed(&d.o_mi[i]);
        if i == 0 && free_root {
            continue;
        }
        for c in 0..m.nvs[i] {
            let s = world_subspace_column(m, d, i, c);
            d.os[i].set_column(c, &s.to_v6());
        }
    }
    // Entries of bodies that are not on one path from the root are zero; the sweep writes all the others. Filled
    // as a slice (a memset): nalgebra's matrix `fill` compiles to a strided loop of about 12 instructions per entry,
    // a fifth of this function's instructions on `naveen_dual_arm` (callgrind).
    d.mass_matrix.as_mut_slice().fill(0.0);
    let (os, ic, o_mi) = (&d.os, &mut d.ic, &d.o_mi);
    let mm = d.mass_matrix.as_mut_slice();
    assert!(mm.len() == nv * nv && m.idx_v.len() >= n && m.nvs.len() >= n && m.parents.len() >= n && os.len() >= n);
    // Entry (r, c) and (c, r) of the column-major nv × nv matrix. SAFETY: every index below is idx_v[j] + k with
    // k < nvs[j], and the model builder guarantees idx_v[j] + nvs[j] <= nv; the matrix is nv × nv (asserted).
    let mut put = |r: usize, c: usize, x: f64| unsafe {
        *mm.get_unchecked_mut(c * nv + r) = x;
        *mm.get_unchecked_mut(r * nv + c) = x;
    };
    for i in (0..n).rev() {
        let ici = ic[i];
        if i == 0 && free_root {
            // Base block: X₀ᵀ oIc₀ X₀ is the whole system's inertia in base coordinates, one change of frame of
            // the composite inertia instead of six columns of 6×6 work.
            let ib = ici.transformed(&o_mi[0].inverse()).to_matrix();
            for c in 0..6 {
                for r in 0..6 {
                    put(r, c, ib[(r, c)]);
                }
            }
            break;
        }
        let ci = m.idx_v[i];
        for c in 0..m.nvs[i] {
            let s = &os[i];
            let f = ici.mul_motion(&Motion::new(
                V3::new(s[(0, c)], s[(1, c)], s[(2, c)]),
                V3::new(s[(3, c)], s[(4, c)], s[(5, c)]),
            ));
            let col = ci + c;
            let mut j = i;
            loop {
                if j == 0 && free_root {
                    // oS₀ = X₀: X₀ᵀ f is f expressed in base coordinates (a force transform, not 6 dot products)
                    let fb = o_mi[0].inv_act_force(&f);
                    for r in 0..3 {
                        put(r, col, fb.lin[r]);
                        put(3 + r, col, fb.ang[r]);
                    }
                    break;
                }
                let sj = &os[j];
                let cj = m.idx_v[j];
                for r in 0..m.nvs[j] {
                    let x = sj[(0, r)] * f.lin.x
                        + sj[(1, r)] * f.lin.y
                        + sj[(2, r)] * f.lin.z
                        + sj[(3, r)] * f.ang.x
                        + sj[(4, r)] * f.ang.y
                        + sj[(5, r)] * f.ang.z;
                    put(cj + r, col, x);
                }
                match m.parents[j] {
                    Some(p) => j = p,
                    None => break,
                }
            }
        }
        if let Some(p) = m.parents[i] {
            ic[p] = ic[p].add(&ici);
        }
    }
}
