//! ∂τ/∂q, ∂τ/∂v of the recursive Newton-Euler algorithm and ∂a/∂(q, v, τ) of forward dynamics, by
//! exact forward-mode differentiation in inertial coordinates (see the module documentation).

use super::{check_workspace, gemm, Derivatives};
use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::dynamics::{crba_unchecked, gravity_acceleration, hybrid_aba_unchecked};
use crate::error::{FfError, Result};
use crate::kinematics::forward_kinematics_unchecked;
use crate::model::Model;
use crate::spatial::{Force, Motion, M6, V3};
use nalgebra::DMatrix;

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
    // CRBA first: under a free root it leaves `d.o_mi`, `d.ic` and `d.os` relative to the base (see
    // `crba_unchecked`), and callers (the DDP cost Jacobians among them) read world-frame kinematics from `d`
    // after this call. ABA and the derivative passes below overwrite them in the inertial frame; neither touches
    // `d.mass_matrix`.
    crba_unchecked(m, d, q);
    hybrid_aba_unchecked(m, d, q, v, tau, fext, None)?;
    w.ddq.copy_from_slice(&d.ddq);
    let a = std::mem::take(&mut w.ddq);
    // ABA ran forward kinematics at q already.
    rnea_derivatives_core(m, d, w, v, &a, fext);
    w.ddq = a;
    if !cholesky_inverse(&d.mass_matrix, &mut w.chol, &mut w.minv) {
        return Err(FfError::Numerical("the mass matrix is not positive definite".into()));
    }
    gemm(&mut w.da_dq, -1.0, &w.minv, &w.dtau_dq, 0.0);
    gemm(&mut w.da_dv, -1.0, &w.minv, &w.dtau_dv, 0.0);
    Ok(())
}

/// Both derivative passes, after forward kinematics at q.
pub(crate) fn rnea_derivatives_core(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    v: &[f64],
    a: &[f64],
    fext: Option<&[f64]>,
) {
    let n = m.nbodies();
    // Nominal RNEA in inertial coordinates (Featherstone, RBDA Table 5.1 with X = ⁰Xᵢ):
    // vᵢ = v_λ + Sᵢq̇ᵢ, aᵢ = a_λ + Sᵢq̈ᵢ + vᵢ × Sᵢq̇ᵢ, fᵢ = Iᵢaᵢ + vᵢ ×* Iᵢvᵢ − fextᵢ, τᵢ = Sᵢᵀ Σ_subtree f.
    let ag = gravity_acceleration(m);
    for i in 0..n {
        let omi = d.o_mi[i];
        let (k, iv) = (m.nvs[i], m.idx_v[i]);
        let (mut vj, mut aj) = (Motion::ZERO, Motion::ZERO);
        for c in 0..k {
            let s = omi.act_motion(&col(&d.s[i], c));
            d.os[i].set_column(c, &s.to_v6());
            vj += s * v[iv + c];
            aj += s * a[iv + c];
        }
        let (vp, ap) = match m.parents[i] {
            Some(p) => (w.ov[p], w.oa[p]),
            None => (Motion::ZERO, ag),
        };
        let ov = vp + vj;
        let oa = ap + aj + ov.cross_motion(&vj);
        let oi = m.inertias[i].transformed(&omi);
        let h = oi.mul_motion(&ov);
        let g = oi.mul_motion(&oa);
        let fe = match fext {
            Some(f) => omi.act_force(&Force::from_slice(&f[6 * i..6 * i + 6])),
            None => Force::ZERO,
        };
        w.ov[i] = ov;
        w.oa[i] = oa;
        w.vj[i] = vj;
        w.aj[i] = aj;
        w.oi[i] = oi;
        w.h[i] = h;
        w.g[i] = g;
        w.fe[i] = fe;
        w.ff[i] = g + ov.cross_force(&h) - fe;
    }
    for i in (1..n).rev() {
        if let Some(p) = m.parents[i] {
            let f = w.ff[i];
            w.ff[p] += f;
        }
    }
    for i in 0..n {
        let f6 = w.ff[i].to_v6();
        for c in 0..m.nvs[i] {
            d.tau[m.idx_v[i] + c] = d.os[i].column(c).dot(&f6);
        }
    }

    // ∂τ/∂v in closed form. A unit rate e = Sⱼ,c of joint j adds e to every twist of j's subtree
    // (dvᵢ = e) and changes the accelerations by daᵢ = e × (vᵢ − wⱼ), wⱼ = v_λ(j) + vⱼ (the chain rule
    // through aᵢ = a_λ + Sᵢq̈ᵢ + vᵢ × Sᵢq̇ᵢ). So dfᵢ = Bᵢ e − Iᵢ (e × wⱼ) with the per-body linear map
    // Bᵢ e = Iᵢ (e × vᵢ) + e ×* (Iᵢ vᵢ) + vᵢ ×* (Iᵢ e), and summed over a subtree
    // dFₖ = Bcₖ e − Icₖ (e × wⱼ) with the composites Bc, Ic: dτᵢ = Sᵢᵀ dF_{i or j, the deeper}.
    for i in 0..n {
        let (ov, h, oi) = (w.ov[i], w.h[i], w.oi[i]);
        for k in 0..6 {
            let mut e = Motion::ZERO;
            if k < 3 {
                e.lin[k] = 1.0;
            } else {
                e.ang[k - 3] = 1.0;
            }
            let b = oi.mul_motion(&e.cross_motion(&ov)) + e.cross_force(&h) + ov.cross_force(&oi.mul_motion(&e));
            w.bc[i].set_column(k, &b.to_v6());
        }
        w.ic[i] = oi;
    }
    for i in (1..n).rev() {
        if let Some(p) = m.parents[i] {
            let b = w.bc[i];
            w.bc[p] += b;
            w.ic[p] = w.ic[p].add(&w.ic[i]);
        }
    }
    for i in 0..n {
        for r in 0..m.nvs[i] {
            let s = col(&d.os[i], r);
            let sb = w.bc[i].transpose() * s.to_v6();
            w.sb[i].set_column(r, &sb);
            let si = w.ic[i].mul_motion(&s).to_v6();
            w.si[i].set_column(r, &si);
        }
    }

    // ∂τ/∂q: one forward-mode pass per tangent direction (joint j, column c).
    for j in 0..n {
        for c in 0..m.nvs[j] {
            let col_idx = m.idx_v[j] + c;
            let psi = col(&d.os[j], c);
            if m.parents[j].is_none() {
                root_q_column(m, d, w, psi, ag, col_idx);
            } else {
                direction(m, w, j, psi);
                write_column(m, d, w, j, psi, col_idx);
            }
            dtau_dv_column(m, d, w, j, psi, col_idx);
        }
    }
}

/// Column of ∂τ/∂v for the unit rate along e = Sⱼ,c (see the closed form above).
fn dtau_dv_column(m: &Model, d: &Data, w: &mut Derivatives, j: usize, e: Motion, c: usize) {
    let n = m.nbodies();
    let wj = match m.parents[j] {
        Some(p) => w.ov[p] + w.ov[j],
        None => w.ov[j],
    };
    let z = e.cross_motion(&wj).to_v6();
    let e6 = e.to_v6();
    let mut colm = w.dtau_dv.column_mut(c);
    colm.fill(0.0);
    for i in j..n {
        let inside = i == j || m.parents[i].is_some_and(|p| p >= j && w.in_sub[p]);
        w.in_sub[i] = inside;
        if !inside {
            continue;
        }
        for r in 0..m.nvs[i] {
            colm[m.idx_v[i] + r] = w.sb[i].column(r).dot(&e6) - w.si[i].column(r).dot(&z);
        }
    }
    let xj = w.bc[j] * e6 - w.ic[j].mul_motion(&Motion::from_v6(&z)).to_v6();
    let mut k = m.parents[j];
    while let Some(p) = k {
        for r in 0..m.nvs[p] {
            colm[m.idx_v[p] + r] = d.os[p].column(r).dot(&xj);
        }
        k = m.parents[p];
    }
}

/// ∂τ/∂q along a root-joint direction ψ, in closed form. The whole tree moves rigidly, so every
/// inertial-frame quantity is covariant (`d x = ψ × x`) except the gravity acceleration a_g, which
/// stays put: `dFᵢ = ψ ×* Fᵢ − Icᵢ (ψ × a_g)` with Icᵢ the composite inertia of i's subtree, and since
/// `(ψ × S)ᵀ F + Sᵀ (ψ ×* F) = 0`, `dτᵢ = −Sᵢᵀ Icᵢ (ψ × a_g)`: zero without gravity (orbital robots).
fn root_q_column(m: &Model, d: &Data, w: &mut Derivatives, psi: Motion, ag: Motion, c: usize) {
    let n = m.nbodies();
    let ga = psi.cross_motion(&ag);
    // w.ic holds the composite inertias (computed with the ∂τ/∂v maps)
    let mut colm = w.dtau_dq.column_mut(c);
    colm.fill(0.0);
    if ga.lin.norm_squared() + ga.ang.norm_squared() == 0.0 {
        return;
    }
    for i in 0..n {
        let f = w.ic[i].mul_motion(&ga).to_v6();
        for r in 0..m.nvs[i] {
            colm[m.idx_v[i] + r] = -d.os[i].column(r).dot(&f);
        }
    }
}

/// Forward-mode sweep over the subtree of `j` for a perturbation of joint j's configuration along
/// ψ (the subtree moves rigidly with twist ψ). Leaves the subtree-summed force derivatives in
/// `w.dff` (subtree of j only).
#[inline]
fn direction(m: &Model, w: &mut Derivatives, j: usize, psi: Motion) {
    let n = m.nbodies();
    for i in j..n {
        let inside = i == j || m.parents[i].is_some_and(|p| p >= j && w.in_sub[p]);
        w.in_sub[i] = inside;
        if !inside {
            continue;
        }
        let (dvp, dap) = match m.parents[i] {
            Some(p) if i != j => (w.dov[p], w.doa[p]),
            _ => (Motion::ZERO, Motion::ZERO),
        };
        let (ov, vj, oa) = (w.ov[i], w.vj[i], w.oa[i]);
        let oi = &w.oi[i];
        let h = w.h[i];
        // Everything fixed to body i turns with ψ: d(Sq̇) = ψ × Sq̇, d(Sq̈) = ψ × Sq̈,
        // d(I x) = ψ ×* (I x) − I (ψ × x), d(fext) = ψ ×* fext.
        let dvj = psi.cross_motion(&vj);
        let daj = psi.cross_motion(&w.aj[i]);
        let dov = dvp + dvj;
        let doa = dap + daj + dov.cross_motion(&vj) + ov.cross_motion(&dvj);
        let dh = psi.cross_force(&h) + oi.mul_motion(&(dov - psi.cross_motion(&ov)));
        let df = psi.cross_force(&w.g[i])
            + oi.mul_motion(&(doa - psi.cross_motion(&oa)))
            + dov.cross_force(&h)
            + ov.cross_force(&dh)
            - psi.cross_force(&w.fe[i]);
        w.dov[i] = dov;
        w.doa[i] = doa;
        w.dff[i] = df;
    }
    for i in (j + 1..n).rev() {
        if w.in_sub[i] {
            let p = m.parents[i].unwrap_or(0);
            let f = w.dff[i];
            w.dff[p] += f;
        }
    }
}

/// Write one column of ∂τ/∂q from the sweep's force derivatives:
/// `dτᵢ = (ψ × Sᵢ)ᵀ Fᵢ + Sᵢᵀ dFᵢ` in the subtree, `Sᵢᵀ dFⱼ` on the ancestors of j, 0 elsewhere.
fn write_column(m: &Model, d: &Data, w: &mut Derivatives, j: usize, psi: Motion, c: usize) {
    let n = m.nbodies();
    let out = &mut w.dtau_dq;
    let mut colm = out.column_mut(c);
    colm.fill(0.0);
    for i in j..n {
        if !w.in_sub[i] {
            continue;
        }
        let df = w.dff[i].to_v6();
        for r in 0..m.nvs[i] {
            let s = col(&d.os[i], r);
            colm[m.idx_v[i] + r] = s.to_v6().dot(&df) + psi.cross_motion(&s).dot(&w.ff[i]);
        }
    }
    let dfj = w.dff[j].to_v6();
    let mut k = m.parents[j];
    while let Some(p) = k {
        for r in 0..m.nvs[p] {
            colm[m.idx_v[p] + r] = d.os[p].column(r).dot(&dfj);
        }
        k = m.parents[p];
    }
}

/// Cholesky factor `l` of the symmetric positive-definite `a` and `inv = a⁻¹` (full), in place,
/// without allocating. False if `a` is not positive definite.
pub(crate) fn cholesky_inverse(a: &DMatrix<f64>, l: &mut DMatrix<f64>, inv: &mut DMatrix<f64>) -> bool {
    let n = a.nrows();
    l.copy_from(a);
    // Left-looking, column-major: column j -= Σ_{k<j} L[j,k] L[j.., k], then scale by 1/√pivot.
    let ls = l.as_mut_slice();
    for j in 0..n {
        for k in 0..j {
            let ljk = ls[k * n + j];
            if ljk == 0.0 {
                continue;
            }
            let (left, right) = ls.split_at_mut(j * n);
            let ck = &left[k * n + j..k * n + n];
            for (x, y) in right[j..n].iter_mut().zip(ck) {
                *x -= ljk * y;
            }
        }
        let s = ls[j * n + j];
        if !(s > 0.0) || !s.is_finite() {
            return false;
        }
        let dj = s.sqrt();
        let inv_d = 1.0 / dj;
        ls[j * n + j] = dj;
        for x in ls[j * n + j + 1..(j + 1) * n].iter_mut() {
            *x *= inv_d;
        }
    }
    // inv = L⁻ᵀ L⁻¹ = Yᵀ Y with Y = L⁻¹ (lower triangular). First Y into inv, column by column by forward
    // substitution in axpy form (L y = e_c).
    let ls = l.as_slice();
    let is = inv.as_mut_slice();
    for c in 0..n {
        let x = &mut is[c * n..(c + 1) * n];
        x.fill(0.0);
        x[c] = 1.0;
        for k in c..n {
            let yk = x[k] / ls[k * n + k];
            x[k] = yk;
            for (xi, li) in x[k + 1..].iter_mut().zip(&ls[k * n + k + 1..(k + 1) * n]) {
                *xi -= yk * li;
            }
        }
    }
    // Then (Yᵀ Y)ᵢⱼ = Σ_{k ≥ j} Y_ki Y_kj for i ≤ j, in place: column by column, the diagonal last. An entry
    // written at (i < j) overwrites a zero of Y; the diagonal Y_jj is read only by entries (i, j') with
    // i, j' ≤ j, all done by then; the strict lower triangle of Y stays until the mirror at the end.
    for j in 0..n {
        for i in 0..=j {
            let (ci, cj) = (i * n, j * n);
            let t = dot(&is[ci + j..ci + n], &is[cj + j..cj + n]);
            is[cj + i] = t;
        }
    }
    for j in 0..n {
        for i in j + 1..n {
            is[j * n + i] = is[i * n + j];
        }
    }
    true
}

/// Dot product of two equally long slices with 4 partial sums (vectorises; a plain sum is one long dependency
/// chain). Also the DDP backward pass's dot product (`control::ddp::dense`).
#[inline(always)]
pub(crate) fn dot(x: &[f64], y: &[f64]) -> f64 {
    let mut s = [0.0_f64; 4];
    let (xc, yc) = (x.chunks_exact(4), y.chunks_exact(4));
    let (xr, yr) = (xc.remainder(), yc.remainder());
    for (a, b) in xc.zip(yc) {
        for l in 0..4 {
            s[l] += a[l] * b[l];
        }
    }
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for (a, b) in xr.iter().zip(yr) {
        t += a * b;
    }
    t
}
