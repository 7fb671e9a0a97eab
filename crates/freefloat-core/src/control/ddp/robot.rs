//! The floating-base robot as a DDP action model: state `x = [q; v]` (q with the base position and
//! quaternion, Pinocchio's layout), tangent `δx = [δq; δv]` (2 nv, the base block a body-frame twist),
//! control `u = τ` (nv: base force and torque in the base frame at its origin, then joint torques; full
//! actuation, as a spacecraft with thrusters and reaction wheels allows), zero gravity or not as the model
//! says. The step is semi-implicit Euler on the group, `v⁺ = v + Δt·ABA(q, v, u)`, `q⁺ = q ⊕ Δt v⁺`.
//!
//! Step Jacobians are analytic (`step_jacobians`, from the engine's forward-dynamics derivatives), as are
//! the cost derivatives (`costs`); `fd_step` keeps the central-difference Jacobians as the test oracle.
//!
//! Rate-driven joints (`set_rate_driven`): the thesis' end effector is massless and its spherical wrist is driven
//! kinematically, the Euler-angle rates being controls (Valverde 2018, §8.4, eqs. (8.50)-(8.51)). Here the last k
//! bodies of the model may be such a tail: their inertia is ignored, the dynamics are those of the leading bodies
//! (`Model::leading_bodies`), and their controls are the joint rates, `v⁺_w = u_w`, `q⁺_w = q_w + Δt u_w`. The state
//! keeps its layout (v_w is the rate last applied, which nothing else reads).

use super::costs::{
    dual_quat_jacobian, frame_dual_quat, keep_out, placement_residual, reference_sign, CostTerm, KeepOut, Residual,
};
use super::problem::{ActionModel, NodeDiff};
use crate::data::Data;
use crate::dynamics::aba;
use crate::dynamics::derivatives::Derivatives;
use crate::error::{FfError, Result};
use crate::kinematics::{jacobian_from_data, Reference};
use crate::model::{JointType, Model};
use crate::spatial::lie::{ff_difference, ff_integrate, log6, se3_right_jacobian_inv};
use crate::spatial::V6;
use nalgebra::{DMatrix, DVector};

/// A floating-base robot over a horizon of N steps of Δt with running and terminal costs.
pub struct FloatingRobot {
    pub(crate) model: Model,
    pub(crate) data: Data,
    pub(crate) dt: f64,
    pub(crate) n: usize,
    /// Running cost terms (nodes 0..N−1).
    pub running: Vec<CostTerm>,
    /// Terminal cost terms (node N).
    pub terminal: Vec<CostTerm>,
    /// Keep-out bumps, applied at every running node.
    pub keep_out: Vec<KeepOut>,
    // Scratch (sized once).
    pub(crate) vnext: Vec<f64>,
    pub(crate) dq: Vec<f64>,
    pub(crate) jac: DMatrix<f64>,
    pub(crate) jres: DMatrix<f64>,
    pub(crate) res: DVector<f64>,
    pub(crate) xbuf: Vec<f64>,
    pub(crate) xbuf2: Vec<f64>,
    pub(crate) xnom: Vec<f64>,
    pub(crate) ubuf: Vec<f64>,
    pub(crate) dxbuf: Vec<f64>,
    pub(crate) dxbuf2: Vec<f64>,
    pub(crate) tbuf: Vec<f64>,
    /// Forward-dynamics derivatives workspace (analytic step Jacobians).
    pub(crate) deriv: Derivatives,
    /// Node k of this horizon reads reference k + offset (receding-horizon windows over a longer task; 0
    /// for an ordinary problem). Past the end of a reference table the last entry holds.
    pub(crate) offset: usize,
    /// Scratch of the full-DDP step Hessian (`step_hessian`), made on first use.
    pub(crate) hess: Option<super::workspace::HessianWork>,
    /// The rate-driven tail, if any (see the module notes).
    pub(crate) rate: Option<RateDriven>,
}

/// The dynamics of a robot whose last `k` joints are driven by their rates (a massless tail): the model of the
/// leading bodies, with its own workspaces.
#[derive(Clone)]
pub(crate) struct RateDriven {
    /// Number of rate-driven joints (the last k bodies, one coordinate each).
    pub(crate) k: usize,
    /// The leading bodies' model (nq − k, nv − k).
    pub(crate) model: Model,
    pub(crate) data: Data,
    pub(crate) deriv: Derivatives,
}

impl FloatingRobot {
    /// A robot action model. `model`: a free-base (or fixed-base) tree of revolute/prismatic joints;
    /// `dt` > 0; `n` ≥ 1 nodes; cost terms checked against the sizes (references 1 or one per node).
    pub fn new(
        model: Model,
        dt: f64,
        n: usize,
        running: Vec<CostTerm>,
        terminal: Vec<CostTerm>,
        keep_out: Vec<KeepOut>,
    ) -> Result<FloatingRobot> {
        if !(dt > 0.0) || !dt.is_finite() {
            return Err(FfError::arg("dt", format!("the time step must be positive and finite, got {dt}")));
        }
        if n == 0 {
            return Err(FfError::arg("horizon", "the horizon must have at least one node (N >= 1)"));
        }
        for i in 0..model.nbodies() {
            let ok = match model.joint_types[i] {
                JointType::Free | JointType::FixedBase => model.parents[i].is_none(),
                JointType::Revolute | JointType::Prismatic => true,
                _ => false,
            };
            if !ok {
                return Err(FfError::arg(
                    "model",
                    format!(
                        "joint '{}' ({:?}): the DDP robot model supports a free or fixed base and revolute/prismatic joints",
                        model.joint_names[i], model.joint_types[i]
                    ),
                ));
            }
        }
        let (nq, nv) = (model.nq, model.nv);
        for t in running.iter().chain(terminal.iter()) {
            t.validate(&model, n, nq + nv, nv)?;
        }
        for t in &terminal {
            if matches!(t.residual, Residual::Control { .. }) {
                return Err(FfError::arg(&t.name, "a control cost cannot be terminal"));
            }
        }
        for k in &keep_out {
            if k.iq >= nq || k.iv >= nv || !(k.width > 0.0) || !k.height.is_finite() || !k.center.is_finite() {
                return Err(FfError::arg("keep_out", format!("bad keep-out term {k:?}")));
            }
        }
        Ok(Self::build(model, dt, n, running, terminal, keep_out))
    }

    /// The fields, without the checks of `new` (its callers have checked, or cloned a checked robot).
    fn build(
        model: Model,
        dt: f64,
        n: usize,
        running: Vec<CostTerm>,
        terminal: Vec<CostTerm>,
        keep_out: Vec<KeepOut>,
    ) -> FloatingRobot {
        let (nq, nv) = (model.nq, model.nv);
        let data = Data::new(&model);
        FloatingRobot {
            offset: 0,
            hess: None,
            rate: None,
            data,
            deriv: Derivatives::new(&model),
            dt,
            n,
            running,
            terminal,
            keep_out,
            vnext: vec![0.0; nv],
            dq: vec![0.0; nv],
            jac: DMatrix::zeros(6, nv),
            jres: DMatrix::zeros(8, nv),
            res: DVector::zeros(8.max(2 * nv)),
            xbuf: vec![0.0; nq + nv],
            xbuf2: vec![0.0; nq + nv],
            xnom: vec![0.0; nq + nv],
            ubuf: vec![0.0; nv],
            dxbuf: vec![0.0; 2 * nv],
            dxbuf2: vec![0.0; 2 * nv],
            tbuf: vec![0.0; 2 * nv],
            model,
        }
    }

    /// The same problem over a window of `horizon` nodes that starts at node `offset()` of this one
    /// (receding-horizon control): same model, step, costs and reference tables (node k of the window reads
    /// reference k + offset, the last entry holding past the end). The window's terminal node uses this
    /// problem's terminal costs. Iteration-scheduled weights (Table 8.2) are frozen at their End column.
    pub fn window(&self, horizon: usize) -> Result<FloatingRobot> {
        if horizon == 0 {
            return Err(FfError::arg("horizon", "the receding horizon must have at least one node (>= 1)"));
        }
        let freeze = |terms: &[CostTerm]| -> Vec<CostTerm> {
            terms
                .iter()
                .map(|t| CostTerm {
                    name: t.name.clone(),
                    residual: t.residual.clone(),
                    weights: t.weights.frozen_end(),
                })
                .collect()
        };
        let mut w = Self::build(
            self.model.clone(),
            self.dt,
            horizon,
            freeze(&self.running),
            freeze(&self.terminal),
            self.keep_out.clone(),
        );
        w.rate = self.rate.clone();
        Ok(w)
    }

    /// Drive the last `k` joints by their rates (0: none, the default): their bodies count as massless, their
    /// controls are the joint rates instead of torques (Valverde 2018, eq. (8.51): the wrist's Euler-angle rates).
    /// Each must be a one-coordinate (revolute or prismatic) joint after the base.
    pub fn set_rate_driven(&mut self, k: usize) -> Result<()> {
        if k == 0 {
            self.rate = None;
            return Ok(());
        }
        let n = self.model.nbodies();
        if k >= n {
            return Err(FfError::arg(
                "rate_joints",
                format!("{k} rate-driven joints leave no body to carry the dynamics ({n} bodies)"),
            ));
        }
        for i in n - k..n {
            if !matches!(self.model.joint_types[i], JointType::Revolute | JointType::Prismatic) {
                return Err(FfError::arg(
                    "rate_joints",
                    format!(
                        "joint '{}' is not revolute or prismatic: only those can be rate-driven",
                        self.model.joint_names[i]
                    ),
                ));
            }
        }
        let model = self.model.leading_bodies(n - k)?;
        let (data, deriv) = (Data::new(&model), Derivatives::new(&model));
        self.rate = Some(RateDriven { k, model, data, deriv });
        Ok(())
    }

    /// Number of rate-driven joints (the last ones of the model; 0 if none).
    pub fn rate_driven(&self) -> usize {
        self.rate.as_ref().map_or(0, |r| r.k)
    }

    /// Reference offset of node 0 (see `window`).
    pub fn offset(&self) -> usize {
        self.offset
    }

    /// Make node 0 read reference `offset` (see `window`).
    pub fn set_offset(&mut self, offset: usize) {
        self.offset = offset;
    }

    /// Replace the robot's inertial parameters (one row of 10 standard parameters per body, as
    /// `Model::parameters`), keeping its layout, costs and scratch: how a controller takes an updated estimate
    /// of the plant (e.g. an online identification) without being rebuilt.
    pub fn set_parameters(&mut self, params: &[f64]) -> Result<()> {
        self.model = self.model.with_parameters(params)?;
        if let Some(r) = self.rate.as_mut() {
            r.model = r.model.with_parameters(&params[..10 * r.model.nbodies()])?;
        }
        Ok(())
    }

    /// The robot.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Time step.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// `q ⊕ δq` on the configuration group (free base: SE(3) exponential; scalar joints: addition).
    pub fn integrate_q(m: &Model, q: &[f64], dq: &[f64], out: &mut [f64]) {
        for i in 0..m.nbodies() {
            let (iq, iv) = (m.idx_q[i], m.idx_v[i]);
            match m.joint_types[i] {
                JointType::Free => ff_integrate(&q[iq..iq + 7], &dq[iv..iv + 6], &mut out[iq..iq + 7]),
                _ => {
                    for c in 0..m.nqs[i] {
                        out[iq + c] = q[iq + c] + dq[iv + c];
                    }
                }
            }
        }
    }

    /// `q1 ⊖ q0`.
    pub fn difference_q(m: &Model, q0: &[f64], q1: &[f64], out: &mut [f64]) {
        for i in 0..m.nbodies() {
            let (iq, iv) = (m.idx_q[i], m.idx_v[i]);
            match m.joint_types[i] {
                JointType::Free => ff_difference(&q0[iq..iq + 7], &q1[iq..iq + 7], &mut out[iv..iv + 6]),
                _ => {
                    for c in 0..m.nqs[i] {
                        out[iv + c] = q1[iq + c] - q0[iq + c];
                    }
                }
            }
        }
    }

    /// One semi-implicit Euler step into `xnext` (runs ABA, so `data` holds the kinematics of q after).
    pub(crate) fn step(&mut self, x: &[f64], u: &[f64], xnext: &mut [f64]) -> Result<()> {
        let (nq, nv) = (self.model.nq, self.model.nv);
        let (q, v) = x.split_at(nq);
        if let Some(r) = self.rate.as_mut() {
            // the leading bodies' dynamics; the massless tail follows its rate controls
            let (nqd, nvd) = (r.model.nq, r.model.nv);
            aba(&r.model, &mut r.data, &q[..nqd], &v[..nvd], &u[..nvd], None)?;
            for i in 0..nv {
                self.vnext[i] = if i < nvd { v[i] + self.dt * r.data.ddq[i] } else { u[i] };
                self.dq[i] = self.dt * self.vnext[i];
            }
            crate::kinematics::forward_kinematics(&self.model, &mut self.data, q)?;
        } else {
            aba(&self.model, &mut self.data, q, v, u, None)?;
            for i in 0..nv {
                self.vnext[i] = v[i] + self.dt * self.data.ddq[i];
                self.dq[i] = self.dt * self.vnext[i];
            }
        }
        let (qn, vn) = xnext.split_at_mut(nq);
        Self::integrate_q(&self.model, q, &self.dq, qn);
        vn.copy_from_slice(&self.vnext);
        Ok(())
    }

    /// Cost of one node; the kinematics of q must be in `data` (after `step` or forward kinematics).
    fn cost(&mut self, k: usize, x: &[f64], u: Option<&[f64]>) -> Result<f64> {
        let terminal = u.is_none();
        let terms = if terminal { &self.terminal } else { &self.running };
        let (nq, nv) = (self.model.nq, self.model.nv);
        let q = &x[..nq];
        let mut total = 0.0;
        for t in terms {
            let w = &t.weights.current;
            match &t.residual {
                Residual::FramePlacement { body, placement, refs } => {
                    let o_mf = self.data.o_mi[*body].compose(placement);
                    let r = log6(&refs[(k + self.offset).min(refs.len() - 1)].inv_compose(&o_mf));
                    total += (0..6).map(|i| w[i] * r[i] * r[i]).sum::<f64>();
                }
                Residual::FrameDualQuat { body, placement, refs, nearest_sign } => {
                    let o_mf = self.data.o_mi[*body].compose(placement);
                    let g = frame_dual_quat(&self.model, q, *body, placement, &o_mf)?.to_array();
                    let rf = &refs[(k + self.offset).min(refs.len() - 1)];
                    let s = reference_sign(&g, rf, *nearest_sign);
                    total += (0..8).map(|i| w[i] * (g[i] - s * rf[i]).powi(2)).sum::<f64>();
                }
                Residual::State { refs } => {
                    let xr = &refs[(k + self.offset).min(refs.len() - 1)];
                    Self::difference_q(&self.model, &xr[..nq], q, &mut self.dxbuf[..nv]);
                    for i in 0..nv {
                        self.dxbuf[nv + i] = x[nq + i] - xr[nq + i];
                    }
                    total += (0..2 * nv).map(|i| w[i] * self.dxbuf[i] * self.dxbuf[i]).sum::<f64>();
                }
                Residual::Control { refs } => {
                    let u = u.expect("control terms are running only");
                    let ur = &refs[(k + self.offset).min(refs.len() - 1)];
                    total += (0..nv).map(|i| w[i] * (u[i] - ur[i]).powi(2)).sum::<f64>();
                }
            }
        }
        if !terminal {
            for ko in &self.keep_out {
                total += keep_out(x[ko.iq], ko.center, ko.width, ko.height).0;
            }
        }
        Ok(total)
    }

    /// Cost derivatives of one node, added to `d.lx`, `d.lu`, `d.lxx`, `d.luu` (Gauss–Newton for the
    /// squared residuals: ∇ = 2 Jᵀ W r, ∇² ≈ 2 Jᵀ W J; the keep-out term exactly).
    fn cost_diff(&mut self, k: usize, x: &[f64], u: Option<&[f64]>, d: &mut NodeDiff) -> Result<()> {
        let terminal = u.is_none();
        let (nq, nv) = (self.model.nq, self.model.nv);
        let q = &x[..nq];
        let nterms = if terminal { self.terminal.len() } else { self.running.len() };
        for ti in 0..nterms {
            let t = if terminal { &self.terminal[ti] } else { &self.running[ti] };
            let w = &t.weights.current;
            match &t.residual {
                Residual::FramePlacement { body, placement, refs } => {
                    // the kinematics of q are in `data` (after `step_jacobians` or forward kinematics)
                    jacobian_from_data(&self.model, &self.data, *body, placement, Reference::Local, &mut self.jac);
                    let o_mf = self.data.o_mi[*body].compose(placement);
                    let (r, jl) = placement_residual(&o_mf, &refs[(k + self.offset).min(refs.len() - 1)]);
                    // J = Jr⁻¹(r) J_local (6 × nv), then 2 Jᵀ W r and 2 Jᵀ W J.
                    for c in 0..nv {
                        let col = jl * V6::from_iterator((0..6).map(|i| self.jac[(i, c)]));
                        for i in 0..6 {
                            self.jres[(i, c)] = col[i];
                        }
                    }
                    for i in 0..6 {
                        self.res[i] = r[i];
                    }
                    add_gauss_newton(&self.jres, 6, &self.res, w, d, nv);
                }
                Residual::FrameDualQuat { body, placement, refs, nearest_sign } => {
                    jacobian_from_data(&self.model, &self.data, *body, placement, Reference::Local, &mut self.jac);
                    let o_mf = self.data.o_mi[*body].compose(placement);
                    let g = frame_dual_quat(&self.model, q, *body, placement, &o_mf)?;
                    dual_quat_jacobian(&g, &o_mf, &self.jac, &mut self.jres);
                    let ga = g.to_array();
                    let rf = &refs[(k + self.offset).min(refs.len() - 1)];
                    let s = reference_sign(&ga, rf, *nearest_sign);
                    for i in 0..8 {
                        self.res[i] = ga[i] - s * rf[i];
                    }
                    add_gauss_newton(&self.jres, 8, &self.res, w, d, nv);
                }
                Residual::State { refs } => {
                    let xr = &refs[(k + self.offset).min(refs.len() - 1)];
                    Self::difference_q(&self.model, &xr[..nq], q, &mut self.dxbuf[..nv]);
                    for i in 0..nv {
                        self.dxbuf[nv + i] = x[nq + i] - xr[nq + i];
                    }
                    // ∂(q ⊖ q_ref)/∂δq: Jr⁻¹ of the base block (the tangent is applied on the right), identity
                    // elsewhere; velocities: identity.
                    for i in 0..2 * nv {
                        d.lx[i] += 2.0 * w[i] * self.dxbuf[i];
                        d.lxx[(i, i)] += 2.0 * w[i];
                    }
                    if self.model.joint_types[0] == JointType::Free && w[..6].iter().any(|&v| v != 0.0) {
                        // Replace the base block by its exact Gauss–Newton form.
                        let r = V6::from_column_slice(&self.dxbuf[..6]);
                        let j = se3_right_jacobian_inv(&r);
                        for i in 0..6 {
                            d.lx[i] -= 2.0 * w[i] * self.dxbuf[i];
                            d.lxx[(i, i)] -= 2.0 * w[i];
                        }
                        for a in 0..6 {
                            let mut g = 0.0;
                            for i in 0..6 {
                                g += j[(i, a)] * w[i] * r[i];
                            }
                            d.lx[a] += 2.0 * g;
                            for b in 0..6 {
                                let mut h = 0.0;
                                for i in 0..6 {
                                    h += j[(i, a)] * w[i] * j[(i, b)];
                                }
                                d.lxx[(a, b)] += 2.0 * h;
                            }
                        }
                    }
                }
                Residual::Control { refs } => {
                    let u = u.expect("control terms are running only");
                    let ur = &refs[(k + self.offset).min(refs.len() - 1)];
                    for i in 0..nv {
                        d.lu[i] += 2.0 * w[i] * (u[i] - ur[i]);
                        d.luu[(i, i)] += 2.0 * w[i];
                    }
                }
            }
        }
        if !terminal {
            for ko in &self.keep_out {
                let (_, c1, c2) = keep_out(x[ko.iq], ko.center, ko.width, ko.height);
                d.lx[ko.iv] += c1;
                d.lxx[(ko.iv, ko.iv)] += c2;
            }
        }
        Ok(())
    }
}

/// `lx[..nv] += 2 Jᵀ W r`, `lxx[..nv, ..nv] += 2 Jᵀ W J` for a residual of `dim` rows.
fn add_gauss_newton(j: &DMatrix<f64>, dim: usize, r: &DVector<f64>, w: &[f64], d: &mut NodeDiff, nv: usize) {
    for a in 0..nv {
        let mut g = 0.0;
        for i in 0..dim {
            g += j[(i, a)] * w[i] * r[i];
        }
        d.lx[a] += 2.0 * g;
        for b in a..nv {
            let mut h = 0.0;
            for i in 0..dim {
                h += j[(i, a)] * w[i] * j[(i, b)];
            }
            d.lxx[(a, b)] += 2.0 * h;
            if b != a {
                d.lxx[(b, a)] += 2.0 * h;
            }
        }
    }
}

impl ActionModel for FloatingRobot {
    fn nx(&self) -> usize {
        self.model.nq + self.model.nv
    }
    fn ndx(&self) -> usize {
        2 * self.model.nv
    }
    fn nu(&self) -> usize {
        self.model.nv
    }
    fn horizon(&self) -> usize {
        self.n
    }
    fn integrate(&self, x: &[f64], dx: &[f64], out: &mut [f64]) {
        let (nq, nv) = (self.model.nq, self.model.nv);
        Self::integrate_q(&self.model, &x[..nq], &dx[..nv], &mut out[..nq]);
        for i in 0..nv {
            out[nq + i] = x[nq + i] + dx[nv + i];
        }
    }
    fn difference(&self, x0: &[f64], x1: &[f64], out: &mut [f64]) {
        let (nq, nv) = (self.model.nq, self.model.nv);
        Self::difference_q(&self.model, &x0[..nq], &x1[..nq], &mut out[..nv]);
        for i in 0..nv {
            out[nv + i] = x1[nq + i] - x0[nq + i];
        }
    }
    fn calc(&mut self, k: usize, x: &[f64], u: &[f64], xnext: &mut [f64]) -> Result<f64> {
        self.step(x, u, xnext)?;
        self.cost(k, x, Some(u))
    }
    fn calc_terminal(&mut self, x: &[f64]) -> Result<f64> {
        crate::kinematics::forward_kinematics(&self.model, &mut self.data, &x[..self.model.nq])?;
        self.cost(self.n, x, None)
    }
    fn calc_diff(&mut self, k: usize, x: &[f64], u: &[f64], d: &mut NodeDiff) -> Result<()> {
        // `step_jacobians` writes every entry of fx and fu; the cost terms add into the rest.
        d.clear_costs();
        self.step_jacobians(x, u, &mut d.fx, &mut d.fu)?;
        self.cost_diff(k, x, Some(u), d)
    }
    fn calc_diff_terminal(&mut self, x: &[f64], d: &mut NodeDiff) -> Result<()> {
        d.clear();
        crate::kinematics::forward_kinematics(&self.model, &mut self.data, &x[..self.model.nq])?;
        self.cost_diff(self.n, x, None, d)
    }
    fn dynamics_hessian(
        &mut self,
        _k: usize,
        x: &[f64],
        u: &[f64],
        lambda: &[f64],
        out: &mut super::problem::DynamicsHessian,
    ) -> Result<bool> {
        self.step_hessian(x, u, lambda, out)?;
        Ok(true)
    }
    fn schedule_end(&self) -> usize {
        self.running.iter().chain(self.terminal.iter()).map(|t| t.weights.schedule_end()).max().unwrap_or(0)
    }
    fn set_iteration(&mut self, i: usize) -> bool {
        let mut changed = false;
        for t in self.running.iter_mut().chain(self.terminal.iter_mut()) {
            changed |= t.weights.set_iteration(i);
        }
        changed
    }
}
