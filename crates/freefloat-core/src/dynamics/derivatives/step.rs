//! One discrete step `x⁺ = step(x, u, dt)` of the forward dynamics and its derivatives in the
//! tangent error state (`x = [q; v]`, tangent `[δq; δv]` of size 2nv, u = τ).
//!
//! - **Semi-implicit (symplectic) Euler**, as Crocoddyl's `IntegratedActionModelEuler`:
//!   `v⁺ = v + a dt`, `q⁺ = q ⊕ v⁺ dt`, with `a = FD(q, v, τ)`.
//! - **RK4 on the Lie group** (Runge-Kutta-Munthe-Kaas): the stages live in the tangent
//!   coordinates δ about q (`q_s = q ⊕ δ_s`), and a stage's body velocity is mapped to the rate of δ
//!   through `dexp⁻¹` (`Jr(δ)⁻¹` on rotations; `Exp(δ_ang)` on the base's linear part), so the step is
//!   fourth order on R³ × SO(3). It is the step the engine's simulator takes with the torque held
//!   over the step. τ is held constant over the step (zero-order hold).
//!
//! The control is the full generalized force τ (nv: base wrench in base axes, then joint forces).
//! For an under-actuated system with `τ = B u`, use `Fu · B` (for a free-floating robot whose base
//! is not actuated: the last nv − 6 columns of `Fu`).

use super::rnea_derivatives::aba_derivatives_unchecked;
use super::{check_workspace, gemm, Derivatives};
use crate::check::{check_args, with_unit_q, Args};
use crate::config::{integrate_jacobians_unchecked, integrate_unchecked, tangent_map, tangent_map_jacobians};
use crate::data::Data;
use crate::dynamics::hybrid_aba_unchecked;
use crate::error::{FfError, Result};
use crate::model::Model;
use nalgebra::DMatrix;

/// Discretisation of one step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scheme {
    /// Semi-implicit Euler: `v⁺ = v + a dt`, `q⁺ = q ⊕ v⁺ dt` (one ABA).
    Euler,
    /// Classical RK4 on the Lie group (four ABA, dexp⁻¹-corrected stages).
    Rk4,
}

impl Scheme {
    /// Parse `"euler"` or `"rk4"`.
    pub fn from_name(s: &str) -> Result<Scheme> {
        match s {
            "euler" => Ok(Scheme::Euler),
            "rk4" => Ok(Scheme::Rk4),
            other => Err(FfError::arg("scheme", format!("expected 'euler' or 'rk4', got '{other}'"))),
        }
    }
}

const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
const B: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];

/// Scratch of the step routines (x: nv × 2nv, u: nv × nv).
#[derive(Clone, Debug, Default)]
pub(crate) struct StepWork {
    qs: Vec<f64>,
    delta: Vec<f64>,
    vs: Vec<f64>,
    k: Vec<f64>,
    sum_k: Vec<f64>,
    sum_a: Vec<f64>,
    ddelta_x: DMatrix<f64>,
    dq_x: DMatrix<f64>,
    dv_x: DMatrix<f64>,
    dk_x: DMatrix<f64>,
    da_x: DMatrix<f64>,
    sum_dk_x: DMatrix<f64>,
    ddelta_u: DMatrix<f64>,
    dq_u: DMatrix<f64>,
    dv_u: DMatrix<f64>,
    dk_u: DMatrix<f64>,
    da_u: DMatrix<f64>,
    sum_dk_u: DMatrix<f64>,
    jq: DMatrix<f64>,
    jd: DMatrix<f64>,
    td: DMatrix<f64>,
    tv: DMatrix<f64>,
}

impl StepWork {
    pub(crate) fn new(m: &Model) -> StepWork {
        let nv = m.nv;
        let x = || DMatrix::zeros(nv, 2 * nv);
        let u = || DMatrix::zeros(nv, nv);
        StepWork {
            qs: vec![0.0; m.nq],
            delta: vec![0.0; nv],
            vs: vec![0.0; nv],
            k: vec![0.0; nv],
            sum_k: vec![0.0; nv],
            sum_a: vec![0.0; nv],
            ddelta_x: x(),
            dq_x: x(),
            dv_x: x(),
            dk_x: x(),
            da_x: x(),
            sum_dk_x: x(),
            ddelta_u: u(),
            dq_u: u(),
            dv_u: u(),
            dk_u: u(),
            da_u: u(),
            sum_dk_u: u(),
            jq: u(),
            jd: u(),
            td: u(),
            tv: u(),
        }
    }
}

fn check_step(m: &Model, d: &Data, w: &Derivatives, q: &[f64], v: &[f64], tau: &[f64], dt: f64) -> Result<bool> {
    let fix = check_args(m, Some(d), &Args::qv(q, v).nv("tau", tau))?;
    check_workspace(m, w)?;
    if !(dt > 0.0) || !dt.is_finite() {
        return Err(FfError::arg("dt", format!("must be a positive finite time step, got {dt}")));
    }
    Ok(fix)
}

/// One step from (q, v) under τ: writes `w.q_next`, `w.v_next`. Checks every argument.
#[allow(clippy::too_many_arguments)]
pub fn step(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    dt: f64,
    scheme: Scheme,
) -> Result<()> {
    let fix = check_step(m, d, w, q, v, tau, dt)?;
    with_scratch(w, |w, rk| with_unit_q(m, d, q, fix, |d, q| run(m, d, w, rk, q, v, tau, dt, scheme, false)))
}

/// One step and its derivatives: `w.q_next`, `w.v_next`, `w.fx` (2nv × 2nv) and `w.fu` (2nv × nv),
/// in the tangent error state of the module documentation (rows and columns `[δq; δv]`). Also leaves
/// the forward-dynamics derivatives of the last stage evaluated in `w.da_dq`, `w.da_dv`, `w.minv`,
/// `w.ddq` (for Euler: at (q, v, τ)). Checks every argument.
#[allow(clippy::too_many_arguments)]
pub fn step_derivatives(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    dt: f64,
    scheme: Scheme,
) -> Result<()> {
    let fix = check_step(m, d, w, q, v, tau, dt)?;
    with_scratch(w, |w, rk| with_unit_q(m, d, q, fix, |d, q| run(m, d, w, rk, q, v, tau, dt, scheme, true)))
}

/// Lend the step scratch out of `w` for the duration of `f` (a move, no allocation).
fn with_scratch<T>(w: &mut Derivatives, f: impl FnOnce(&mut Derivatives, &mut StepWork) -> T) -> T {
    let mut rk = std::mem::take(&mut w.rk);
    let r = f(w, &mut rk);
    w.rk = rk;
    r
}

#[allow(clippy::too_many_arguments)]
fn run(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    rk: &mut StepWork,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    dt: f64,
    scheme: Scheme,
    derivs: bool,
) -> Result<()> {
    match scheme {
        Scheme::Euler => euler(m, d, w, rk, q, v, tau, dt, derivs),
        Scheme::Rk4 => rk4(m, d, w, rk, q, v, tau, dt, derivs),
    }
}

/// `y += a x` (same shapes).
fn add_scaled(y: &mut nalgebra::DMatrixViewMut<f64>, a: f64, x: &DMatrix<f64>) {
    for (yi, xi) in y.iter_mut().zip(x.iter()) {
        *yi += a * xi;
    }
}

fn finite(x: &[f64]) -> Result<()> {
    match x.iter().position(|a| !a.is_finite()) {
        Some(k) => Err(FfError::Numerical(format!("acceleration {k} is not finite"))),
        None => Ok(()),
    }
}

/// Forward dynamics at (q, v, τ) into `w.ddq`, with its derivatives when `derivs`.
fn fd(m: &Model, d: &mut Data, w: &mut Derivatives, q: &[f64], v: &[f64], tau: &[f64], derivs: bool) -> Result<()> {
    if derivs {
        aba_derivatives_unchecked(m, d, w, q, v, tau, None)?;
    } else {
        hybrid_aba_unchecked(m, d, q, v, tau, None, None)?;
        w.ddq.copy_from_slice(&d.ddq);
    }
    finite(&w.ddq)
}

/// Semi-implicit Euler (Crocoddyl's `IntegratedActionModelEuler`, with this module's ⊕):
/// `∂v⁺/∂q = dt A_q`, `∂v⁺/∂v = I + dt A_v`, `∂v⁺/∂u = dt M⁻¹`,
/// `∂q⁺/∂q = J_q + dt J_δ ∂v⁺/∂q`, `∂q⁺/∂(v, u) = dt J_δ ∂v⁺/∂(v, u)`, with J_q, J_δ the Jacobians of
/// `q ⊕ δ` at δ = v⁺ dt.
#[allow(clippy::too_many_arguments)]
fn euler(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    rk: &mut StepWork,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    dt: f64,
    derivs: bool,
) -> Result<()> {
    let nv = m.nv;
    fd(m, d, w, q, v, tau, derivs)?;
    for k in 0..nv {
        w.v_next[k] = v[k] + w.ddq[k] * dt;
        rk.delta[k] = w.v_next[k] * dt;
    }
    integrate_unchecked(m, q, &rk.delta, &mut w.q_next);
    if !derivs {
        return Ok(());
    }
    integrate_jacobians_unchecked(m, &rk.delta, Some(&mut rk.jq), Some(&mut rk.jd));
    // velocity rows [dt A_q, I + dt A_v] and dt M⁻¹, kept in dv_x / dv_u
    rk.dv_x.view_mut((0, 0), (nv, nv)).copy_from(&w.da_dq);
    rk.dv_x.view_mut((0, nv), (nv, nv)).copy_from(&w.da_dv);
    rk.dv_x *= dt;
    for k in 0..nv {
        rk.dv_x[(k, nv + k)] += 1.0;
    }
    rk.dv_u.copy_from(&w.minv);
    rk.dv_u *= dt;
    w.fx.view_mut((nv, 0), (nv, 2 * nv)).copy_from(&rk.dv_x);
    w.fu.view_mut((nv, 0), (nv, nv)).copy_from(&rk.dv_u);
    // configuration rows: J_q [I 0] + dt J_δ ∂v⁺
    gemm(&mut rk.dq_x, dt, &rk.jd, &rk.dv_x, 0.0);
    let mut fq = w.fx.view_mut((0, 0), (nv, 2 * nv));
    fq.copy_from(&rk.dq_x);
    let mut fqq = w.fx.view_mut((0, 0), (nv, nv));
    fqq += &rk.jq;
    gemm(&mut w.fu.view_mut((0, 0), (nv, nv)), dt, &rk.jd, &rk.dv_u, 0.0);
    Ok(())
}

/// RK4 on the Lie group (RKMK). Stage s: `δ_s = c_s h K_{s−1}`, `q_s = q ⊕ δ_s`,
/// `v_s = v + c_s h a_{s−1}`, `a_s = FD(q_s, v_s, τ)`, `K_s = T(δ_s, v_s)` (the tangent map, dexp⁻¹);
/// `q⁺ = q ⊕ h Σ b_s K_s`, `v⁺ = v + h Σ b_s a_s`. Derivatives by the chain rule through every
/// stage: `∂q_s = J_q(δ_s)[I 0] + J_δ(δ_s) ∂δ_s`, `∂a_s = A_q ∂q_s + A_v ∂v_s (+ M⁻¹ for u)`,
/// `∂K_s = T_δ ∂δ_s + T_v ∂v_s`.
///
/// This is RK4's stage loop written out, not the engine's `rk::step` (which the simulator, the concurrent-learning
/// driver and the adaptive controller share): each stage here also carries its Jacobians (nv × 2nv and nv × nv
/// matrices), propagated by the chain rule through the same recursion, `∂δ_{s+1} = c_{s+1} h ∂K_s`, and the stage
/// lives in the derivatives' chart (`config::integrate`, `config::tangent_map`), so its states and rates are not the
/// simulator's rows. `tests/test_derivatives.py::test_rk4_step_is_the_simulators_step` checks that its step is the
/// simulator's to 1e-12.
#[allow(clippy::too_many_arguments)]
fn rk4(
    m: &Model,
    d: &mut Data,
    w: &mut Derivatives,
    rk: &mut StepWork,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    h: f64,
    derivs: bool,
) -> Result<()> {
    let nv = m.nv;
    rk.delta.fill(0.0);
    rk.vs.copy_from_slice(v);
    rk.sum_k.fill(0.0);
    rk.sum_a.fill(0.0);
    if derivs {
        rk.ddelta_x.fill(0.0);
        rk.ddelta_u.fill(0.0);
        rk.dv_x.fill(0.0);
        for k in 0..nv {
            rk.dv_x[(k, nv + k)] = 1.0;
        }
        rk.dv_u.fill(0.0);
        rk.sum_dk_x.fill(0.0);
        rk.sum_dk_u.fill(0.0);
        // Σ b ∂a accumulates in the velocity rows of fx / fu
        w.fx.fill(0.0);
        w.fu.fill(0.0);
    }
    for s in 0..4 {
        integrate_unchecked(m, q, &rk.delta, &mut rk.qs);
        fd(m, d, w, &rk.qs, &rk.vs, tau, derivs)?;
        tangent_map(m, &rk.delta, &rk.vs, &mut rk.k);
        for k in 0..nv {
            rk.sum_k[k] += B[s] * rk.k[k];
            rk.sum_a[k] += B[s] * w.ddq[k];
        }
        if derivs {
            integrate_jacobians_unchecked(m, &rk.delta, Some(&mut rk.jq), Some(&mut rk.jd));
            gemm(&mut rk.dq_x, 1.0, &rk.jd, &rk.ddelta_x, 0.0);
            let mut dqq = rk.dq_x.view_mut((0, 0), (nv, nv));
            dqq += &rk.jq;
            gemm(&mut rk.dq_u, 1.0, &rk.jd, &rk.ddelta_u, 0.0);
            gemm(&mut rk.da_x, 1.0, &w.da_dq, &rk.dq_x, 0.0);
            gemm(&mut rk.da_x, 1.0, &w.da_dv, &rk.dv_x, 1.0);
            rk.da_u.copy_from(&w.minv);
            gemm(&mut rk.da_u, 1.0, &w.da_dq, &rk.dq_u, 1.0);
            gemm(&mut rk.da_u, 1.0, &w.da_dv, &rk.dv_u, 1.0);
            tangent_map_jacobians(m, &rk.delta, &rk.vs, &mut rk.td, &mut rk.tv);
            gemm(&mut rk.dk_x, 1.0, &rk.td, &rk.ddelta_x, 0.0);
            gemm(&mut rk.dk_x, 1.0, &rk.tv, &rk.dv_x, 1.0);
            gemm(&mut rk.dk_u, 1.0, &rk.td, &rk.ddelta_u, 0.0);
            gemm(&mut rk.dk_u, 1.0, &rk.tv, &rk.dv_u, 1.0);
            add_scaled(&mut rk.sum_dk_x.view_mut((0, 0), (nv, 2 * nv)), B[s], &rk.dk_x);
            add_scaled(&mut rk.sum_dk_u.view_mut((0, 0), (nv, nv)), B[s], &rk.dk_u);
            add_scaled(&mut w.fx.view_mut((nv, 0), (nv, 2 * nv)), B[s], &rk.da_x);
            add_scaled(&mut w.fu.view_mut((nv, 0), (nv, nv)), B[s], &rk.da_u);
        }
        if s < 3 {
            let c = C[s + 1] * h;
            for k in 0..nv {
                rk.delta[k] = c * rk.k[k];
                rk.vs[k] = v[k] + c * w.ddq[k];
            }
            if derivs {
                // ∂δ_{s+1} = c h ∂K_s, ∂v_{s+1} = [0 I] + c h ∂a_s
                rk.ddelta_x.copy_from(&rk.dk_x);
                rk.ddelta_x *= c;
                rk.ddelta_u.copy_from(&rk.dk_u);
                rk.ddelta_u *= c;
                rk.dv_x.copy_from(&rk.da_x);
                rk.dv_x *= c;
                for k in 0..nv {
                    rk.dv_x[(k, nv + k)] += 1.0;
                }
                rk.dv_u.copy_from(&rk.da_u);
                rk.dv_u *= c;
            }
        }
    }
    for k in 0..nv {
        rk.delta[k] = h * rk.sum_k[k];
        w.v_next[k] = v[k] + h * rk.sum_a[k];
    }
    integrate_unchecked(m, q, &rk.delta, &mut w.q_next);
    if !derivs {
        return Ok(());
    }
    integrate_jacobians_unchecked(m, &rk.delta, Some(&mut rk.jq), Some(&mut rk.jd));
    {
        let mut fv = w.fx.view_mut((nv, 0), (nv, 2 * nv));
        fv *= h;
        for k in 0..nv {
            fv[(k, nv + k)] += 1.0;
        }
    }
    w.fu.view_mut((nv, 0), (nv, nv)).scale_mut(h);
    gemm(&mut w.fx.view_mut((0, 0), (nv, 2 * nv)), h, &rk.jd, &rk.sum_dk_x, 0.0);
    let mut fqq = w.fx.view_mut((0, 0), (nv, nv));
    fqq += &rk.jq;
    gemm(&mut w.fu.view_mut((0, 0), (nv, nv)), h, &rk.jd, &rk.sum_dk_u, 0.0);
    Ok(())
}
