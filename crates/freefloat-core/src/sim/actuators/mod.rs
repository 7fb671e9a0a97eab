//! Actuator models evaluated inside the simulator's stepper (no allocation per step): joint effort
//! and rate limits of every joint (`limits`), reaction wheels (`wheel`), thrusters and propellant
//! tanks (`thruster`). Internal actuators (joint limits, wheel motors and friction) keep the
//! momentum at round-off; thrusters and wheel imbalance jitter are external wrenches on their body,
//! accumulated into the stepper's per-body `fext` buffer (body frame, about the body origin).

pub(crate) mod limits;
mod thruster;
mod wheel;

pub use limits::JointLimit;
pub use thruster::{Tank, Thruster, G0};
pub use wheel::Wheel;

use crate::error::{FfError, Result};
use crate::model::Model;
use crate::spatial::Inertia;
use wheel::WheelRt;

/// The actuators of a simulation (besides the joint limits, which every model carries, and which
/// `limits` may override joint by joint).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Actuators {
    /// Joint limits replacing the model's for some joints (each quantity given replaces the model's).
    pub limits: Vec<JointLimit>,
    /// Reaction wheels (each one a revolute joint of the model).
    pub wheels: Vec<Wheel>,
    /// Thrusters.
    pub thrusters: Vec<Thruster>,
    /// Propellant tanks feeding the thrusters.
    pub tanks: Vec<Tank>,
}

impl Actuators {
    /// Whether there is nothing to model.
    pub fn is_empty(&self) -> bool {
        self.limits.is_empty() && self.wheels.is_empty() && self.thrusters.is_empty() && self.tanks.is_empty()
    }
}

/// The actuators resolved against a model, with their state.
#[derive(Debug, Default)]
pub(crate) struct ActuatorRt {
    pub limits: Vec<limits::Limit>,
    wheels: Vec<WheelRt>,
    thrusters: Vec<Thruster>,
    tanks: Vec<Tank>,
    /// Wet inertia of each tank's body in the model.
    wet: Vec<Inertia>,
    /// Whether anything writes external wrenches.
    pub uses_fext: bool,
}

impl ActuatorRt {
    /// Check `a` against `m` and resolve it. `prescribed` flags the bodies whose joints follow a
    /// prescribed motion (no limit or wheel model applies to those).
    pub fn new(m: &Model, a: Option<Actuators>, prescribed: &[bool]) -> Result<Self> {
        let a = a.unwrap_or_default();
        limits::check(m, &a.limits, prescribed)?;
        let mut seen = vec![false; m.nbodies()];
        let mut wheels = Vec::with_capacity(a.wheels.len());
        for (j, w) in a.wheels.iter().enumerate() {
            let at = format!("actuators.wheels[{j}]");
            w.check(m, &at)?;
            if seen[w.joint] {
                return Err(FfError::arg(
                    &format!("{at}.joint"),
                    format!("joint '{}' has two wheel models", m.joint_names[w.joint]),
                ));
            }
            if prescribed[w.joint] {
                return Err(FfError::arg(
                    &format!("{at}.joint"),
                    format!("joint '{}' is prescribed", m.joint_names[w.joint]),
                ));
            }
            seen[w.joint] = true;
            wheels.push(WheelRt::new(m, w));
        }
        for (j, t) in a.tanks.iter().enumerate() {
            t.check(m, &format!("actuators.tanks[{j}]"))?;
        }
        // Tanks on one body together must leave it some dry mass.
        for b in 0..m.nbodies() {
            let total: f64 = a.tanks.iter().filter(|t| t.body == b).map(|t| t.mass).sum();
            if total > 0.0 && total >= m.inertias[b].mass {
                return Err(FfError::arg(
                    "actuators.tanks",
                    format!(
                        "the tanks on body '{}' hold {total} kg, not less than the body's {} kg",
                        m.body_names[b], m.inertias[b].mass
                    ),
                ));
            }
        }
        let mut thrusters = a.thrusters.clone();
        for (j, t) in thrusters.iter_mut().enumerate() {
            t.check(m, a.tanks.len(), &format!("actuators.thrusters[{j}]"))?;
        }
        let uses_fext = !thrusters.is_empty() || wheels.iter().any(|w| w.jitters());
        let wet = a.tanks.iter().map(|t| m.inertias[t.body]).collect();
        Ok(ActuatorRt {
            limits: limits::collect(m, &a.limits, prescribed),
            wheels,
            thrusters,
            tanks: a.tanks,
            wet,
            uses_fext,
        })
    }

    /// Number of tanks (extra integrated states: the propellant left in each).
    pub fn ntanks(&self) -> usize {
        self.tanks.len()
    }

    /// Initial propellant of each tank into `mp`.
    pub fn initial_propellant(&self, mp: &mut [f64]) {
        for (x, t) in mp.iter_mut().zip(&self.tanks) {
            *x = t.mass;
        }
    }

    /// Whether the model's inertias change along the run.
    pub fn depletes(&self) -> bool {
        !self.tanks.is_empty()
    }

    /// Shape the command (once per step, or every stage with the stage timing): joint limits, then
    /// the wheels' torque, power and speed saturation, at the rates `v`.
    pub fn command(&mut self, v: &[f64], cmd: &mut [f64]) {
        limits::apply(&self.limits, v, cmd);
        for w in &mut self.wheels {
            cmd[w.kv] = w.command(cmd[w.kv], v[w.kv]);
        }
    }

    /// The forces at a stage: wheel friction subtracted from `tau`, external wrenches into `fext`,
    /// and the propellant flow of each tank into `mdot` (kg/s, negative), with the propellant
    /// left `mp` at this stage. `left`: the stage is not a step's first (see `Thruster::factor`).
    #[allow(clippy::too_many_arguments)]
    pub fn forces(
        &self,
        t: f64,
        left: bool,
        q: &[f64],
        v: &[f64],
        mp: &[f64],
        tau: &mut [f64],
        fext: &mut [f64],
        mdot: &mut [f64],
    ) {
        for w in &self.wheels {
            tau[w.kv] -= w.friction(v[w.kv]);
        }
        if !self.uses_fext {
            return;
        }
        fext.fill(0.0);
        mdot.fill(0.0);
        for w in self.wheels.iter().filter(|w| w.jitters()) {
            w.jitter(q, v, fext);
        }
        for th in &self.thrusters {
            let phi = th.factor(t, left);
            if phi <= 0.0 {
                continue;
            }
            if let Some(k) = th.tank {
                if mp[k] <= 0.0 {
                    continue; // empty tank: no thrust
                }
            }
            let f = th.max_thrust * phi;
            th.wrench(f, fext);
            if let (Some(k), Some(isp)) = (th.tank, th.isp) {
                mdot[k] -= f / (isp * G0);
            }
        }
    }

    /// Write the inertias of the tanks' bodies with `mp` propellant left into `model`.
    pub fn deplete(&self, model: &mut Model, mp: &[f64]) {
        for (k, t) in self.tanks.iter().enumerate() {
            model.inertias[t.body] = self.wet[k];
        }
        for (k, t) in self.tanks.iter().enumerate() {
            let dm = mp[k].max(0.0) - t.mass;
            model.inertias[t.body] = model.inertias[t.body].add(&t.tank_inertia(dm));
        }
    }

    /// Next firing edge or ramp corner strictly after t (for the adaptive stepper to land on).
    pub fn next_event(&self, t: f64) -> f64 {
        let mut next = f64::INFINITY;
        for th in &self.thrusters {
            for &(s, d) in &th.firings {
                for e in [s, s + th.ramp_on.min(d), s + d, s + d + th.ramp_off] {
                    if e > t * (1.0 + 1e-12) + 1e-15 && e < next {
                        next = e;
                    }
                }
            }
        }
        next
    }
}
