//! Joint effort and rate limits of every joint (URDF `<limit effort velocity>`, YAML `limits:`), and
//! the overrides a simulation may give for some joints (`Actuators::limits`, a scenario's
//! `actuators.limits: [{joint, effort, velocity}]`): a value given there replaces the model's value of
//! that quantity for that joint; a quantity it leaves out keeps the model's value.
//!
//! What the simulator does with them, the way a motor drive does it:
//! - **effort**: the drive cannot give more, so the commanded generalized force of each coordinate of
//!   the joint is clipped to `[-effort, effort]`;
//! - **velocity**: the drive stops pushing when the joint is at or past its rate limit: a command
//!   that would drive `|v|` further past `velocity` (same sign as `v`) becomes zero, a command that
//!   slows the joint passes. This is Basilisk's wheel speed saturation
//!   (`ReactionWheelStateEffector::ConfigureRWRequests`). The joint is not stopped by force: passive
//!   motion (the base turning, friction, a neighbour's reaction) can still carry it past the limit.
//!
//! Both act on the command, inside the robot (a joint force acts equally on the two bodies it joins),
//! so momentum stays at round-off. With the per-step input timing they are applied once per step, to
//! the command held through it, with the joint rate at the step's start.

use crate::error::{FfError, Result};
use crate::model::Model;

/// A simulation's own limits for one joint, replacing the model's (symmetric magnitudes; `None`:
/// keep the model's value of that quantity).
#[derive(Clone, Debug, PartialEq)]
pub struct JointLimit {
    /// Body index of the joint's child (the joint), as in `Wheel::joint`.
    pub joint: usize,
    /// Largest |generalized force| (N m or N).
    pub effort: Option<f64>,
    /// Rate beyond which the drive stops pushing (rad/s or m/s).
    pub velocity: Option<f64>,
}

/// Check the overrides against the model; errors name the entry (`actuators.limits[1].effort`).
pub(crate) fn check(m: &Model, overrides: &[JointLimit], prescribed: &[bool]) -> Result<()> {
    let mut seen = vec![None; m.nbodies()];
    for (j, l) in overrides.iter().enumerate() {
        let at = format!("actuators.limits[{j}]");
        let i = l.joint;
        if i == 0 || i >= m.nbodies() {
            return Err(FfError::arg(
                &format!("{at}.joint"),
                format!("must be a joint of the model other than the base's (body index {i} is not)"),
            ));
        }
        let name = &m.joint_names[i];
        if m.nvs[i] == 0 {
            return Err(FfError::arg(
                &format!("{at}.joint"),
                format!("joint '{name}' is fixed (it has no rate to limit)"),
            ));
        }
        if prescribed[i] {
            return Err(FfError::arg(&format!("{at}.joint"), format!("joint '{name}' is prescribed")));
        }
        if let Some(k) = seen[i] {
            return Err(FfError::arg(
                &format!("{at}.joint"),
                format!("joint '{name}' is limited twice (actuators.limits[{k}] limits it too)"),
            ));
        }
        seen[i] = Some(j);
        if l.effort.is_none() && l.velocity.is_none() {
            return Err(FfError::arg(&at, format!("joint '{name}': give an effort, a velocity limit or both")));
        }
        for (key, x) in [("effort", l.effort), ("velocity", l.velocity)] {
            if let Some(x) = x {
                if !(x > 0.0) || !x.is_finite() {
                    return Err(FfError::arg(
                        &format!("{at}.{key}"),
                        format!("must be positive and finite (a symmetric magnitude), got {x}"),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// One limited velocity coordinate.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Limit {
    /// Index in v.
    pub k: usize,
    /// Largest |force| (infinite if none).
    pub effort: f64,
    /// Rate beyond which no force drives further (infinite if none).
    pub velocity: f64,
}

/// Limits of the joints that have one and are not prescribed: the model's, with each quantity that
/// `overrides` (checked by `check`) gives for a joint replacing the model's.
pub(crate) fn collect(m: &Model, overrides: &[JointLimit], prescribed: &[bool]) -> Vec<Limit> {
    let mut out = Vec::new();
    for i in 0..m.nbodies() {
        let over = overrides.iter().find(|o| o.joint == i);
        let effort = over.and_then(|o| o.effort).or(m.limits[i].effort);
        let velocity = over.and_then(|o| o.velocity).or(m.limits[i].velocity);
        if prescribed[i] || (effort.is_none() && velocity.is_none()) {
            continue;
        }
        for c in 0..m.nvs[i] {
            out.push(Limit {
                k: m.idx_v[i] + c,
                effort: effort.unwrap_or(f64::INFINITY),
                velocity: velocity.unwrap_or(f64::INFINITY),
            });
        }
    }
    out
}

/// Apply the limits to the command `cmd` (nv) at joint rates `v`.
#[inline]
pub(crate) fn apply(limits: &[Limit], v: &[f64], cmd: &mut [f64]) {
    for l in limits {
        let u = cmd[l.k].clamp(-l.effort, l.effort);
        let w = v[l.k];
        // Rate saturation: no force that drives the joint further past its limit.
        cmd[l.k] = if w.abs() >= l.velocity && u * w > 0.0 { 0.0 } else { u };
    }
}
