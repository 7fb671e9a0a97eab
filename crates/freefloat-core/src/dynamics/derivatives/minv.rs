//! M⁻¹ by the articulated-body algorithm run on all nv unit torques at once (Carpentier, "Analytical inverse of
//! the joint space inertia matrix", 2018; Featherstone, RBDA §7.3 with τ = eₖ, v = 0, no gravity): O(nv · n)
//! 6-vector operations instead of CRBA, a Cholesky factor and a triangular inverse (O(nv³)).
//!
//! Articulated-body recursion with the bias force pᴬᵢ(τ) and the accelerations linear in τ (inertial frame):
//! backward, `Uᵢ = Iᴬᵢ Sᵢ`, `Dᵢ = Sᵢᵀ Uᵢ`, `q̈ᵢ ← Dᵢ⁻¹ (τᵢ − Sᵢᵀ pᴬᵢ)` (the part not depending on the parent's
//! acceleration), `Iᴬ_λ += Iᴬᵢ − Uᵢ Dᵢ⁻¹ Uᵢᵀ`, `pᴬ_λ += pᴬᵢ + Uᵢ q̈ᵢ`; forward, `q̈ᵢ −= Dᵢ⁻¹ Uᵢᵀ a_λ`,
//! `aᵢ = a_λ + Sᵢ q̈ᵢ` (RBDA §7.3, Table 7.1). Each of pᴬ and a is kept as a 6 × nv matrix (one column per unit
//! torque).
//! pᴬᵢ depends only on the torques of i's subtree, so the backward pass works on the columns of that subtree's
//! velocity range only; by symmetry the forward pass computes the upper triangle only (columns from joint i on).

use super::Derivatives;
use crate::data::Data;
use crate::model::{JointType, Model};
use crate::spatial::{Force, Motion, M6, V6};

/// Fill `w.minv` with M(q)⁻¹, after `rnea_derivatives_core` left the inertial-frame inertias in `w.oi` and the
/// subspaces in `d.os`. False if an articulated joint inertia Dᵢ is not positive definite.
pub(crate) fn minv_core(m: &Model, d: &Data, w: &mut Derivatives) -> bool {
    let (n, nv) = (m.nbodies(), m.nv);
    let Derivatives { fm, ia, mu, mdinv, sub_end, oi, minv, .. } = w;
    let ms = minv.as_mut_slice();
    // column c of body i's 6 × nv matrix (pᴬ in the backward pass, a in the forward pass)
    let at = |i: usize, c: usize| 6 * (nv * i + c);
    for i in 0..n {
        fm[at(i, m.idx_v[i])..at(i, sub_end[i])].fill(0.0);
        ia[i] = oi[i].to_matrix();
    }
    for i in (0..n).rev() {
        let (k, iv, end) = (m.nvs[i], m.idx_v[i], sub_end[i]);
        let parent = m.parents[i];
        let s = &d.os[i];
        if k == 0 {
            // a welded body passes its whole inertia and bias on
            if let Some(p) = parent {
                let iai = ia[i];
                ia[p] += iai;
                for c in iv..end {
                    for r in 0..6 {
                        fm[at(p, c) + r] += fm[at(i, c) + r];
                    }
                }
            }
            continue;
        }
        if k == 1 {
            // one degree of freedom: scalar D, rank-one update of the parent (RBDA Table 7.1)
            let s0 = s.column(0).into_owned();
            let u0 = ia[i] * s0;
            let dd = s0.dot(&u0);
            if !(dd > 0.0) || !dd.is_finite() {
                return false;
            }
            let dinv = 1.0 / dd;
            for c in iv..end {
                let f = &fm[at(i, c)..at(i, c) + 6];
                let e = if c == iv { 1.0 } else { 0.0 };
                ms[c * nv + iv] = dinv * (e - dot6(s0.as_slice(), f));
            }
            for c in end..nv {
                ms[c * nv + iv] = 0.0;
            }
            if let Some(p) = parent {
                let iai = ia[i];
                let iap = &mut ia[p];
                for cc in 0..6 {
                    let uc = u0[cc] * dinv;
                    for r in 0..6 {
                        iap[(r, cc)] += iai[(r, cc)] - u0[r] * uc;
                    }
                }
                for c in iv..end {
                    let x = ms[c * nv + iv];
                    let (lo, hi) = fm.split_at_mut(at(i, 0));
                    let (fp, fi) = (&mut lo[at(p, c)..at(p, c) + 6], &hi[6 * c..6 * c + 6]);
                    for r in 0..6 {
                        fp[r] += u0[r].mul_add(x, fi[r]);
                    }
                }
            }
            // (the forward pass reads column 0 only for k = 1)
            mu[i].set_column(0, &u0);
            mdinv[i][(0, 0)] = dinv;
            continue;
        }
        if parent.is_none() && m.joint_types[i] == JointType::Free {
            // The free root: S = X₀, the base placement's motion transform, is invertible, so with Iᴬ its (complete)
            // articulated inertia D⁻¹ = X₀⁻¹ Iᴬ⁻¹ X₀⁻ᵀ, and the root's rows and acceleration are q̈ = X₀⁻¹ a with
            // a = Iᴬ⁻¹ (X₀⁻ᵀ e − pᴬ) (RBDA §7.3 with S = X₀, as `aba` solves the root). Nothing is left for the
            // forward pass (a_λ = 0).
            let Some(ch) = nalgebra::Cholesky::new(ia[i]) else {
                return false;
            };
            let (iainv, omi) = (ch.inverse(), &d.o_mi[i]);
            for c in iv..end {
                let mut g = -V6::from_column_slice(&fm[at(i, c)..at(i, c) + 6]);
                if c < iv + 6 {
                    let mut e = Force::ZERO;
                    if c < iv + 3 {
                        e.lin[c - iv] = 1.0;
                    } else {
                        e.ang[c - iv - 3] = 1.0;
                    }
                    g += omi.act_force(&e).to_v6();
                }
                let a = iainv * g;
                omi.inv_act_motion(&Motion::from_v6(&a)).write(&mut ms[c * nv + iv..c * nv + iv + 6]);
                fm[at(i, c)..at(i, c) + 6].copy_from_slice(a.as_slice());
            }
            for c in end..nv {
                ms[c * nv + iv..c * nv + iv + 6].fill(0.0);
            }
            continue;
        }
        // Several degrees of freedom (2 or 3; a free joint is always the root): fixed 6 × 6 products, with S padded
        // by zero columns so that U, D⁻¹ and the rows below are zero past k.
        let mut sp = *s;
        sp.columns_mut(k, 6 - k).fill(0.0);
        let u = ia[i] * sp;
        let Some(dinv) = joint_inverse(&sp, &u, k) else {
            return false;
        };
        // rows iv..iv+k: Dᵢ⁻¹ (eᵢ − Sᵢᵀ pᴬᵢ) on the subtree columns, 0 beyond (filled by the forward pass)
        for c in iv..end {
            let mut t = -sp.tr_mul(&V6::from_column_slice(&fm[at(i, c)..at(i, c) + 6]));
            if c < iv + k {
                t[c - iv] += 1.0;
            }
            let x = dinv * t;
            ms[c * nv + iv..c * nv + iv + k].copy_from_slice(&x.as_slice()[..k]);
        }
        for c in end..nv {
            ms[c * nv + iv..c * nv + iv + k].fill(0.0);
        }
        if let Some(p) = parent {
            // Iᴬ_λ += Iᴬᵢ − U D⁻¹ Uᵀ, pᴬ_λ += pᴬᵢ + U q̈ᵢ
            let ud = u * dinv;
            let iai = ia[i] - ud * u.transpose();
            ia[p] += iai;
            for c in iv..end {
                let mut x = V6::zeros();
                x.as_mut_slice()[..k].copy_from_slice(&ms[c * nv + iv..c * nv + iv + k]);
                let add = V6::from_column_slice(&fm[at(i, c)..at(i, c) + 6]) + u * x;
                for (fp, a) in fm[at(p, c)..at(p, c) + 6].iter_mut().zip(add.iter()) {
                    *fp += a;
                }
            }
        }
        mu[i] = u;
        mdinv[i] = dinv;
    }
    // Forward pass: aᵢ (6 × nv, in the same buffer: pᴬᵢ is no longer needed) on the columns iv.. only.
    for i in 0..n {
        let (k, iv) = (m.nvs[i], m.idx_v[i]);
        let (s, u, dinv) = (&d.os[i], &mu[i], &mdinv[i]);
        let Some(p) = m.parents[i] else {
            if m.joint_types[i] == JointType::Free {
                // done in the backward pass
                mirror(ms, nv, iv, k);
                continue;
            }
            // the root: a = S q̈ (no parent acceleration)
            for c in iv..nv {
                let mut a = [0.0; 6];
                for r in 0..k {
                    let x = ms[c * nv + iv + r];
                    for (e, sv) in a.iter_mut().zip(s.column(r).iter()) {
                        *e = sv.mul_add(x, *e);
                    }
                }
                fm[at(i, c)..at(i, c) + 6].copy_from_slice(&a);
            }
            mirror(ms, nv, iv, k);
            continue;
        };
        let (lo, hi) = fm.split_at_mut(at(i, 0));
        if k == 1 {
            // q̈ᵢ −= Dᵢ⁻¹ Uᵢᵀ a_λ, aᵢ = a_λ + Sᵢ q̈ᵢ; the finished row is mirrored into column iv at once
            let (s0, u0, dinv) = (s.column(0), u.column(0), dinv[(0, 0)]);
            for c in iv..nv {
                let ap: &[f64; 6] = lo[at(p, c)..at(p, c) + 6].try_into().expect("6 entries");
                let x = (-dinv).mul_add(dot6(u0.as_slice(), ap), ms[c * nv + iv]);
                ms[c * nv + iv] = x;
                ms[iv * nv + c] = x;
                let ai = &mut hi[6 * c..6 * c + 6];
                for r in 0..6 {
                    ai[r] = s0[r].mul_add(x, ap[r]);
                }
            }
            continue;
        }
        for c in iv..nv {
            let ap = V6::from_column_slice(&lo[at(p, c)..at(p, c) + 6]);
            let mut a = ap;
            if k > 0 {
                // q̈ᵢ −= Dᵢ⁻¹ Uᵢᵀ a_λ (U, D⁻¹ zero past k), aᵢ = a_λ + Sᵢ q̈ᵢ
                let y = dinv * u.tr_mul(&ap);
                for r in 0..k {
                    let x = ms[c * nv + iv + r] - y[r];
                    ms[c * nv + iv + r] = x;
                    a += s.column(r) * x;
                }
            }
            hi[6 * c..6 * c + 6].copy_from_slice(a.as_slice());
        }
        mirror(ms, nv, iv, k);
    }
    true
}

/// Copy rows `iv..iv + k` of the upper triangle (columns from iv on) to the lower triangle, in place.
fn mirror(ms: &mut [f64], nv: usize, iv: usize, k: usize) {
    for r in iv..iv + k {
        for c in r + 1..nv {
            ms[r * nv + c] = ms[c * nv + r];
        }
    }
}

#[inline(always)]
fn dot6(a: &[f64], b: &[f64]) -> f64 {
    let (a, b) = (&a[..6], &b[..6]);
    a[2].mul_add(b[2], a[1].mul_add(b[1], a[0] * b[0])) + a[5].mul_add(b[5], a[4].mul_add(b[4], a[3] * b[3]))
}

/// Dᵢ⁻¹ for `Dᵢ = Sᵢᵀ Uᵢ` (k × k in the top-left corner; S and U zero past column k, and so is the result), None
/// if Dᵢ is not positive definite.
fn joint_inverse(s: &M6, u: &M6, k: usize) -> Option<M6> {
    // padded with the identity so the fixed-size (non-allocating) Cholesky applies to every k; the inverse of
    // [[D, 0], [0, 1]] is [[D⁻¹, 0], [0, 1]] exactly
    let mut dm = s.tr_mul(u);
    for r in k..6 {
        dm[(r, r)] = 1.0;
    }
    let mut inv = nalgebra::Cholesky::new(dm)?.inverse();
    for r in k..6 {
        inv[(r, r)] = 0.0;
    }
    Some(inv)
}
