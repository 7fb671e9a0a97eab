//! Condition number of the system matrix S of (6.17) (Valverde 2018, Figs. 5.5 and 7.x), from the blocks that
//! `system.rs` assembles. The public entry `condition_number` is in `system.rs`, beside the solve it runs, so that
//! this file does not import the one that calls it.

use super::sixvec::M6;
use super::workspace::Joint;
use crate::dualquat::DualInertia;
use nalgebra::DMatrix;

/// The dense system matrix S of (6.17) from the blocks the solve assembled, and its 2-norm condition number
/// (the quantity `condition_number` returns; `system.rs` calls this when asked for it).
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
