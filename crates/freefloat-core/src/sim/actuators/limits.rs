//! Joint effort and rate limits of every joint (URDF `<limit effort velocity>`, YAML `limits:`).
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

use crate::model::Model;

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

/// Limits of the joints that have one and are not prescribed.
pub(crate) fn collect(m: &Model, prescribed: &[bool]) -> Vec<Limit> {
    let mut out = Vec::new();
    for i in 0..m.nbodies() {
        let l = &m.limits[i];
        if prescribed[i] || (l.effort.is_none() && l.velocity.is_none()) {
            continue;
        }
        for c in 0..m.nvs[i] {
            out.push(Limit {
                k: m.idx_v[i] + c,
                effort: l.effort.unwrap_or(f64::INFINITY),
                velocity: l.velocity.unwrap_or(f64::INFINITY),
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
