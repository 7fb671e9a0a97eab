//! The orbital environment of a simulation: point-mass gravity of a central body with the orbit of the
//! system, the gravity gradient on every body, J2, and a constant disturbance wrench (Valverde 2018, §2.3.3,
//! (2.61)–(2.68)). Everything is off by default, and an `Environment` that is all off changes nothing: the
//! simulator then passes no external forces at all, as before.
//!
//! **Frame.** The simulator's world frame keeps inertial axes but its origin translates with a free-falling
//! reference point: the reference point P moves on the given orbit of the system's centre of mass
//! (`orbit::Propagator`) and the frame origin is `O = P − c0 − ċ0 t`, c0 and ċ0 the CoM's local position and
//! velocity at t = 0 (O is P when the CoM starts at rest at the local origin). Positions in `q` stay metres, not
//! 7e6 m, so millimetre arm motion keeps its digits. O accelerates with `g(R)`, R = P, so every body in this
//! frame feels its gravity minus `m g(R)`: the differential (tidal) gravity `m [g(R + r) − g(R)]` (r: the
//! body's CoM relative to P) on its centre of mass (`gravity_gradient`, with J2's differential part in `j2`), and
//! the gravity-gradient torque about it. This is exact (no linearisation: O's acceleration is exactly g(P)), so the system
//! CoM leaves c0 + ċ0 t only by the tiny net tidal force (second order in size/radius). A local point x is inertially
//! at `O(t) + x`. Inertial rather than LVLH axes: no fictitious Coriolis or centrifugal forces on
//! every body, the momentum the simulator records keeps its meaning, and the free-flyer `q` stays Pinocchio's.

pub mod disturbance;
pub mod gravity_gradient;
pub mod j2;
pub mod orbit;

pub use disturbance::{Axes, Disturbance};
pub use orbit::{CentralBody, Elements, Orbit, Propagator, ReferenceState};

use crate::check::check_vec;
use crate::data::Data;
use crate::dualquat::orbital::{tidal_roots, tidal_x};
use crate::error::{FfError, Result};
use crate::kinematics::forward_kinematics_unchecked;
use crate::model::Model;
use crate::spatial::{Force, M3, V3};

/// What acts on the system from outside. `Default` is all off.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Environment {
    /// The central body and the orbit of the system's centre of mass at t = 0. Without it there is no gravity
    /// field (and neither gravity gradient nor J2).
    pub orbit: Option<Orbit>,
    /// Apply the tidal force and the gravity-gradient torque to every body.
    pub gravity_gradient: bool,
    /// Add J2 to the orbit of the frame origin and its differential part to every body.
    pub j2: bool,
    /// A constant wrench on one body.
    pub disturbance: Option<Disturbance>,
}

impl Environment {
    /// Nothing acts: the simulator skips the environment entirely.
    pub fn is_off(&self) -> bool {
        self.orbit.is_none() && self.disturbance.is_none()
    }

    /// Checks the environment against the model it will act on.
    pub fn check(&self, m: &Model) -> Result<()> {
        if let Some(o) = &self.orbit {
            o.central.check()?;
            // `Orbit::new` checked the orbit when it was made; its fields are public, so check it again.
            Orbit::new(o.central, o.position, o.velocity)?;
            if m.gravity.norm() != 0.0 {
                return Err(FfError::arg(
                    "environment.orbit",
                    format!(
                        "the model has a uniform gravity {:?} m/s²; an orbit gives its own gravity field, so set the \
                         model's gravity to zero",
                        m.gravity.as_slice()
                    ),
                ));
            }
        } else if self.gravity_gradient || self.j2 {
            let what = if self.j2 { "j2" } else { "gravity_gradient" };
            return Err(FfError::arg(
                &format!("environment.{what}"),
                "needs an orbit (the central body and the system's orbit)",
            ));
        }
        if let Some(dist) = &self.disturbance {
            dist.check(m.nbodies())?;
        }
        Ok(())
    }

    /// The workspace of one simulation from (q0, v0): the reference point starts on the given orbit of the
    /// system's centre of mass, the frame origin at `P − c0` (checked).
    pub fn workspace(&self, m: &Model, d: &mut Data, q0: &[f64], v0: &[f64]) -> Result<EnvWorkspace> {
        self.check(m)?;
        check_vec("q0", q0, m.nq)?;
        check_vec("v0", v0, m.nv)?;
        let prop = match &self.orbit {
            None => None,
            Some(o) => {
                let h = crate::kinematics::momentum(m, d, q0, v0)?;
                let c = crate::kinematics::center_of_mass(m, d, q0)?;
                // The reference point P follows the given orbit of the system's CoM; the frame origin O is
                // P − c0 − ċ0 t (c0, ċ0: the CoM's local position and velocity at t = 0), which accelerates with
                // P, g(P): a body at local r is at P + (r − c0 − ċ0 t) and feels the tidal gravity of that
                // offset. The CoM then stays at c0 + ċ0 t locally, to second order in size/radius.
                Some((Propagator::new(o.central, o.position, o.velocity, self.j2), c, h.lin / m.total_mass()))
            }
        };
        let n = m.nbodies();
        let (prop, c0, cdot0) = match prop {
            Some((p, c, cd)) => (Some(p), c, cd),
            None => (None, V3::zeros(), V3::zeros()),
        };
        Ok(EnvWorkspace {
            prop,
            c0,
            cdot0,
            fext: vec![0.0; 6 * n],
            com: m.inertias.iter().map(|i| i.com()).collect(),
            i_com: m.inertias.iter().map(|i| i.i_com()).collect(),
            mass: m.inertias.iter().map(|i| i.mass).collect(),
            rel: vec![V3::zeros(); n],
            xs: vec![0.0; n],
            roots: vec![(0.0, 0.0); n],
            inv_dist: vec![0.0; n],
        })
    }
}

/// Per-simulation buffers of the environment: the orbit propagator, the per-body external wrenches handed to
/// the dynamics (`fext`: body frame, about the body origin, `[force; torque]` per body), and each body's CoM and
/// inertia about it.
#[derive(Clone, Debug)]
pub struct EnvWorkspace {
    prop: Option<Propagator>,
    c0: V3,
    cdot0: V3,
    /// Per-body external wrenches of the last `eval` (6 per body).
    pub fext: Vec<f64>,
    com: Vec<V3>,
    i_com: Vec<M3>,
    /// The mass each body's `com` / `i_com` were computed for: a body whose tank drains (variable-mass model
    /// handed to `eval`) gets them recomputed, so its CoM and inertia follow the propellant.
    mass: Vec<f64>,
    /// Per body, during `eval`: its CoM from the reference point, its tidal series variable and that variable's
    /// roots (`dualquat::orbital::tidal_x`, `tidal_roots`), and (with J2) 1/‖R + r‖ computed directly.
    rel: Vec<V3>,
    xs: Vec<f64>,
    roots: Vec<(f64, f64)>,
    inv_dist: Vec<f64>,
}

impl EnvWorkspace {
    /// The reference point's inertial state at time t: the orbit of the system's CoM (None without an orbit).
    pub fn reference(&mut self, t: f64) -> Option<ReferenceState> {
        self.prop.as_mut().map(|p| p.state(t))
    }

    /// The frame origin's inertial state at time t, `P − c0 − ċ0 t` (None without an orbit).
    pub fn origin(&mut self, t: f64) -> Option<ReferenceState> {
        let (c0, cd) = (self.c0, self.cdot0);
        self.reference(t).map(|s| ReferenceState { position: s.position - c0 - cd * t, velocity: s.velocity - cd })
    }

    /// Fills `self.fext` for time t from the placements in `d` (forward kinematics done). Each body's dual
    /// force about its CoM in body axes, `f + ετ` (2.39), is the sum of the effects, then moves to the body
    /// origin by (2.40), `f + ε(τ + c × f)` with `c` the CoM in body axes.
    pub fn eval(&mut self, env: &Environment, m: &Model, d: &Data, t: f64) {
        let refst = self.reference(t);
        // what every body shares: the origin's distance powers and, with J2, its J2 acceleration
        let shared = match (&env.orbit, &refst) {
            (Some(o), Some(rs)) => {
                let a_j2 = if env.j2 { j2::at_origin(&rs.position, &o.central) } else { V3::zeros() };
                Some((gravity_gradient::Origin::new(rs.position, o.central.mu), a_j2, o.central))
            }
            _ => None,
        };
        // the reference point P in the frame: c0 + ċ0 t
        let p_ref = self.c0 + self.cdot0 * t;
        let n = m.nbodies();
        let (rel, xs, roots) = (&mut self.rel[..n], &mut self.xs[..n], &mut self.roots[..n]);
        let inv_dist = &mut self.inv_dist[..n];
        for i in 0..n {
            let mass = m.inertias[i].mass;
            if mass != self.mass[i] {
                self.com[i] = m.inertias[i].com();
                self.i_com[i] = m.inertias[i].i_com();
                self.mass[i] = mass;
            }
        }
        if let Some((origin, ..)) = &shared {
            // Loops of their own (see `tidal_acceleration_inv`): each body's CoM from the reference point P; its
            // series variable, then every body's square root and division, independent of one another (for the
            // gravity gradient only: J2 alone needs neither); then, below, the wrenches.
            for i in 0..n {
                rel[i] = d.o_mi[i].act_point(&self.com[i]) - p_ref;
            }
            if env.gravity_gradient {
                for (x, r) in xs.iter_mut().zip(rel.iter()) {
                    *x = tidal_x(&origin.big_r, r, origin.inv_r2);
                }
                for (x, root) in xs.iter().zip(roots.iter_mut()) {
                    *root = tidal_roots(*x);
                }
            }
            if env.j2 {
                // J2's differential is a plain difference that magnifies an error in 1/‖R + r‖ by about ‖R‖/‖r‖:
                // the distance computed directly, not from the tidal series' root (a few ulps off, which moved the
                // J2 force by ~1e-8 of itself); here with the other roots, off the per-body chain
                for (id, r) in inv_dist.iter_mut().zip(rel.iter()) {
                    *id = 1.0 / (origin.big_r + r).norm();
                }
            }
        }
        self.fext.fill(0.0);
        for i in 0..n {
            let mass = self.mass[i];
            let x = &d.o_mi[i];
            // the dual force f + ετ about the CoM in body axes, summed over the effects as its two vectors
            let (mut f, mut tau) = (V3::zeros(), V3::zeros());
            let add = |f: &mut V3, tau: &mut V3, w: crate::dualquat::DualQuat| {
                *f += w.r.v;
                *tau += w.d.v;
            };
            let mut any = false;
            if let Some((origin, a_j2, central)) = &shared {
                if mass > 0.0 {
                    let r = &rel[i];
                    if env.gravity_gradient {
                        let (fg, tg) =
                            gravity_gradient::wrench(&x.rot, origin, r, xs[i], roots[i], mass, &self.i_com[i]);
                        f += fg;
                        tau += tg;
                        any = true;
                    }
                    if env.j2 {
                        let inv_d = inv_dist[i];
                        add(&mut f, &mut tau, j2::wrench(&x.rot, &origin.big_r, r, inv_d, a_j2, mass, central));
                        any = true;
                    }
                }
            }
            if let Some(dist) = env.disturbance.as_ref().filter(|dd| dd.body == i) {
                add(&mut f, &mut tau, dist.wrench(&x.rot));
                any = true;
            }
            if any {
                let tau = tau + self.com[i].cross(&f);
                self.fext[6 * i..6 * i + 3].copy_from_slice(f.as_slice());
                self.fext[6 * i + 3..6 * i + 6].copy_from_slice(tau.as_slice());
            }
        }
    }

    /// Total external wrench of the last `eval` about the frame origin, inertial axes (`d` as in `eval`).
    pub fn total_wrench(&self, m: &Model, d: &Data) -> Force {
        let mut tot = Force::ZERO;
        for i in 0..m.nbodies() {
            tot += d.o_mi[i].act_force(&Force::from_slice(&self.fext[6 * i..6 * i + 6]));
        }
        tot
    }
}

/// The frame origin O's inertial state `[position (3), velocity (3)]` at each of `times` for a simulation that
/// starts at (q0, v0): the same propagation the simulator uses, so the system's inertial position at a recorded
/// sample is this position plus the local one.
pub fn reference_orbit(env: &Environment, m: &Model, q0: &[f64], v0: &[f64], times: &[f64]) -> Result<Vec<f64>> {
    let mut d = Data::new(m);
    let mut ws = env.workspace(m, &mut d, q0, v0)?;
    if ws.prop.is_none() {
        return Err(FfError::arg("environment.orbit", "the environment has no orbit"));
    }
    check_times(times)?;
    let mut out = Vec::with_capacity(6 * times.len());
    for &t in times {
        let s = ws.origin(t).expect("checked above");
        out.extend_from_slice(s.position.as_slice());
        out.extend_from_slice(s.velocity.as_slice());
    }
    Ok(out)
}

/// The environment's total external wrench `[force (3), moment about the frame origin (3)]`, inertial axes,
/// at each sample `(times[k], qs[k])` of a simulation that started at (q0, v0): what the simulator applied there.
pub fn external_wrenches(
    env: &Environment,
    m: &Model,
    q0: &[f64],
    v0: &[f64],
    times: &[f64],
    qs: &[f64],
) -> Result<Vec<f64>> {
    let mut d = Data::new(m);
    let mut ws = env.workspace(m, &mut d, q0, v0)?;
    check_times(times)?;
    if qs.len() != times.len() * m.nq {
        return Err(FfError::arg(
            "q",
            format!("expected {} × {} configurations, got {} values", times.len(), m.nq, qs.len()),
        ));
    }
    let mut out = Vec::with_capacity(6 * times.len());
    let mut qbuf = Vec::new();
    for (k, &t) in times.iter().enumerate() {
        let q = m.checked_q(&qs[k * m.nq..(k + 1) * m.nq], &mut qbuf)?;
        forward_kinematics_unchecked(m, &mut d, q);
        ws.eval(env, m, &d, t);
        let w = ws.total_wrench(m, &d);
        out.extend_from_slice(w.lin.as_slice());
        out.extend_from_slice(w.ang.as_slice());
    }
    Ok(out)
}

fn check_times(times: &[f64]) -> Result<()> {
    if let Some(k) = times.iter().position(|t| !(t.is_finite() && *t >= 0.0)) {
        return Err(FfError::arg("times", format!("entry {k} is not a finite time ≥ 0")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dualquat::orbital::tidal_acceleration;

    #[test]
    fn tidal_acceleration_is_the_difference_of_gravities_without_its_cancellation() {
        let mu = CentralBody::EARTH.mu;
        // near the centre the plain difference keeps its digits: both agree to round-off
        let (big_r, r) = (V3::new(3.0, -4.0, 12.0), V3::new(0.3, 0.2, -0.1));
        let g = |x: &V3| -x * (mu / x.norm().powi(3));
        let plain = g(&(big_r + r)) - g(&big_r);
        assert!((tidal_acceleration(&big_r, &r, mu) - plain).norm() < 1e-13 * plain.norm());
        // at 7000 km: the first-order tidal tensor (μ/R³)(3 R̂R̂ᵀ − I) r, to O(‖r‖/‖R‖)
        let (big_r, r) = (V3::new(4.0e6, -3.0e6, 5.0e6), V3::new(0.5, -1.0, 2.0));
        let rh = big_r.normalize();
        let lin = (rh * (3.0 * rh.dot(&r)) - r) * (mu / big_r.norm().powi(3));
        let t = tidal_acceleration(&big_r, &r, mu);
        assert!((t - lin).norm() < 1e-5 * lin.norm(), "{t} vs {lin}");
    }

    /// The per-body shortcuts of the simulator's environment: the distance `1/‖R + r‖` from the tidal series' root,
    /// and the J2 acceleration from a given `1/‖r‖`, against the direct forms.
    #[test]
    fn shared_roots_give_the_distance_and_the_j2_acceleration() {
        use crate::dualquat::orbital::{j2_acceleration, j2_acceleration_inv, tidal_acceleration_inv};
        let c = CentralBody::EARTH;
        for (big_r, r) in [
            (V3::new(4.0e6, -3.0e6, 5.0e6), V3::new(0.5, -1.0, 2.0)),
            (V3::new(-6.9e6, 1.0e5, 2.0e3), V3::new(-30.0, 12.0, 4.0)),
            (V3::new(3.0, -4.0, 12.0), V3::new(0.3, 0.2, -0.1)),
        ] {
            let inv_r2 = 1.0 / big_r.norm_squared();
            let (a, inv_d) = tidal_acceleration_inv(&big_r, &r, inv_r2, inv_r2.sqrt(), c.mu);
            let d = big_r + r;
            assert!((inv_d * d.norm() - 1.0).abs() < 4.0 * f64::EPSILON, "{inv_d} vs 1/{}", d.norm());
            assert_eq!(a, tidal_acceleration(&big_r, &r, c.mu));
            let (j, k) =
                (j2_acceleration(&d, c.mu, c.j2, c.radius), j2_acceleration_inv(&d, inv_d, c.mu, c.j2, c.radius));
            // inv_d to a few ulps, raised to the fifth power
            assert!((j - k).norm() < 32.0 * f64::EPSILON * j.norm(), "{j} vs {k}");
            // against the textbook form (2.64), with divisions
            let rn = d.norm();
            let z2 = (d.z / rn).powi(2);
            let kk = -1.5 * c.mu * c.j2 * c.radius * c.radius / rn.powi(4);
            let book = V3::new(
                kk * (1.0 - 5.0 * z2) * d.x / rn,
                kk * (1.0 - 5.0 * z2) * d.y / rn,
                kk * (3.0 - 5.0 * z2) * d.z / rn,
            );
            assert!((j - book).norm() < 8.0 * f64::EPSILON * book.norm(), "{j} vs {book}");
        }
    }

    #[test]
    fn kepler_closed_form_matches_the_rk4_grid_without_j2() {
        let c = CentralBody { j2: 0.0, ..CentralBody::EARTH };
        let el = Elements { a: 7.2e6, e: 0.05, i: 0.5, raan: 0.2, argp: 0.7, nu: 1.0 };
        let o = Orbit::from_elements(c, &el).unwrap();
        let mut grid = Propagator::new(c, o.position, o.velocity, true);
        let mut closed = Propagator::new(c, o.position, o.velocity, false);
        for k in 0..=10 {
            let t = o.period() * k as f64 / 10.0 + 0.37;
            let (a, b) = (grid.state(t), closed.state(t));
            assert!((a.position - b.position).norm() < 1e-4, "t = {t}: {}", (a.position - b.position).norm());
            assert!((a.velocity - b.velocity).norm() < 1e-7);
        }
        // an earlier time after a later one (an RK45 rejection) gives the same answer as in order
        let later = grid.state(3000.5);
        let earlier = grid.state(1000.25);
        let mut fresh = Propagator::new(c, o.position, o.velocity, true);
        assert_eq!(fresh.state(1000.25), earlier);
        assert_eq!(fresh.state(3000.5), later);
        // a whole period later the closed form is back where it started
        let p = closed.state(o.period());
        assert!((p.position - o.position).norm() < 1e-7, "{}", (p.position - o.position).norm());
    }

    #[test]
    fn orbits_below_the_surface_and_bad_constants_are_refused() {
        let c = CentralBody::EARTH;
        let low = Elements { a: 6.5e6, e: 0.1, i: 0.0, raan: 0.0, argp: 0.0, nu: 0.0 };
        assert!(Orbit::from_elements(c, &low).unwrap_err().to_string().contains("semi_major_axis"));
        let bad = CentralBody { mu: -1.0, ..c };
        assert!(bad.check().unwrap_err().to_string().contains("mu"));
        let esc = Orbit::new(c, V3::new(7e6, 0.0, 0.0), V3::new(0.0, 2e4, 0.0));
        assert!(esc.unwrap_err().to_string().contains("bound"));
    }

    /// `eval`'s per-body wrenches (shared roots, three loops, J2 at the origin once) against each body's direct
    /// forms: `m Cᵀ[g(R + r) − g(R)]` by `tidal_acceleration`, `3μ d × (Ī d)/‖d‖⁵` by `gravity_gradient_of`, and
    /// `m Cᵀ[a_J2(R + r) − a_J2(R)]` with `j2_acceleration` at both points; for each effect alone and both.
    #[test]
    fn eval_matches_the_direct_per_body_forms() {
        use crate::dualquat::orbital::{gravity_gradient_of, j2_acceleration};
        let m = crate::model::builtin::load("naveen_dual_arm").unwrap();
        let el = Elements { a: 6.9e6, e: 0.01, i: 0.9, raan: 0.4, argp: 0.2, nu: 1.1 };
        let orbit = Some(Orbit::from_elements(CentralBody::EARTH, &el).unwrap());
        let c = CentralBody::EARTH;
        let mut d = Data::new(&m);
        let mut q = m.neutral();
        q[0..3].copy_from_slice(&[0.4, -1.3, 2.0]);
        q[3..7].copy_from_slice(&[0.1, -0.2, 0.3, 0.927_361_849_549_570_3]);
        for (k, x) in q[7..].iter_mut().enumerate() {
            *x = 0.3 + 0.4 * k as f64;
        }
        let mut v0 = vec![0.0; m.nv];
        v0[6..].iter_mut().enumerate().for_each(|(k, x)| *x = 0.05 * k as f64);
        for (gg, j2) in [(true, false), (false, true), (true, true)] {
            let env = Environment { orbit, gravity_gradient: gg, j2, disturbance: None };
            let mut ws = env.workspace(&m, &mut d, &q, &v0).unwrap();
            let t = 12.5;
            forward_kinematics_unchecked(&m, &mut d, &q);
            ws.eval(&env, &m, &d, t);
            let big_r = ws.reference(t).unwrap().position;
            let p_ref = ws.c0 + ws.cdot0 * t;
            for i in 0..m.nbodies() {
                let (mass, com, i_com) = (m.inertias[i].mass, m.inertias[i].com(), m.inertias[i].i_com());
                let x = &d.o_mi[i];
                let r = x.act_point(&com) - p_ref;
                let (mut f, mut tau) = (V3::zeros(), V3::zeros());
                if mass > 0.0 && gg {
                    f += x.rot.tr_mul(&(tidal_acceleration(&big_r, &r, c.mu) * mass));
                    tau += gravity_gradient_of(&i_com, &x.rot.tr_mul(&(big_r + r)), c.mu).d.v;
                }
                if mass > 0.0 && j2 {
                    let da = j2_acceleration(&(big_r + r), c.mu, c.j2, c.radius)
                        - j2_acceleration(&big_r, c.mu, c.j2, c.radius);
                    f += x.rot.tr_mul(&(da * mass));
                }
                let tau = tau + com.cross(&f);
                let (fe, te) = (
                    V3::from_column_slice(&ws.fext[6 * i..6 * i + 3]),
                    V3::from_column_slice(&ws.fext[6 * i + 3..6 * i + 6]),
                );
                assert!((fe - f).norm() <= 1e-12 * f.norm().max(1e-300), "body {i} ({gg}, {j2}): force {fe} vs {f}");
                assert!(
                    (te - tau).norm() <= 1e-12 * tau.norm().max(1e-300),
                    "body {i} ({gg}, {j2}): torque {te} vs {tau}"
                );
                assert!(mass == 0.0 || f.norm() > 0.0);
            }
        }
    }

    #[test]
    fn a_draining_body_gets_its_com_and_inertia_recomputed() {
        // a tank draining off the base origin moves the base's CoM: the gravity gradient must follow it
        // (the workspace was built from the full-tank model, the stepper hands it the drained one)
        let full = crate::model::builtin::load("naveen_dual_arm").unwrap();
        let mut drained = full.clone();
        let b = &full.inertias[0];
        let (m, c) = (b.mass * 0.9, b.com() + V3::new(0.05, -0.02, 0.03));
        drained.inertias[0] = crate::spatial::Inertia::from_com(m, c, b.i_com() * 0.9);
        let el = Elements { a: 7.0e6, e: 0.0, i: 0.3, raan: 0.0, argp: 0.0, nu: 0.0 };
        let env = Environment {
            orbit: Some(Orbit::from_elements(CentralBody::EARTH, &el).unwrap()),
            gravity_gradient: true,
            j2: true,
            disturbance: None,
        };
        let mut d = Data::new(&full);
        let mut q0 = vec![0.0; full.nq];
        q0[3..7].copy_from_slice(&[0.1, -0.2, 0.3, 0.927_361_849_549_570_3]);
        let v0 = vec![0.0; full.nv];
        let mut ws = env.workspace(&full, &mut d, &q0, &v0).unwrap();
        // the reference: the same workspace with body 0's CoM and inertia set to the drained values by hand
        let mut reference = ws.clone();
        reference.com[0] = drained.inertias[0].com();
        reference.i_com[0] = drained.inertias[0].i_com();
        reference.mass[0] = m;
        let mut stale = ws.clone();
        forward_kinematics_unchecked(&drained, &mut d, &q0);
        ws.eval(&env, &drained, &d, 1.0);
        reference.eval(&env, &drained, &d, 1.0);
        stale.mass[0] = m; // pretend it was already refreshed: the old, full-tank CoM stays
        stale.eval(&env, &drained, &d, 1.0);
        assert_eq!(ws.fext, reference.fext);
        let gap = (0..6).map(|k| (stale.fext[k] - reference.fext[k]).abs()).fold(0.0, f64::max);
        assert!(gap > 1e-9 * reference.fext[..6].iter().map(|x| x.abs()).fold(0.0, f64::max), "{gap}");
    }
}
