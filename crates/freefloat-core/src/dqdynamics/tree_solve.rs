//! Solving the Delassus system `K W̃ = rhs` of the dual-quaternion dynamics: tree-sparse block elimination
//! (default) and the dense Cholesky of the assembled matrix (reference).

use super::sixvec::M6;
use super::workspace::{Joint, TreeWork};
use crate::error::{FfError, Result};
use crate::spatial::V6;
use nalgebra::{DMatrix, DVector};

/// Tree-sparse block Cholesky of K. Joint j couples only to joints sharing its child body i (i's children)
/// or its parent body k (k's distal joint and k's other children). Eliminating joints in decreasing index
/// (children before parents) leaves, when j's turn comes, only body i's block of j (its children's Schur
/// updates already folded in) and neighbours that all share body k: their updates land in body k's blocks,
/// so there is no fill-in outside the per-body blocks. Every block is a stack 6×6 (padding dimensions get
/// a unit pivot and stay zero). The solution is left in `w.x` (one padded 6-vector per joint); every
/// buffer is `w`'s, so a call allocates nothing once `w` has grown to the model.
pub(super) fn solve_tree(
    joints: &[Joint],
    inc: &[Vec<usize>],
    start: &[usize],
    blocks: &mut [M6],
    rhs: &mut [V6],
    w: &mut TreeWork,
) -> Result<()> {
    let nj = joints.len();
    let singular = || {
        FfError::Numerical("the dual-quaternion constraint system (Delassus matrix) is singular or indefinite".into())
    };
    let TreeWork { eliminated, pivots, coupling, cstart, cend, rest, x } = w;
    eliminated.clear();
    eliminated.resize(nj, false);
    pivots.clear();
    pivots.resize(nj, None);
    coupling.clear();
    cstart.clear();
    cstart.resize(nj + 1, 0);
    cend.clear();
    cend.resize(nj, 0);
    for jj in (0..nj).rev() {
        let (i, k, rj) = (joints[jj].body, joints[jj].parent, joints[jj].reaction.len());
        let mut p = blocks[start[i]];
        rest.clear();
        let (lk, pos) = (inc[k].len(), inc[k].iter().position(|&x| x == jj));
        if let Some(pos) = pos {
            p += blocks[start[k] + pos * lk + pos];
            for (pa, &ja) in inc[k].iter().enumerate() {
                if ja != jj && !eliminated[ja] {
                    rest.push((ja, pa));
                }
            }
        }
        for d in rj..6 {
            p[(d, d)] = 1.0;
        }
        let ch = nalgebra::Cholesky::new(p).ok_or_else(singular)?;
        let y_rhs = ch.solve(&rhs[jj]);
        cstart[jj] = coupling.len();
        if let Some(pos) = pos {
            for &(ja, pa) in rest.iter() {
                let c_a = blocks[start[k] + pa * lk + pos]; // C[a, j]
                let y_a = ch.solve(&c_a.transpose()); // P⁻¹ C[j, a]
                rhs[ja] -= c_a * y_rhs;
                for &(_, pb) in rest.iter() {
                    let c_b = blocks[start[k] + pb * lk + pos];
                    blocks[start[k] + pb * lk + pa] -= c_b * y_a;
                }
                coupling.push((ja, c_a));
            }
        }
        cend[jj] = coupling.len();
        pivots[jj] = Some(ch);
        eliminated[jj] = true;
    }
    cstart[nj] = coupling.len();
    // back substitution, parents first: x_j = P⁻¹ (rhs_j − Σ_a C[a, j]ᵀ x_a)
    x.clear();
    x.resize(nj, V6::zeros());
    for jj in 0..nj {
        let mut b = rhs[jj];
        for (ja, c) in &coupling[cstart[jj]..cend[jj]] {
            b -= c.transpose() * x[*ja];
        }
        x[jj] = pivots[jj].as_ref().ok_or_else(singular)?.solve(&b);
    }
    Ok(())
}

/// Solve the symmetric positive-definite Delassus system by Cholesky; a failure means dependent constraint
/// rows (e.g. degenerate joint axes) or a non-physical body. The dense reference solver: it allocates.
pub(super) fn solve_spd(k: DMatrix<f64>, rhs: DVector<f64>) -> Result<DVector<f64>> {
    if k.nrows() == 0 {
        return Ok(rhs);
    }
    match k.cholesky() {
        Some(ch) => Ok(ch.solve(&rhs)),
        None => Err(FfError::Numerical(
            "the dual-quaternion constraint system (Delassus matrix) is singular or indefinite".into(),
        )),
    }
}
