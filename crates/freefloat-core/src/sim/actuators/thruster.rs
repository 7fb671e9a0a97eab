//! Thrusters and the propellant tanks that feed them.
//!
//! A thruster is fixed on a body (the base or any other) at `position` and pushes the body along
//! `direction` (unit, body frame) with `max_thrust · φ(t)`: an external wrench on that body,
//! `[F d̂; r × F d̂]` about the body origin, so momentum changes by exactly the integrated thrust
//! wrench. Its command is a list of firings `(start, duration)` (Basilisk's on-time requests):
//! a firing shorter than `min_on_time` lasts `min_on_time` (the minimum impulse bit), the thrust
//! factor φ rises linearly from 0 to 1 over `ramp_on` seconds and, when the firing ends, falls
//! linearly from the level reached to 0 over `ramp_off` seconds (0: instant). φ depends on time only
//! and is read at every stage; place the firing edges on step boundaries (or use rk45, which lands
//! on them) to integrate them exactly.
//!
//! A tank is a propellant mass on a body at `position` (a point mass, or a solid sphere of `radius`).
//! The body's inertial parameters in the model are its wet (full-tank) values; the propellant left
//! `m_p` is integrated with the state, `ṁ_p = −Σ F_i / (Isp_i g₀)` over the thrusters it feeds
//! (g₀ = 9.80665 m/s²), and at every stage the body's inertia is the model's plus the tank's change
//! `I(m_p − m_p0)` (the inertia of a point or uniform sphere is linear in its mass). An empty tank
//! gives no thrust. Mass leaves the body with the body's velocity: the recorded momentum of what is
//! left therefore changes by the integrated thrust plus the momentum the propellant carried away.

use crate::error::{FfError, Result};
use crate::model::Model;
use crate::spatial::{Inertia, M3, V3};

/// Standard gravity for the specific impulse (m/s²).
pub const G0: f64 = 9.80665;

/// A thruster on body `body`.
#[derive(Clone, Debug, PartialEq)]
pub struct Thruster {
    /// Body it is fixed on (0: the base).
    pub body: usize,
    /// Position in the body frame (m).
    pub position: V3,
    /// Direction of the force on the body, body frame (normalised when checked).
    pub direction: V3,
    /// Thrust at full factor (N).
    pub max_thrust: f64,
    /// Shortest firing (s): shorter requests are lengthened to it.
    pub min_on_time: f64,
    /// Rise time from 0 to full thrust (s).
    pub ramp_on: f64,
    /// Fall time from full thrust to 0 (s).
    pub ramp_off: f64,
    /// Specific impulse (s); needed with a tank.
    pub isp: Option<f64>,
    /// Index of the tank that feeds it (in `Actuators::tanks`).
    pub tank: Option<usize>,
    /// Firings `(start, duration)` (s), in increasing start order, not overlapping.
    pub firings: Vec<(f64, f64)>,
}

/// A propellant tank on body `body`.
#[derive(Clone, Debug, PartialEq)]
pub struct Tank {
    /// Body that carries it.
    pub body: usize,
    /// Centre of the tank in the body frame (m).
    pub position: V3,
    /// Propellant at t = 0 (kg), included in the body's mass in the model.
    pub mass: f64,
    /// Radius of a uniform spherical propellant mass (m); 0 for a point mass.
    pub radius: f64,
}

impl Tank {
    /// The inertia of `mass` of propellant in this tank (about the body origin, body axes).
    pub(crate) fn tank_inertia(&self, mass: f64) -> Inertia {
        Inertia::from_com(mass, self.position, M3::identity() * (0.4 * mass * self.radius * self.radius))
    }

    pub(crate) fn check(&self, m: &Model, at: &str) -> Result<()> {
        if self.body >= m.nbodies() {
            return Err(FfError::arg(&format!("{at}.body"), format!("body index {} does not exist", self.body)));
        }
        if !(self.mass > 0.0) || !self.mass.is_finite() {
            return Err(FfError::arg(&format!("{at}.mass"), format!("must be positive, got {}", self.mass)));
        }
        if !(self.radius >= 0.0) || !self.radius.is_finite() || !self.position.iter().all(|x| x.is_finite()) {
            return Err(FfError::arg(&format!("{at}.radius"), "radius must be >= 0 and position finite"));
        }
        let mb = m.inertias[self.body].mass;
        if self.mass >= mb {
            return Err(FfError::arg(
                &format!("{at}.mass"),
                format!(
                    "the tank's propellant ({} kg) is not lighter than its body '{}' ({mb} kg, which includes it)",
                    self.mass, m.body_names[self.body]
                ),
            ));
        }
        Ok(())
    }
}

impl Thruster {
    pub(crate) fn check(&mut self, m: &Model, ntanks: usize, at: &str) -> Result<()> {
        if self.body >= m.nbodies() {
            return Err(FfError::arg(&format!("{at}.body"), format!("body index {} does not exist", self.body)));
        }
        let n = self.direction.norm();
        if !(n > 1e-12) || !n.is_finite() {
            return Err(FfError::arg(&format!("{at}.direction"), "has zero length (or is not finite)"));
        }
        self.direction /= n;
        if !self.position.iter().all(|x| x.is_finite()) {
            return Err(FfError::arg(&format!("{at}.position"), "must be finite"));
        }
        if !(self.max_thrust >= 0.0) || !self.max_thrust.is_finite() {
            return Err(FfError::arg(&format!("{at}.max_thrust"), format!("must be >= 0, got {}", self.max_thrust)));
        }
        for (key, x) in [("min_on_time", self.min_on_time), ("ramp_on", self.ramp_on), ("ramp_off", self.ramp_off)] {
            if !(x >= 0.0) || !x.is_finite() {
                return Err(FfError::arg(&format!("{at}.{key}"), format!("must be >= 0, got {x}")));
            }
        }
        if let Some(isp) = self.isp {
            if !(isp > 0.0) || !isp.is_finite() {
                return Err(FfError::arg(&format!("{at}.isp"), format!("must be positive (seconds), got {isp}")));
            }
        }
        if let Some(k) = self.tank {
            if k >= ntanks {
                return Err(FfError::arg(&format!("{at}.tank"), format!("tank {k} does not exist ({ntanks} tanks)")));
            }
            if self.isp.is_none() {
                return Err(FfError::arg(&format!("{at}.isp"), "a thruster fed by a tank needs its Isp"));
            }
        }
        let mut last_end = f64::NEG_INFINITY;
        for (j, f) in self.firings.iter_mut().enumerate() {
            if !(f.0.is_finite() && f.1 >= 0.0 && f.1.is_finite()) {
                return Err(FfError::arg(&format!("{at}.firings[{j}]"), "start must be finite and duration >= 0"));
            }
            f.1 = f.1.max(self.min_on_time);
            if f.0 < last_end {
                return Err(FfError::arg(
                    &format!("{at}.firings[{j}]"),
                    format!("starts at {} before the previous firing ends at {last_end}", f.0),
                ));
            }
            last_end = f.0 + f.1;
        }
        Ok(())
    }

    /// Thrust factor φ(t) in [0, 1]. `left`: the limit from the left at a firing edge (a stage at the
    /// end of a step belongs to that step, so a firing that starts at the step's end must not act in it,
    /// and one that ends there must: piecewise-smooth φ is then integrated exactly when its edges fall on
    /// step boundaries).
    #[inline]
    pub(crate) fn factor(&self, t: f64, left: bool) -> f64 {
        // Firings are few: a linear scan over those that may still act at t.
        let mut phi: f64 = 0.0;
        // Stage times t0 + c h carry round-off: an edge within eps of t counts as at t.
        let eps = 1e-12 * t.abs().max(1.0);
        for &(s, d) in &self.firings {
            let started = if left { t > s + eps } else { t >= s - eps };
            if !started {
                break;
            }
            let e = s + d;
            let rise = |x: f64| if self.ramp_on > 0.0 { (x / self.ramp_on).clamp(0.0, 1.0) } else { 1.0 };
            let on = if left { t <= e + eps } else { t < e - eps };
            let p = if on {
                rise(t - s)
            } else {
                let top = rise(d);
                if self.ramp_off > 0.0 {
                    top * (1.0 - (t - e) / self.ramp_off).max(0.0)
                } else {
                    0.0
                }
            };
            phi = phi.max(p);
        }
        phi
    }

    /// Add this thruster's wrench at thrust `f` (N) on its body into `fext` (nbodies × 6).
    #[inline]
    pub(crate) fn wrench(&self, f: f64, fext: &mut [f64]) {
        let force: V3 = self.direction * f;
        let tq = self.position.cross(&force);
        let o = 6 * self.body;
        for j in 0..3 {
            fext[o + j] += force[j];
            fext[o + 3 + j] += tq[j];
        }
    }
}
