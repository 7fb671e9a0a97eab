//! Reaction wheels: a wheel is a revolute joint of the model (its rotor is the joint's child body);
//! this module turns the commanded wheel torque into the torque the motor applies and adds friction
//! and, optionally, the imbalance jitter on the hub.
//!
//! The command (from the torque source and the controller, the wheel joint's entry of the
//! generalized force) is shaped once per step, as Basilisk's `ReactionWheelStateEffector::
//! ConfigureRWRequests` does, in its order: torque saturation `|u| <= max_torque`, power saturation
//! `|u Ω| <= max_power` (u becomes `±max_power/|Ω|`), speed saturation (no torque that drives `|Ω|`
//! further past `max_speed`). Friction is evaluated at every stage with the stage's wheel rate and
//! subtracted from the motor torque (Basilisk `updateContributions`):
//! - Coulomb and viscous: `f = f_c sign(Ω) + c_v Ω`;
//! - with a Stribeck speed β (static friction `f_s`, used while the wheel starts from near rest and
//!   keeps accelerating in the same sense, as Basilisk latches it):
//!   `f = sqrt(2e) (f_s − f_c) exp(−(Ω/β)²/2) Ω/(β sqrt 2) + f_c tanh(10 Ω/β) + c_v Ω`;
//! - below `limit_cycle_speed` the friction is the straight line through zero and its value there, so
//!   that a resting wheel does not chatter.
//!
//! Motor torque and friction act between hub and rotor: momentum stays at round-off. The imbalance
//! jitter ("simple jitter" of Basilisk) is an external wrench on the hub, so it does change the
//! momentum, as in Basilisk: static imbalance `U_s` (kg m) gives `F = U_s Ω² ŵ₂` at the wheel's
//! position `r` and the torque `r × F`; dynamic imbalance `U_d` (kg m²) the torque `U_d Ω² ŵ₂`; `ŵ₂`
//! turns with the wheel angle θ about the spin axis `ĝ`: `ŵ₂ = cos θ ŵ₂₀ + sin θ (ĝ × ŵ₂₀)`,
//! `ŵ₂₀ = ĝ × x̂` normalised (`ĝ × ŷ` when ĝ is nearly along x̂), Basilisk's wheel frame.

use crate::error::{FfError, Result};
use crate::model::{JointType, Model};
use crate::spatial::V3;

/// A reaction wheel: the model's revolute joint `joint` (body index of the rotor) with its drive.
/// Every limit is optional (`None`: none); friction coefficients default to zero.
#[derive(Clone, Debug, PartialEq)]
pub struct Wheel {
    /// Body index of the rotor (the child of the wheel's revolute joint).
    pub joint: usize,
    /// Largest motor torque |u| (N m).
    pub max_torque: Option<f64>,
    /// Wheel rate beyond which the motor stops driving (rad/s).
    pub max_speed: Option<f64>,
    /// Largest motor power |u Ω| (W).
    pub max_power: Option<f64>,
    /// Coulomb friction torque f_c (N m).
    pub coulomb: f64,
    /// Static (break-away) friction torque f_s (N m), used with `stribeck_speed`.
    pub static_friction: f64,
    /// Stribeck speed β (rad/s); `None`: no Stribeck term.
    pub stribeck_speed: Option<f64>,
    /// Viscous friction coefficient c_v (N m s/rad).
    pub viscous: f64,
    /// Below this rate the friction is linear in Ω (rad/s; Basilisk's default 1e-4).
    pub limit_cycle_speed: f64,
    /// Static imbalance U_s (kg m).
    pub static_imbalance: f64,
    /// Dynamic imbalance U_d (kg m²).
    pub dynamic_imbalance: f64,
}

impl Wheel {
    /// A frictionless, unlimited wheel on the rotor body `joint`.
    pub fn new(joint: usize) -> Self {
        Wheel {
            joint,
            max_torque: None,
            max_speed: None,
            max_power: None,
            coulomb: 0.0,
            static_friction: 0.0,
            stribeck_speed: None,
            viscous: 0.0,
            limit_cycle_speed: 1e-4,
            static_imbalance: 0.0,
            dynamic_imbalance: 0.0,
        }
    }

    /// Check the wheel against the model; `at` names it in errors (e.g. `actuators.wheels[0]`).
    pub(crate) fn check(&self, m: &Model, at: &str) -> Result<()> {
        let i = self.joint;
        if i == 0 || i >= m.nbodies() || m.joint_types[i] != JointType::Revolute {
            return Err(FfError::arg(
                &format!("{at}.joint"),
                format!("must be a revolute joint of the model (body index {i} is not)"),
            ));
        }
        let pos = |key: &str, x: Option<f64>| -> Result<()> {
            match x {
                Some(x) if !(x > 0.0) || !x.is_finite() => {
                    Err(FfError::arg(&format!("{at}.{key}"), format!("must be positive and finite, got {x}")))
                }
                _ => Ok(()),
            }
        };
        pos("max_torque", self.max_torque)?;
        pos("max_speed", self.max_speed)?;
        pos("max_power", self.max_power)?;
        pos("stribeck_speed", self.stribeck_speed)?;
        pos("limit_cycle_speed", Some(self.limit_cycle_speed))?;
        for (key, x) in [
            ("coulomb", self.coulomb),
            ("static_friction", self.static_friction),
            ("viscous", self.viscous),
            ("static_imbalance", self.static_imbalance),
            ("dynamic_imbalance", self.dynamic_imbalance),
        ] {
            if !(x >= 0.0) || !x.is_finite() {
                return Err(FfError::arg(&format!("{at}.{key}"), format!("must be >= 0 and finite, got {x}")));
            }
        }
        if self.stribeck_speed.is_some() && self.static_friction < self.coulomb {
            return Err(FfError::arg(
                &format!("{at}.static_friction"),
                format!(
                    "the static (break-away) friction {} must be at least the Coulomb friction {}",
                    self.static_friction, self.coulomb
                ),
            ));
        }
        Ok(())
    }
}

/// A wheel resolved against the model, with the state its drive keeps between steps.
#[derive(Clone, Debug)]
pub(crate) struct WheelRt {
    pub w: Wheel,
    /// Index of the wheel rate in v and of the angle in q.
    pub kv: usize,
    pub kq: usize,
    /// Hub body (where the jitter acts), wheel position and ŵ₂₀, ŵ₃₀ in the hub frame.
    pub hub: usize,
    pub r: V3,
    pub w20: V3,
    pub w30: V3,
    /// Motor torque held through the step.
    pub u: f64,
    /// Basilisk's Stribeck latch and the rate at the previous step.
    pub stribeck_on: bool,
    pub omega_before: f64,
}

impl WheelRt {
    pub(crate) fn new(m: &Model, w: &Wheel) -> Self {
        let i = w.joint;
        let pl = &m.placements[i];
        let g = pl.rot * m.axes[i];
        let mut w20 = g.cross(&V3::x());
        if w20.norm() < 0.01 {
            w20 = g.cross(&V3::y());
        }
        let w20 = w20.normalize();
        let w30 = g.cross(&w20);
        WheelRt {
            w: w.clone(),
            kv: m.idx_v[i],
            kq: m.idx_q[i],
            hub: m.parents[i].unwrap_or(0),
            r: pl.trans,
            w20,
            w30,
            u: 0.0,
            stribeck_on: false,
            omega_before: 0.0,
        }
    }

    /// Shape the command `u` at wheel rate `omega` (once per step): torque, power, speed saturation.
    #[inline]
    pub(crate) fn command(&mut self, mut u: f64, omega: f64) -> f64 {
        let w = &self.w;
        if let Some(umax) = w.max_torque {
            u = u.clamp(-umax, umax);
        }
        if let Some(pmax) = w.max_power {
            if (u * omega).abs() >= pmax {
                u = (pmax / omega.abs()).copysign(u);
            }
        }
        if let Some(om) = w.max_speed {
            if omega.abs() >= om && omega * u >= 0.0 {
                u = 0.0;
            }
        }
        // Basilisk's Stribeck latch: on when starting near rest, kept while Ω and Ω̇ share a sign.
        if let Some(_beta) = w.stribeck_speed {
            if omega.abs() < 0.1 * w.limit_cycle_speed {
                self.stribeck_on = true;
            }
            let s_om = sign(omega);
            let s_dom = sign(omega - self.omega_before);
            self.stribeck_on = self.stribeck_on && (s_om - s_dom).abs() < 2.0;
        }
        self.omega_before = omega;
        self.u = u;
        u
    }

    /// Friction torque opposing the rotor at rate `omega` (N m, same sign as omega).
    #[inline]
    pub(crate) fn friction(&self, omega: f64) -> f64 {
        let w = &self.w;
        let curve = |om: f64, mag: bool| -> f64 {
            match (w.stribeck_speed, self.stribeck_on) {
                (Some(beta), true) => {
                    let x = om / beta;
                    (2.0 * std::f64::consts::E).sqrt() * (w.static_friction - w.coulomb) * (-x * x / 2.0).exp() * x
                        / std::f64::consts::SQRT_2
                        + w.coulomb * (10.0 * x).tanh()
                        + w.viscous * om
                }
                _ => (if mag { 1.0 } else { sign(om) }) * w.coulomb + w.viscous * om,
            }
        };
        let lc = w.limit_cycle_speed;
        if omega.abs() < lc {
            curve(lc, true) / lc * omega
        } else {
            curve(omega, false)
        }
    }

    /// Whether this wheel puts a wrench on its hub.
    pub(crate) fn jitters(&self) -> bool {
        self.w.static_imbalance > 0.0 || self.w.dynamic_imbalance > 0.0
    }

    /// Add the imbalance wrench on the hub (body frame, about its origin) into `fext` (nbodies × 6).
    #[inline]
    pub(crate) fn jitter(&self, q: &[f64], v: &[f64], fext: &mut [f64]) {
        let (th, om) = (q[self.kq], v[self.kv]);
        let w2 = self.w20 * th.cos() + self.w30 * th.sin();
        let om2 = om * om;
        let f = w2 * (self.w.static_imbalance * om2);
        let tq = self.r.cross(&f) + w2 * (self.w.dynamic_imbalance * om2);
        let o = 6 * self.hub;
        for j in 0..3 {
            fext[o + j] += f[j];
            fext[o + 3 + j] += tq[j];
        }
    }
}

/// −1, 0 or 1 (Basilisk's `(x > 0) - (x < 0)`).
#[inline]
fn sign(x: f64) -> f64 {
    ((x > 0.0) as i32 - (x < 0.0) as i32) as f64
}
