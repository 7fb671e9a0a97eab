use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::kinematics::{joint_placement_at, joint_sin_cos, subspace_column_at};
use crate::model::{JointType, Model};
use crate::spatial::{Motion, Se3, V3};

/// Joint-space inertia matrix by the composite-rigid-body algorithm, into `d.mass_matrix` (full,
/// symmetric). Works in one frame for every body (the inertial frame, or the base frame under a free root):
/// composite inertias of subtrees add without a change of frame, and entry (j, i) for an ancestor j of i is
/// `oSⱼᵀ oIcᵢ oSᵢ` with no force transport along the path. Under a free root, `d.o_mi` is left holding
/// placements relative to the base (see `crba_unchecked`): call `forward_kinematics` for world placements.
/// Checks `q` and that `d` belongs to `m`.
pub fn crba(m: &Model, d: &mut Data, q: &[f64]) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::q(q))?;
    d.ensure_mass_matrix(m)?;
    with_unit_q(m, d, q, fix, |d, q| crba_unchecked(m, d, q));
    Ok(())
}

/// `crba` without the argument check (allocates `d.mass_matrix` infallibly if `crba` has not).
///
/// One pass root to leaves (placements, each body's inertia oIᵢ and joint subspace oSᵢ in one common frame), one
/// pass leaves to root: body i's composite inertia oIcᵢ is complete when its turn comes (children have larger
/// indices and were added already), its columns Fᵢ = oIcᵢ oSᵢ are formed once, and entry (j, i) for i and each
/// ancestor j is oSⱼᵀ Fᵢ (Featherstone, RBDA §6.2, Table 6.2, in one frame for all bodies: no force transport along
/// the path).
///
/// The common frame is the inertial one, except under a free root, where it is the base frame: with the base
/// twist in base coordinates, M does not depend on the base placement (kinetic energy is unchanged by a rigid
/// motion of the whole system), so the base is put at the origin. Its inertia then needs no change of frame, the
/// base block is oIc₀ itself and the base rows of column i are Fᵢ as they are (RBDA §6.2's floating-base remark);
/// the base's children are placed by their joint alone. Leaves `d.o_mi`, `d.ic` (composite inertias) and `d.os`
/// (every joint but a free root) in that common frame. `d.li_mi` is not written (no caller reads it after the CRBA:
/// the derivatives run ABA and post-capture control runs RNEA next, both of which redo forward kinematics; the
/// Python `crba` reads only the matrix); call `forward_kinematics` for the parent-relative placements.
pub(crate) fn crba_unchecked(m: &Model, d: &mut Data, q: &[f64]) {
    let n = m.nbodies();
    let nv = m.nv;
    if d.mass_matrix.shape() != (nv, nv) {
        // Internal callers (derivatives, post-capture control) come here without `crba`'s fallible allocation; the
        // writes below rely on the nv × nv shape, so make sure of it.
        d.mass_matrix = nalgebra::DMatrix::zeros(nv, nv);
    }
    // The model's per-body vectors have n entries (the builder makes them so), as in `forward_kinematics`: said
    // once, it lets the compiler drop the bounds checks of the forward sweep (the helpers index them by i < n).
    // Data's per-body buffers as n-entry slices keep their lengths in registers instead of re-reading them after
    // every store.
    assert!(
        m.parents.len() == n
            && m.idx_q.len() == n
            && m.nqs.len() == n
            && m.nvs.len() == n
            && m.joint_types.len() == n
            && m.placements.len() == n
            && m.axes.len() == n
            && m.axes2.len() == n
            && m.inertias.len() == n
            && m.principal_revolute().len() == n
    );
    let free_root = n > 0 && m.joint_types[0] == JointType::Free;
    {
        let (o_mi, ic, os, s) = (&mut d.o_mi[..n], &mut d.ic[..n], &mut d.os[..n], &mut d.s[..n]);
        let sc = &mut d.joint_sc[..n];
        joint_sin_cos(m, q, sc);
        for i in 0..n {
            if i == 0 && free_root {
                o_mi[0] = Se3::identity();
                ic[0] = m.inertias[0];
                continue;
            }
            // (revolute joints about a principal axis of their frame take the specialised rotation and subspace
            // column inside `joint_placement_at` and `subspace_column_at`, as forward kinematics and ABA do)
            let li = joint_placement_at(m, &mut s[i], i, q, sc[i]);
            let o = match m.parents[i] {
                Some(0) if free_root => li,
                Some(p) => o_mi[p].compose(&li),
                None => li,
            };
            o_mi[i] = o;
            // the subspace columns before the inertia: formed while `o` is still in registers (the other order
            // spills it and reloads it, about 25 instructions a body on naveen_dual_arm_consistent, callgrind)
            for c in 0..m.nvs[i] {
                let sc = subspace_column_at(m, &o, &s[i], i, c);
                os[i].set_column(c, &sc.to_v6());
            }
            ic[i] = m.inertias[i].transformed(&o);
        }
    }
    // Entries of bodies that are not on one path from the root are zero; the sweep writes all the others. Filled
    // as a slice (a memset): nalgebra's matrix `fill` compiles to a strided loop of about 12 instructions per entry,
    // a fifth of this function's instructions on `naveen_dual_arm` (callgrind).
    d.mass_matrix.as_mut_slice().fill(0.0);
    let (os, ic) = (&d.os, &mut d.ic);
    let mm = d.mass_matrix.as_mut_slice();
    assert!(
        mm.len() == nv * nv
            && m.idx_v.len() >= n
            && m.nvs.len() >= n
            && m.parents.len() >= n
            && os.len() >= n
            && ic.len() >= n
    );
    // Entry (r, c) and (c, r) of the column-major nv × nv matrix. SAFETY: every index below is idx_v[j] + k with
    // k < nvs[j], and the model builder guarantees idx_v[j] + nvs[j] <= nv; the matrix is nv × nv (asserted).
    let mut put = |r: usize, c: usize, x: f64| unsafe {
        *mm.get_unchecked_mut(c * nv + r) = x;
        *mm.get_unchecked_mut(r * nv + c) = x;
    };
    for i in (0..n).rev() {
        // SAFETY (all `get_unchecked` below): i < n and every j visited is i or an ancestor of i, so j < n (the
        // builder orders bodies with parents[j] < j), and the per-body vectors have n entries (asserted above).
        // body i's composite inertia, borrowed beside its ancestors' (all of smaller index): no copy of it
        let (ic_anc, ic_rest) = ic.split_at_mut(i);
        let ici = &ic_rest[0];
        if i == 0 && free_root {
            // Base block: oIc₀ is the whole system's inertia, already in base coordinates.
            let ib = ici.to_matrix();
            for c in 0..6 {
                for r in 0..6 {
                    put(r, c, ib[(r, c)]);
                }
            }
            break;
        }
        let (ci, nvi, si) = unsafe { (*m.idx_v.get_unchecked(i), *m.nvs.get_unchecked(i), os.get_unchecked(i)) };
        for c in 0..nvi {
            let sc = si.fixed_view::<6, 1>(0, c);
            let f = ici.mul_motion(&Motion::new(V3::new(sc[0], sc[1], sc[2]), V3::new(sc[3], sc[4], sc[5])));
            let col = ci + c;
            let mut j = i;
            loop {
                if j == 0 && free_root {
                    // oS₀ is the identity in base coordinates: the base rows are F itself
                    for r in 0..3 {
                        put(r, col, f.lin[r]);
                        put(3 + r, col, f.ang[r]);
                    }
                    break;
                }
                let (sj, cj, nvj) =
                    unsafe { (os.get_unchecked(j), *m.idx_v.get_unchecked(j), *m.nvs.get_unchecked(j)) };
                for r in 0..nvj {
                    let s = sj.fixed_view::<6, 1>(0, r);
                    let sr = Motion::new(V3::new(s[0], s[1], s[2]), V3::new(s[3], s[4], s[5]));
                    put(cj + r, col, sr.dot(&f));
                }
                match unsafe { *m.parents.get_unchecked(j) } {
                    Some(p) => j = p,
                    None => break,
                }
            }
        }
        if let Some(p) = unsafe { *m.parents.get_unchecked(i) } {
            // SAFETY: the builder orders bodies with parents[i] < i, and ic_anc has i entries.
            let icp = unsafe { ic_anc.get_unchecked_mut(p) };
            *icp = icp.add(ici);
        }
    }
}
