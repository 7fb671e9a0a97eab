//! ∂τ/∂q, ∂τ/∂v of the recursive Newton-Euler algorithm (Carpentier and Mansard 2018, Alg. 1) and ∂a/∂(q, v, τ) of
//! forward dynamics, in inertial coordinates (see the module documentation).

use super::minv::minv_core;
use super::{check_workspace, gemm_pair, Derivatives};
use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::dynamics::{gravity_acceleration, hybrid_aba_unchecked};
use crate::error::{FfError, Result};
use crate::kinematics::forward_kinematics_unchecked;
use crate::model::Model;
use crate::spatial::{skew, Force, Inertia, Motion, M3, M6, V3};

/// Column `c` of a 6×k subspace as a motion.
#[inline]
pub(crate) fn col(s: &M6, c: usize) -> Motion {
    Motion::new(V3::new(s[(0, c)], s[(1, c)], s[(2, c)]), V3::new(s[(3, c)], s[(4, c)], s[(5, c)]))
}

/// Derivatives of inverse dynamics `τ = RNEA(q, v, a, fext)`: fills `w.dtau_dq` and `w.dtau_dv`
/// (nv × nv, q in the local tangent of the module documentation; ∂τ/∂a is the mass matrix, see
/// `crba`). Also leaves `d.tau = RNEA(q, v, a)`. Checks every argument like `rnea`.
#[allow(clippy::too_many_arguments)]
pub fn rnea_derivatives(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    fext: Option<&[f64]>,
) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::qv(q, v).nv("a", a).fext(fext))?;
    check_workspace(m, w)?;
    with_unit_q(m, d, q, fix, |d, q| {
        forward_kinematics_unchecked(m, d, q);
        rnea_derivatives_core(m, d, w, v, a, fext);
    });
    Ok(())
}

/// Derivatives of forward dynamics `a = FD(q, v, τ, fext)` (the articulated-body algorithm): fills
/// `w.ddq` (= `aba`'s result), `w.da_dq`, `w.da_dv`, `w.minv` (= ∂a/∂τ = M⁻¹) and, on the way,
/// `w.dtau_dq`, `w.dtau_dv` at a = FD. From differentiating `M(q) a + h(q, v) = τ` along the
/// solution: `∂a/∂q = −M⁻¹ ∂τ/∂q`, `∂a/∂v = −M⁻¹ ∂τ/∂v` (Carpentier and Mansard 2018, eq. (9)).
/// Leaves `d` holding forward kinematics at q in the inertial frame (as `aba` does). Checks every argument like
/// `aba`.
#[allow(clippy::too_many_arguments)]
pub fn aba_derivatives(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::qv(q, v).nv("tau", tau).fext(fext))?;
    check_workspace(m, w)?;
    with_unit_q(m, d, q, fix, |d, q| aba_derivatives_unchecked(m, d, w, q, v, tau, fext))
}

/// `aba_derivatives` without the argument check (`q` normalised).
pub(crate) fn aba_derivatives_unchecked(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
) -> Result<()> {
    hybrid_aba_unchecked(m, d, q, v, tau, fext, None)?;
    w.ddq.copy_from_slice(&d.ddq);
    let a = std::mem::take(&mut w.ddq);
    // ABA ran forward kinematics at q already.
    rnea_derivatives_core(m, d, w, v, &a, fext);
    w.ddq = a;
    if !minv_core(m, d, w) {
        return Err(FfError::Numerical("the mass matrix is not positive definite".into()));
    }
    gemm_pair(&mut w.da_dq, &mut w.da_dv, -1.0, &w.minv, &w.dtau_dq, &w.dtau_dv);
    Ok(())
}

/// ∂τ/∂q, ∂τ/∂v (into `w.dtau_dq`, `w.dtau_dv`) and τ (into `d.tau`) after forward kinematics at q: the
/// single-pass algorithm of Carpentier and Mansard, RSS 2018, Alg. 1 (one forward pass, one backward pass; see
/// the module documentation for the derivation in this engine's notation).
pub(crate) fn rnea_derivatives_core(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    v: &[f64],
    a: &[f64],
    fext: Option<&[f64]>,
) {
    let (n, nv) = (m.nbodies(), m.nv);
    let ag = gravity_acceleration(m);
    let Derivatives {
        ov: ovs,
        oa: oas,
        oi: ois,
        ff,
        ic,
        bc,
        sw,
        psi_d,
        psi_dd,
        dadv,
        dtau_dq,
        dtau_dv,
        dof_parent,
        ..
    } = w;
    // Forward pass (Alg. 1, its first loop), inertial coordinates (Featherstone, RBDA Table 5.1 with X = ⁰Xᵢ):
    // vᵢ = v_λ + Sᵢq̇ᵢ, aᵢ = a_λ + Sᵢq̈ᵢ + vᵢ × Sᵢq̇ᵢ, fᵢ = Iᵢaᵢ + vᵢ ×* Iᵢvᵢ − fextᵢ; and per joint column ψ
    // the parts of ∂v/∂q and ∂a/∂q that do not merely turn with the moved subtree, Ψ̇ = v_λ × ψ and
    // Ψ̈ = a_λ × ψ + v_λ × Ψ̇, and ∂a/∂q̇ = Ψ̇ + vᵢ × ψ (the Ṡ term).
    for i in 0..n {
        let omi = d.o_mi[i];
        let (k, iv) = (m.nvs[i], m.idx_v[i]);
        let (vp, ap) = match m.parents[i] {
            Some(p) => (ovs[p], oas[p]),
            None => (Motion::ZERO, ag),
        };
        let (mut vj, mut aj) = (Motion::ZERO, Motion::ZERO);
        for c in 0..k {
            let s = omi.act_motion(&col(&d.s[i], c));
            d.os[i].set_column(c, &s.to_v6());
            sw[iv + c] = s;
            vj += s * v[iv + c];
            aj += s * a[iv + c];
            if m.parents[i].is_some() {
                let pd = vp.cross_motion(&s);
                psi_d[iv + c] = pd;
                psi_dd[iv + c] = ap.cross_motion(&s) + vp.cross_motion(&pd);
            } else {
                // the root: v_λ = 0, a_λ = a_g (the base's columns of ∂τ/∂q are gravity's only)
                psi_d[iv + c] = Motion::ZERO;
                psi_dd[iv + c] = ap.cross_motion(&s);
            }
        }
        let ov = vp + vj;
        let oa = ap + aj + ov.cross_motion(&vj);
        for c in iv..iv + k {
            dadv[c] = psi_d[c] + ov.cross_motion(&sw[c]);
        }
        let oi = m.inertias[i].transformed(&omi);
        let h = oi.mul_motion(&ov);
        let fe = match fext {
            Some(f) => omi.act_force(&Force::from_slice(&f[6 * i..6 * i + 6])),
            None => Force::ZERO,
        };
        ovs[i] = ov;
        oas[i] = oa;
        ois[i] = oi;
        ic[i] = oi;
        bc[i] = BMap::of(&oi, &ov, &h);
        ff[i] = oi.mul_motion(&oa) + ov.cross_force(&h) - fe;
    }

    // Backward pass (Alg. 1, its second loop). With the subtree composites Fᵢ = Σ f, Icᵢ = Σ I and Bcᵢ = Σ B,
    // for joint i and any joint j on its path to the root (j ⪯ i; column ψ of j):
    //   ∂τᵢ/∂q_j = Sᵢᵀ (Icᵢ Ψ̈_j + Bcᵢ Ψ̇_j)                ∂τᵢ/∂q̇_j = Sᵢᵀ (Bcᵢ ψ + Icᵢ (Ψ̇_j + Ṡ_j))
    // (row i), and for the strict ancestors j of i, with ψ now a column of i,
    //   ∂τ_j/∂qᵢ = S_jᵀ (ψ ×* Fᵢ + Icᵢ Ψ̈ᵢ + Bcᵢ Ψ̇ᵢ)        ∂τ_j/∂q̇ᵢ = S_jᵀ (Bcᵢ ψ + Icᵢ (Ψ̇ᵢ + Ṡᵢ))
    // (column i). Every other entry is zero (joints on different branches).
    let (tq, tv) = (dtau_dq.as_mut_slice(), dtau_dv.as_mut_slice());
    tq.fill(0.0);
    tv.fill(0.0);
    for i in (0..n).rev() {
        let (k, iv) = (m.nvs[i], m.idx_v[i]);
        let (ici, bci, f) = (ic[i], bc[i], ff[i]);
        for row in iv..iv + k {
            let s = sw[row];
            d.tau[row] = s.dot(&f);
            // Sᵢᵀ Icᵢ (Icᵢ is symmetric) and Sᵢᵀ Bcᵢ (angular part only) as covectors
            let u1 = ici.mul_motion(&s);
            let u2 = bci.tr_apply(&s);
            // the joint's own columns and its ancestors', walking the path one velocity index at a time
            let mut c = iv + k - 1;
            loop {
                tq[c * nv + row] = psi_dd[c].dot(&u1) + psi_d[c].ang.dot(&u2);
                tv[c * nv + row] = sw[c].ang.dot(&u2) + dadv[c].dot(&u1);
                match dof_parent[c] {
                    Some(pc) => c = pc,
                    None => break,
                }
            }
            let mut up = dof_parent[iv];
            if up.is_none() {
                continue;
            }
            let xq = s.cross_force(&f) + ici.mul_motion(&psi_dd[row]) + bci.apply(&psi_d[row]);
            let xv = bci.apply(&s) + ici.mul_motion(&dadv[row]);
            while let Some(c) = up {
                tq[row * nv + c] = sw[c].dot(&xq);
                tv[row * nv + c] = sw[c].dot(&xv);
                up = dof_parent[c];
            }
        }
        if let Some(p) = m.parents[i] {
            ic[p] = ic[p].add(&ici);
            bc[p].add(&bci);
            ff[p] += f;
        }
    }
}

/// The map `e ↦ I (e × v) + e ×* (I v) + v ×* (I e)` of one body (or a sum of them over a subtree): the derivative
/// of a body's force `f = I a + v ×* I v` along a change `e` of its twist that also enters its acceleration as
/// `e × v` (the B of Carpentier and Mansard 2018, here derived directly). As a 6×6 matrix it is `H − I X − (I X)ᵀ` with X = [v×],
/// `[v×*] = −Xᵀ` and H the matrix of `e ↦ e ×* h` (h = I v = (h_lin, h_ang)); written out in 3×3 blocks with
/// `I = [[m 1, −[c]], [[c], I_o]]` (c the first moment) and h_lin = m v_lin − c × ω, its linear-input half vanishes:
/// `[[0, −2[h_lin]], [0, A + Aᵀ − (v_lin cᵀ + c v_linᵀ) + 2 (c·v_lin) 1 − [h_ang]]]`, A = [ω] I_o. So it is kept
/// as h_lin and the 3×3 block (both additive over a subtree).
#[derive(Clone, Copy, Debug)]
pub(crate) struct BMap {
    h_lin: V3,
    aa: M3,
}

impl BMap {
    pub(crate) const ZERO: BMap =
        BMap { h_lin: V3::new(0.0, 0.0, 0.0), aa: M3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0) };

    /// Of a body of inertia `oi` moving with twist `ov` and momentum `h = oi ov`.
    fn of(oi: &Inertia, ov: &Motion, h: &Force) -> BMap {
        let (c, vl, w) = (&oi.h, &ov.lin, &ov.ang);
        let io = &oi.i_o;
        // A = [ω] I_o, column by column
        let a = M3::from_columns(&[w.cross(&io.column(0)), w.cross(&io.column(1)), w.cross(&io.column(2))]);
        let mut aa = a + a.transpose() - (vl * c.transpose() + c * vl.transpose()) - skew(&h.ang);
        let d2 = 2.0 * c.dot(vl);
        for r in 0..3 {
            aa[(r, r)] += d2;
        }
        BMap { h_lin: h.lin, aa }
    }

    fn add(&mut self, o: &BMap) {
        self.h_lin += o.h_lin;
        self.aa += o.aa;
    }

    /// `B e = (2 e_ang × h_lin, A e_ang)`.
    #[inline]
    fn apply(&self, e: &Motion) -> Force {
        Force::new(2.0 * e.ang.cross(&self.h_lin), self.aa * e.ang)
    }

    /// The angular half of `Bᵀ s` (its linear half is zero): `2 h_lin × s_lin + Aᵀ s_ang`.
    #[inline]
    fn tr_apply(&self, s: &Motion) -> V3 {
        2.0 * self.h_lin.cross(&s.lin) + self.aa.tr_mul(&s.ang)
    }
}
