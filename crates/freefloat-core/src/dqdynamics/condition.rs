//! Condition number of the system matrix S of (6.17) (Valverde 2018, Figs. 5.5 and 7.x).

use super::sixvec::M6;
use super::system::{solve_system, Solver};
use super::workspace::{DqData, Joint};
use crate::check::{check_args, Args};
use crate::dualquat::DualInertia;
use crate::error::Result;
use crate::model::Model;
use nalgebra::DMatrix;

/// 2-norm condition number of the thesis' system matrix S (6.17) at configuration `q` (it does not depend
/// on velocities or forces): the quantity of Figs. 5.5 and 7.x. Assembled densely from the same blocks as
/// the solve: `S11 = blkdiag(H(M_i))`, `S12 = −G`, `S21 = Gᵀ P_swap` — the thesis' matrix up to a row
/// permutation of S21 (its E-selector order), which leaves singular values unchanged. The scalar slots the
/// 6-vectors drop are decoupled rows with singular value 1 (the ones of (2.45)), folded in at the end.
/// Checks `q`. Allocates its own workspace and the dense matrix (an analysis routine, not a hot path).
pub fn condition_number(m: &Model, q: &[f64]) -> Result<f64> {
    let mut qbuf = Vec::new();
    check_args(m, None, &Args::q(q))?;
    let q = m.checked_q(q, &mut qbuf)?;
    let (v, tau) = (vec![0.0; m.nv], vec![0.0; m.nv]);
    let mut c = f64::NAN;
    let mut w = DqData::new(m);
    solve_system(m, &mut w, q, &v, &tau, None, None, None, Solver::Tree, Some(&mut c))?;
    Ok(c)
}

pub(super) fn full_system_condition(joints: &[Joint], inert: &[Option<DualInertia>], n: usize, r_total: usize) -> f64 {
    let mut boff = vec![usize::MAX; n];
    let mut nb = 0;
    for i in 0..n {
        if inert[i].is_some() {
            boff[i] = 6 * nb;
            nb += 1;
        }
    }
    let size = 6 * nb + r_total;
    let mut s = DMatrix::<f64>::zeros(size, size);
    for i in 0..n {
        if let Some(mi) = &inert[i] {
            // H(M) on [ω; v]: M (a)^s = [m v; Ī ω]
            let o = boff[i];
            for k in 0..3 {
                s[(o + k, o + 3 + k)] = mi.mass();
            }
            s.view_mut((o + 3, o), (3, 3)).copy_from(&mi.i_com());
        }
    }
    let p = |g: &M6| -> M6 { M6::from_fn(|r, c| g[((r + 3) % 6, c)]) }; // P_swap G
    for j in joints {
        let r = j.reaction.len();
        for (body, g) in [(j.body, &j.g_dist), (j.parent, &j.g_prox)] {
            if boff[body] == usize::MAX {
                continue;
            }
            let o = boff[body];
            s.view_mut((o, 6 * nb + j.off), (6, r)).copy_from(&(-g.columns(0, r)));
            let pg = p(g);
            s.view_mut((6 * nb + j.off, o), (r, 6)).copy_from(&pg.columns(0, r).transpose());
        }
    }
    let sv = s.singular_values();
    let (mx, mn) = (sv.max().max(1.0), sv.min().min(1.0));
    mx / mn
}
