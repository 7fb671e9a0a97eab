//! The central body and the orbit of the simulation frame's origin (a free-falling reference point that starts
//! at the system's centre of mass). With point-mass gravity only the reference state at any time is the closed
//! two-body (Kepler) solution; with J2 it is integrated by fixed-step RK4 on a grid of its own (see
//! `Propagator`), so its value at a time does not depend on the order in which times are asked for.

use crate::dualquat::orbital::j2_acceleration;
use crate::error::{FfError, Result};
use crate::spatial::V3;
use std::f64::consts::TAU;

/// A central body: gravitational parameter, equatorial radius and J2 coefficient (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CentralBody {
    /// Gravitational parameter μ (m³/s²).
    pub mu: f64,
    /// Equatorial radius (m): no orbit may come closer to the centre than this.
    pub radius: f64,
    /// Second zonal harmonic J2 (dimensionless); used only when the environment's `j2` is on.
    pub j2: f64,
}

impl CentralBody {
    /// The Earth: μ = 398600.4418 km³/s², Re = 6378.137 km, J2 = 0.0010826267 (the constants of Valverde 2018,
    /// after (2.62) and (2.64)), in SI units.
    pub const EARTH: CentralBody = CentralBody { mu: 3.986004418e14, radius: 6_378_137.0, j2: 1.0826267e-3 };

    /// Checks μ > 0, radius > 0 and a finite J2.
    pub fn check(&self) -> Result<()> {
        if !(self.mu > 0.0) || !self.mu.is_finite() {
            return Err(FfError::arg("mu", format!("the gravitational parameter must be positive, got {}", self.mu)));
        }
        if !(self.radius > 0.0) || !self.radius.is_finite() {
            return Err(FfError::arg(
                "radius",
                format!("the central body's radius must be positive, got {}", self.radius),
            ));
        }
        if !self.j2.is_finite() {
            return Err(FfError::arg("j2", format!("must be finite, got {}", self.j2)));
        }
        Ok(())
    }

    /// Point-mass gravity acceleration at `r` (inertial, from the centre): `−μ r/‖r‖³` (Valverde 2018, (2.62)).
    pub fn point_mass_acceleration(&self, r: &V3) -> V3 {
        -r * (self.mu / r.norm().powi(3))
    }

    /// Gravity at `r` with or without the J2 term (2.62) + (2.64).
    pub fn acceleration(&self, r: &V3, with_j2: bool) -> V3 {
        let a = self.point_mass_acceleration(r);
        if with_j2 {
            a + j2_acceleration(r, self.mu, self.j2, self.radius)
        } else {
            a
        }
    }
}

/// The orbit of the system's centre of mass at t = 0: inertial position from the centre of the central body
/// and inertial velocity. The simulator's own positions are relative to a point on this orbit (see `Environment`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// The body the system orbits.
    pub central: CentralBody,
    /// Position of the system's centre of mass at t = 0 (m, inertial, from the central body's centre).
    pub position: V3,
    /// Velocity of the system's centre of mass at t = 0 (m/s, inertial).
    pub velocity: V3,
}

/// Classical orbital elements of a bound orbit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elements {
    /// Semi-major axis (m).
    pub a: f64,
    /// Eccentricity, 0 ≤ e < 1.
    pub e: f64,
    /// Inclination (rad).
    pub i: f64,
    /// Right ascension of the ascending node (rad).
    pub raan: f64,
    /// Argument of periapsis (rad).
    pub argp: f64,
    /// True anomaly at t = 0 (rad).
    pub nu: f64,
}

impl Orbit {
    /// From classical elements (checked: a bound orbit whose periapsis is above the central body's radius).
    pub fn from_elements(central: CentralBody, el: &Elements) -> Result<Orbit> {
        central.check()?;
        for (name, x) in [("inclination", el.i), ("raan", el.raan), ("arg_periapsis", el.argp), ("true_anomaly", el.nu)]
        {
            if !x.is_finite() {
                return Err(FfError::arg(name, format!("must be finite, got {x}")));
            }
        }
        if !(el.e >= 0.0 && el.e < 1.0) {
            return Err(FfError::arg("eccentricity", format!("must be in [0, 1) (a bound orbit), got {}", el.e)));
        }
        if !(el.a > 0.0) || !el.a.is_finite() {
            return Err(FfError::arg("semi_major_axis", format!("must be positive and finite, got {}", el.a)));
        }
        let rp = el.a * (1.0 - el.e);
        if rp <= central.radius {
            return Err(FfError::arg(
                "semi_major_axis",
                format!(
                    "the orbit's periapsis radius {rp:.1} m is not above the central body's radius {:.1} m",
                    central.radius
                ),
            ));
        }
        // Perifocal position and velocity, rotated by R3(−Ω) R1(−i) R3(−ω) (Vallado, "COE2RV").
        let p = el.a * (1.0 - el.e * el.e);
        let (sn, cn) = el.nu.sin_cos();
        let r = p / (1.0 + el.e * cn);
        let rpf = V3::new(r * cn, r * sn, 0.0);
        let k = (central.mu / p).sqrt();
        let vpf = V3::new(-k * sn, k * (el.e + cn), 0.0);
        let rot = rz(el.raan) * rx(el.i) * rz(el.argp);
        Orbit::new(central, rot * rpf, rot * vpf)
    }

    /// From a state (checked: finite, bound, periapsis above the central body's radius).
    pub fn new(central: CentralBody, position: V3, velocity: V3) -> Result<Orbit> {
        central.check()?;
        if position.iter().chain(velocity.iter()).any(|x| !x.is_finite()) {
            return Err(FfError::arg("orbit", "position and velocity must be finite"));
        }
        let o = Orbit { central, position, velocity };
        let (a, e) = o.size_shape();
        if !(a > 0.0) {
            return Err(FfError::arg("orbit", "the orbit is not bound (energy ≥ 0): the system would escape"));
        }
        if a * (1.0 - e) <= central.radius {
            return Err(FfError::arg(
                "orbit",
                format!(
                    "the orbit's periapsis radius {:.1} m is not above the central body's radius {:.1} m",
                    a * (1.0 - e),
                    central.radius
                ),
            ));
        }
        Ok(o)
    }

    /// Semi-major axis (negative if unbound) and eccentricity of the t = 0 state.
    pub fn size_shape(&self) -> (f64, f64) {
        let mu = self.central.mu;
        let (r, v) = (self.position, self.velocity);
        let a = 1.0 / (2.0 / r.norm() - v.norm_squared() / mu);
        let e = ((v.norm_squared() - mu / r.norm()) * r - r.dot(&v) * v) / mu;
        (a, e.norm())
    }

    /// Orbital period 2π√(a³/μ) (s).
    pub fn period(&self) -> f64 {
        let (a, _) = self.size_shape();
        TAU * (a.powi(3) / self.central.mu).sqrt()
    }

    /// Two-body state at time t from the t = 0 state `(r0, v0)`: Kepler's equation in the change of eccentric
    /// anomaly ΔE, `n Δt = ΔE + σ₀/√a (1 − cos ΔE) − (1 − r₀/a) sin ΔE` with `σ₀ = r₀·v₀/√μ`, solved by
    /// Newton's method, then the Lagrange coefficients f, g, ḟ, ġ (Battin 1999, §4.3; Vallado 2013, alg. 8).
    /// Whole revolutions are taken out of Δt first, so g keeps its digits over many orbits.
    pub fn kepler(mu: f64, r0: &V3, v0: &V3, t: f64) -> (V3, V3) {
        let rn = r0.norm();
        let a = 1.0 / (2.0 / rn - v0.norm_squared() / mu);
        let n = (mu / a.powi(3)).sqrt();
        let period = TAU / n;
        let dt = t - (t / period).floor() * period;
        let sa = a.sqrt();
        let sigma = r0.dot(v0) / mu.sqrt();
        let (c1, c2) = (sigma / sa, 1.0 - rn / a);
        let m = n * dt;
        let mut de = m;
        for _ in 0..50 {
            let (s, c) = de.sin_cos();
            let f = de + c1 * (1.0 - c) - c2 * s - m;
            let fp = 1.0 + c1 * s - c2 * c;
            let step = f / fp;
            de -= step;
            // ΔE is in [0, 2π + …]: an absolute bound; Newton converges quadratically, so the step after one
            // of 1e-9 is already at round-off
            if step.abs() <= 1e-9 {
                if step.abs() > 1e-16 {
                    let (s, c) = de.sin_cos();
                    de -= (de + c1 * (1.0 - c) - c2 * s - m) / (1.0 + c1 * s - c2 * c);
                }
                break;
            }
        }
        let (s, c) = de.sin_cos();
        let r = a + (rn - a) * c + sigma * sa * s;
        let f = 1.0 - a / rn * (1.0 - c);
        let g = dt - (de - s) / n;
        let fd = -(mu * a).sqrt() / (r * rn) * s;
        let gd = 1.0 - a / r * (1.0 - c);
        (f * r0 + g * v0, fd * r0 + gd * v0)
    }
}

fn rz(a: f64) -> crate::spatial::M3 {
    let (s, c) = a.sin_cos();
    crate::spatial::M3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

fn rx(a: f64) -> crate::spatial::M3 {
    let (s, c) = a.sin_cos();
    crate::spatial::M3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// State of the reference point: inertial position, velocity and gravitational acceleration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceState {
    /// Position from the central body's centre (m, inertial).
    pub position: V3,
    /// Velocity (m/s, inertial).
    pub velocity: V3,
}

/// Nodes per orbit of the J2 propagator's RK4 grid: the global error of RK4 over one orbit scales as
/// (2π/N)⁴; with N = 20 000 it is ~1e-14 of the radius for a low Earth orbit, far below what the tidal forces
/// (which depend on the radius to first order only) can see.
const NODES_PER_ORBIT: f64 = 20_000.0;
/// A checkpoint every this many nodes: a query before the current node (an RK45 step that was rejected)
/// re-advances from the last checkpoint at or before it instead of from t = 0.
const CHECKPOINT_EVERY: usize = 256;

/// Propagates the reference point. Closed form for point-mass gravity; RK4 on a fixed grid with J2. Holds the
/// grid's current node and checkpoints, so it is a per-simulation workspace.
#[derive(Clone, Debug)]
pub struct Propagator {
    central: CentralBody,
    j2: bool,
    r0: V3,
    v0: V3,
    h: f64,
    node: usize,
    state: [V3; 2],
    checkpoints: Vec<[V3; 2]>,
    cache: [(f64, ReferenceState); 2],
}

impl Propagator {
    /// From the reference point's state at t = 0 (`j2` off: the closed-form two-body solution).
    pub fn new(central: CentralBody, r0: V3, v0: V3, j2: bool) -> Propagator {
        let a = 1.0 / (2.0 / r0.norm() - v0.norm_squared() / central.mu);
        let period = TAU * (a.abs().powi(3) / central.mu).sqrt();
        Propagator {
            central,
            j2,
            r0,
            v0,
            h: period / NODES_PER_ORBIT,
            node: 0,
            state: [r0, v0],
            checkpoints: vec![[r0, v0]],
            cache: [(f64::NAN, ReferenceState { position: r0, velocity: v0 }); 2],
        }
    }

    /// The grid step of the J2 propagator (s).
    pub fn grid_step(&self) -> f64 {
        self.h
    }

    fn deriv(&self, x: &[V3; 2]) -> [V3; 2] {
        [x[1], self.central.acceleration(&x[0], true)]
    }

    fn rk4(&self, x: &[V3; 2], h: f64) -> [V3; 2] {
        let add = |x: &[V3; 2], k: &[V3; 2], s: f64| [x[0] + k[0] * s, x[1] + k[1] * s];
        let k1 = self.deriv(x);
        let k2 = self.deriv(&add(x, &k1, 0.5 * h));
        let k3 = self.deriv(&add(x, &k2, 0.5 * h));
        let k4 = self.deriv(&add(x, &k3, h));
        let s = h / 6.0;
        [x[0] + (k1[0] + (k2[0] + k3[0]) * 2.0 + k4[0]) * s, x[1] + (k1[1] + (k2[1] + k3[1]) * 2.0 + k4[1]) * s]
    }

    /// Reference state at time t ≥ 0.
    pub fn state(&mut self, t: f64) -> ReferenceState {
        // RK4 asks for t + h/2 twice and a step's end again as the next step's start: keep the last two answers
        for (tc, sc) in &self.cache {
            if *tc == t {
                return *sc;
            }
        }
        let s = self.compute(t);
        self.cache[1] = self.cache[0];
        self.cache[0] = (t, s);
        s
    }

    fn compute(&mut self, t: f64) -> ReferenceState {
        if !self.j2 {
            let (position, velocity) = Orbit::kepler(self.central.mu, &self.r0, &self.v0, t);
            return ReferenceState { position, velocity };
        }
        let k = (t / self.h).floor().max(0.0) as usize;
        if k < self.node {
            let c = k / CHECKPOINT_EVERY;
            self.node = c * CHECKPOINT_EVERY;
            self.state = self.checkpoints[c];
        }
        while self.node < k {
            self.state = self.rk4(&self.state, self.h);
            self.node += 1;
            if self.node.is_multiple_of(CHECKPOINT_EVERY) && self.node / CHECKPOINT_EVERY == self.checkpoints.len() {
                self.checkpoints.push(self.state);
            }
        }
        let x = self.rk4(&self.state, t - self.node as f64 * self.h);
        ReferenceState { position: x[0], velocity: x[1] }
    }
}
