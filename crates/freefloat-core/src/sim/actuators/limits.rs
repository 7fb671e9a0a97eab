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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::yaml::from_yaml_str;

    fn hub_wheel(limits: &str) -> Model {
        let text = format!(
            "name: hw\nbase: free\ngravity: [0, 0, 0]\nbodies:\n  - name: hub\n    inertial: {{mass: 10.0, com: [0, 0, \
             0], inertia: [2.0, 2.0, 2.0]}}\n  - name: rotor\n    parent: hub\n    joint: {{name: rw, type: revolute, \
             axis: [0, 0, 1]{limits}}}\n    origin: {{xyz: [0, 0, 0], rpy: [0, 0, 0]}}\n    inertial: {{mass: 1.0, com: \
             [0, 0, 0], inertia: [0.06, 0.06, 0.1]}}\n"
        );
        from_yaml_str(&text, "test").unwrap()
    }

    #[test]
    fn override_replaces_each_quantity_given_and_keeps_the_others() {
        let m = hub_wheel(", limits: {effort: 0.05, velocity: 1.0}");
        let free = vec![false; m.nbodies()];
        let o = [JointLimit { joint: 1, effort: Some(0.08), velocity: None }];
        check(&m, &o, &free).unwrap();
        let l = collect(&m, &o, &free);
        assert_eq!(l.len(), 1);
        assert_eq!((l[0].k, l[0].effort, l[0].velocity), (6, 0.08, 1.0));
        // a model without limits gets the override alone
        let m = hub_wheel("");
        assert!(collect(&m, &[], &free).is_empty());
        let l = collect(&m, &[JointLimit { joint: 1, effort: None, velocity: Some(0.5) }], &free);
        assert_eq!((l[0].effort, l[0].velocity), (f64::INFINITY, 0.5));
    }

    #[test]
    fn bad_overrides_name_the_entry() {
        let m = hub_wheel("");
        let free = vec![false; m.nbodies()];
        let msg = |o: &[JointLimit]| format!("{}", check(&m, o, &free).unwrap_err());
        let l = |joint, effort, velocity| JointLimit { joint, effort, velocity };
        assert!(msg(&[l(0, Some(1.0), None)]).contains("actuators.limits[0].joint"));
        assert!(msg(&[l(7, Some(1.0), None)]).contains("actuators.limits[0].joint"));
        assert!(msg(&[l(1, Some(-1.0), None)]).contains("actuators.limits[0].effort"));
        assert!(msg(&[l(1, None, Some(f64::NAN))]).contains("actuators.limits[0].velocity"));
        assert!(msg(&[l(1, Some(0.0), None)]).contains("positive"));
        assert!(msg(&[l(1, None, None)]).contains("both"));
        let two = msg(&[l(1, Some(1.0), None), l(1, None, Some(1.0))]);
        assert!(two.contains("actuators.limits[1].joint") && two.contains("twice"), "{two}");
        let presc = vec![false, true];
        assert!(format!("{}", check(&m, &[l(1, Some(1.0), None)], &presc).unwrap_err()).contains("prescribed"));
    }
}
