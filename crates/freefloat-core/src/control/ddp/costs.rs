//! Costs of the chapter 8 problems (Valverde 2018, eqs. (8.52), (8.56)): weighted squared residuals in
//! the thesis' form `Σᵢ wᵢ rᵢ²` (no ½, no Δt: eq. (8.52), not the ½-weighted form of (8.11)), with Gauss–Newton
//! Hessians `2 Jᵀ W J`, and the soft keep-out bump with its exact derivatives.
//!
//! Residuals: the end-effector pose as `log6(M_ref⁻¹ M)` (the metric Crocoddyl uses) or as the thesis'
//! component-wise dual-quaternion difference `q_G − q_D` (eq. (8.52)); a state residual `x ⊖ x_ref`
//! (the base dual-velocity penalty is its velocity block); a control residual `u − u_ref`.
//! Weights may follow the iteration schedule of Table 8.2.

use crate::dualquat::{pose, DualQuat, Quat};
use crate::error::{FfError, Result};
use crate::model::{JointType, Model};
use crate::spatial::lie::{log6, se3_right_jacobian_inv};
use crate::spatial::{Se3, V3, V6};

/// Piecewise-linear iteration schedule (Valverde 2018, §8.6, eqs. (8.63)–(8.64), Table 8.2):
/// S for i ≤ i1, S→M on (i1, i2), M on [i2, i3], M→E on (i3, i4), E for i ≥ i4. The profile of Fig. 8.6
/// is not in the text; piecewise linear is our reading.
pub fn schedule_blend(i: usize, breaks: [usize; 4]) -> (f64, f64, f64) {
    let [i1, i2, i3, i4] = breaks;
    let ramp = |a: usize, b: usize| if b > a { (i as f64 - a as f64) / (b as f64 - a as f64) } else { 1.0 };
    if i <= i1 {
        (1.0, 0.0, 0.0)
    } else if i < i2 {
        let t = ramp(i1, i2);
        (1.0 - t, t, 0.0)
    } else if i <= i3 {
        (0.0, 1.0, 0.0)
    } else if i < i4 {
        let t = ramp(i3, i4);
        (0.0, 1.0 - t, t)
    } else {
        (0.0, 0.0, 1.0)
    }
}

/// Weights of one residual, constant or iteration-scheduled.
#[derive(Clone, Debug, PartialEq)]
pub struct Weights {
    start: Vec<f64>,
    medium: Vec<f64>,
    end: Vec<f64>,
    breaks: Option<[usize; 4]>,
    /// The weights in force at the current iteration.
    pub current: Vec<f64>,
}

impl Weights {
    /// Constant weights (each ≥ 0 and finite).
    pub fn constant(w: Vec<f64>) -> Result<Weights> {
        check_weights("weights", &w)?;
        Ok(Weights { start: w.clone(), medium: w.clone(), end: w.clone(), breaks: None, current: w })
    }
    /// Scheduled weights: `start`, `medium`, `end` (same length, ≥ 0) and breakpoints i1 ≤ i2 ≤ i3 ≤ i4.
    pub fn scheduled(start: Vec<f64>, medium: Vec<f64>, end: Vec<f64>, breaks: [usize; 4]) -> Result<Weights> {
        check_weights("start", &start)?;
        check_weights("medium", &medium)?;
        check_weights("end", &end)?;
        if medium.len() != start.len() || end.len() != start.len() {
            return Err(FfError::arg("weights", "start, medium and end weights must have the same length"));
        }
        if !(breaks[0] <= breaks[1] && breaks[1] <= breaks[2] && breaks[2] <= breaks[3]) {
            return Err(FfError::arg("breakpoints", format!("need i1 <= i2 <= i3 <= i4, got {breaks:?}")));
        }
        let current = start.clone();
        Ok(Weights { start, medium, end, breaks: Some(breaks), current })
    }
    /// The End-column weights, held constant (what a receding-horizon controller uses: it re-solves from
    /// warm starts and has no iteration count to schedule against).
    pub fn frozen_end(&self) -> Weights {
        let e = self.end.clone();
        Weights { start: e.clone(), medium: e.clone(), end: e.clone(), breaks: None, current: e }
    }
    /// The last iteration at which the weights change (the fourth breakpoint; 0 for constant weights).
    pub fn schedule_end(&self) -> usize {
        self.breaks.map(|b| b[3]).unwrap_or(0)
    }
    /// Number of weights.
    pub fn len(&self) -> usize {
        self.current.len()
    }
    /// Whether there are no weights.
    pub fn is_empty(&self) -> bool {
        self.current.is_empty()
    }
    /// Set the weights of iteration i (from 1); true if they changed.
    pub fn set_iteration(&mut self, i: usize) -> bool {
        let Some(b) = self.breaks else { return false };
        let (a, m, e) = schedule_blend(i, b);
        let mut changed = false;
        for j in 0..self.current.len() {
            let w = a * self.start[j] + m * self.medium[j] + e * self.end[j];
            changed |= w != self.current[j];
            self.current[j] = w;
        }
        changed
    }
}

fn check_weights(name: &str, w: &[f64]) -> Result<()> {
    if w.iter().any(|x| !x.is_finite() || *x < 0.0) {
        return Err(FfError::arg(name, format!("weights must be finite and >= 0, got {w:?}")));
    }
    Ok(())
}

/// Soft keep-out bump `c(θ) = K / (exp((θ − θ̄)²/ℓ²) + 1)` (Valverde 2018, eq. (8.56)), with
/// its first and second derivatives (σ(s) = 1/(eˢ + 1), s = (θ − θ̄)²/ℓ²).
pub fn keep_out(theta: f64, center: f64, width: f64, height: f64) -> (f64, f64, f64) {
    let e = theta - center;
    let s = e * e / (width * width);
    if s > 700.0 {
        return (0.0, 0.0, 0.0);
    }
    // σ' = −σ(1 − σ), σ'' = σ(1 − σ)(1 − 2σ): the same as the e^s forms, without overflowing e^{2s}.
    let sig = 1.0 / (s.exp() + 1.0);
    let one_minus = 1.0 / (1.0 + (-s).exp());
    let dsig = -sig * one_minus;
    let d2sig = sig * one_minus * (1.0 - 2.0 * sig);
    let ds = 2.0 * e / (width * width);
    (height * sig, height * dsig * ds, height * (d2sig * ds * ds + dsig * 2.0 / (width * width)))
}

/// What a cost term penalises.
#[derive(Clone, Debug)]
pub enum Residual {
    /// `log6(M_ref⁻¹ M_frame)` (6, linear part first) of the frame `placement` on `body`; one reference or
    /// one per node (N + 1).
    FramePlacement {
        /// Body index.
        body: usize,
        /// Frame placement in the body.
        placement: Se3,
        /// References.
        refs: Vec<Se3>,
    },
    /// `q_G − q_D` (8, thesis layout [real w x y z, dual w x y z], translation first, eq. (3.2)); the
    /// frame's dual quaternion is composed along the chain (eq. (8.46)) so it stays continuous in the
    /// joint angles and is never properised.
    FrameDualQuat {
        /// Body index.
        body: usize,
        /// Frame placement in the body.
        placement: Se3,
        /// References (thesis layout).
        refs: Vec<[f64; 8]>,
        /// Compare with whichever of ±q_D is nearer (`q_G − s q_D`, s = sign(q_G,r · q_D,r)), so that the cost
        /// measures the pose and not the quaternion's sheet; false: the thesis' literal `q_G − q_D`, which is
        /// maximal (4 w) at the exact pose on the other sheet (a reference that turns by 2π ends at −q).
        nearest_sign: bool,
    },
    /// `x ⊖ x_ref` (ndx); one reference or one per node.
    State {
        /// References (nx each).
        refs: Vec<Vec<f64>>,
    },
    /// `u − u_ref` (nu), running nodes only.
    Control {
        /// References (nu each).
        refs: Vec<Vec<f64>>,
    },
}

/// A weighted squared residual `Σᵢ wᵢ rᵢ²`.
#[derive(Clone, Debug)]
pub struct CostTerm {
    /// Name (for reports).
    pub name: String,
    /// The residual.
    pub residual: Residual,
    /// Its weights (one per residual entry).
    pub weights: Weights,
}

/// The keep-out bump on one joint coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct KeepOut {
    /// Index in q (and in the tangent, for a scalar joint after the base: `iv`).
    pub iq: usize,
    /// Tangent index.
    pub iv: usize,
    /// θ̄ (rad).
    pub center: f64,
    /// ℓ (rad).
    pub width: f64,
    /// K.
    pub height: f64,
}

impl CostTerm {
    /// Residual size for a model with nv velocities and nu controls.
    pub fn dim(&self, nv: usize, nu: usize) -> usize {
        match self.residual {
            Residual::FramePlacement { .. } => 6,
            Residual::FrameDualQuat { .. } => 8,
            Residual::State { .. } => 2 * nv,
            Residual::Control { .. } => nu,
        }
    }
    /// Check sizes against the model and horizon (references: 1 or N + 1 for states and poses, 1 or N
    /// for controls) and the weights' length.
    pub fn validate(&self, m: &Model, n: usize, nx: usize, nu: usize) -> Result<()> {
        let name = &self.name;
        let (len, per_node, each) = match &self.residual {
            Residual::FramePlacement { body, refs, .. } => {
                crate::check::check_body(m, "body", *body)?;
                (refs.len(), n + 1, None)
            }
            Residual::FrameDualQuat { body, refs, .. } => {
                crate::check::check_body(m, "body", *body)?;
                if refs.iter().flatten().any(|v| !v.is_finite()) {
                    return Err(FfError::arg(&format!("{name}.reference"), "non-finite entries"));
                }
                (refs.len(), n + 1, None)
            }
            Residual::State { refs } => (refs.len(), n + 1, Some((refs, nx))),
            Residual::Control { refs } => (refs.len(), n, Some((refs, nu))),
        };
        if len != 1 && len != per_node {
            return Err(FfError::arg(
                &format!("{name}.reference"),
                format!("need 1 reference or one per node ({per_node}), got {len}"),
            ));
        }
        if let Some((refs, size)) = each {
            for (k, r) in refs.iter().enumerate() {
                crate::check::check_vec(&format!("{name}.reference[{k}]"), r, size)?;
            }
        }
        let dim = self.dim(m.nv, nu);
        if self.weights.len() != dim {
            return Err(FfError::arg(
                &format!("{name}.weights"),
                format!("need {dim} weights (one per residual entry), got {}", self.weights.len()),
            ));
        }
        Ok(())
    }
}

/// The frame's pose as a dual quaternion (thesis layout), composed along the chain from the base
/// quaternion of `q` and the joint rotations, so that it is continuous in q (eq. (8.46)). The
/// translation is taken from forward kinematics (`o_mf`, already computed).
pub fn frame_dual_quat(m: &Model, q: &[f64], body: usize, placement: &Se3, o_mf: &Se3) -> Result<DualQuat> {
    // Walk from the body to the root, left-multiplying each joint's (placement ∘ joint) rotation, so the
    // product is q_base q_1 ... q_body q_frame without a buffer.
    let mut rot = Quat::from_rotation_matrix(&placement.rot);
    let mut j = Some(body);
    while let Some(i) = j {
        let iq = m.idx_q[i];
        let joint = match m.joint_types[i] {
            JointType::Free => Quat::from_xyzw(&[q[iq + 3], q[iq + 4], q[iq + 5], q[iq + 6]]),
            JointType::Revolute => Quat::from_axis_angle(&m.axes[i], q[iq]),
            JointType::Prismatic | JointType::FixedBase => Quat::new(1.0, 0.0, 0.0, 0.0),
            other => {
                return Err(FfError::arg(
                    "model",
                    format!("the dual-quaternion pose cost does not support {other:?} joints"),
                ))
            }
        };
        let place = if m.parents[i].is_some() {
            Quat::from_rotation_matrix(&m.placements[i].rot)
        } else {
            Quat::new(1.0, 0.0, 0.0, 0.0)
        };
        rot = place.mul(&joint).mul(&rot);
        j = m.parents[i];
    }
    Ok(pose::from_rotation_translation(&rot, &o_mf.trans))
}

/// Residual of a frame-placement term and its Jacobian factor: `r = log6(M_ref⁻¹ M)`, `∂r/∂δ = Jr⁻¹(r) J_local`.
pub fn placement_residual(o_mf: &Se3, reference: &Se3) -> (V6, nalgebra::Matrix6<f64>) {
    let r = log6(&reference.inv_compose(o_mf));
    (r, se3_right_jacobian_inv(&r))
}

/// The sign s ∈ {1, −1} with which the reference enters the dual-quaternion residual `q_G − s q_D`: +1 for the
/// thesis' literal cost, else the sign of `q_G,r · q_D,r` (the nearer of ±q_D; +1 on a tie). s is constant wherever
/// the dot product does not vanish, i.e. for orientation errors below 180°, so the residual's Jacobian is ∂q_G/∂δ.
pub fn reference_sign(g: &[f64; 8], reference: &[f64; 8], nearest: bool) -> f64 {
    let dot = g[0] * reference[0] + g[1] * reference[1] + g[2] * reference[2] + g[3] * reference[3];
    if nearest && dot < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Columns of `∂q_G/∂δ` (8 × nv) from the frame's local Jacobian (6 × nv): with a local twist (v, ω),
/// `q̇_r = ½ q_r (0, ω)` and `q̇_d = ½ (0, R v) q_r + ½ (0, p) q̇_r` (translation-first form, eq. (3.2)).
pub fn dual_quat_jacobian(g: &DualQuat, o_mf: &Se3, jlocal: &nalgebra::DMatrix<f64>, out: &mut nalgebra::DMatrix<f64>) {
    let qr = g.r;
    let p = Quat::pure(&o_mf.trans);
    for c in 0..jlocal.ncols() {
        let v = V3::new(jlocal[(0, c)], jlocal[(1, c)], jlocal[(2, c)]);
        let w = V3::new(jlocal[(3, c)], jlocal[(4, c)], jlocal[(5, c)]);
        let dr = qr.mul(&Quat::pure(&w)).scale(0.5);
        let dd = Quat::pure(&(o_mf.rot * v)).mul(&qr).scale(0.5) + p.mul(&dr).scale(0.5);
        let a = DualQuat::new(dr, dd).to_array();
        for r in 0..8 {
            out[(r, c)] = a[r];
        }
    }
}
