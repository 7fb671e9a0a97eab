//! The desired frame's motion for the pose tracker: its twist `ω^D_{D/I} = ω̄ + ε v̄` and the rate of its
//! components `ω̇^D_{D/I}` (both in D axes), as the relative dynamics (2.58) need them. The pose `q_{D/I}`
//! itself is never needed (Valverde 2018 §4.5 does not give it).
//!
//! Two forms: per-component harmonics `x_i(t) = o_i + a_i sin(w_i t + φ_i)` (constants and the thesis'
//! `[0, sin t, 0]` are special cases), with exact rates; and tables of samples, interpolated by cubic Hermite
//! pieces whose slopes are three-point finite differences, so the twist is C¹ and its rate is the exact
//! derivative of the interpolated twist (continuous, piecewise quadratic). Outside the table the end values are
//! held with zero rate.

use crate::dualquat::DualQuat;
use crate::error::{FfError, Result};
use crate::spatial::V3;

/// Harmonic components of one 3-vector (angular or linear).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Harmonic3 {
    /// o: constant part.
    pub offset: V3,
    /// a: amplitude.
    pub amplitude: V3,
    /// w: angular frequency (rad/s).
    pub frequency: V3,
    /// φ: phase (rad).
    pub phase: V3,
}

impl Harmonic3 {
    /// A constant vector.
    pub fn constant(x: V3) -> Harmonic3 {
        Harmonic3 { offset: x, ..Default::default() }
    }
    fn eval(&self, t: f64) -> (V3, V3) {
        let mut x = self.offset;
        let mut dx = V3::zeros();
        for i in 0..3 {
            let (s, c) = (self.frequency[i] * t + self.phase[i]).sin_cos();
            x[i] += self.amplitude[i] * s;
            dx[i] = self.amplitude[i] * self.frequency[i] * c;
        }
        (x, dx)
    }
    fn check(&self, name: &str) -> Result<()> {
        for (what, v) in [
            ("offset", self.offset),
            ("amplitude", self.amplitude),
            ("frequency", self.frequency),
            ("phase", self.phase),
        ] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(FfError::arg(&format!("{name}.{what}"), "has non-finite entries"));
            }
        }
        Ok(())
    }
}

/// Sampled twists: times (strictly increasing), angular rates ω̄ (rad/s) and linear velocities v̄ (m/s), in D.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    t: Vec<f64>,
    /// per sample `[ω̄, v̄]` (6 numbers)
    x: Vec<[f64; 6]>,
    /// Hermite slopes at the samples
    m: Vec<[f64; 6]>,
}

impl Table {
    /// From times and `[ω̄x, ω̄y, ω̄z, v̄x, v̄y, v̄z]` per sample (at least 2 samples).
    pub fn new(t: Vec<f64>, x: Vec<[f64; 6]>) -> Result<Table> {
        if t.len() < 2 || t.len() != x.len() {
            return Err(FfError::arg(
                "reference",
                format!(
                    "a table needs at least 2 samples and one twist per time ({} times, {} twists)",
                    t.len(),
                    x.len()
                ),
            ));
        }
        if let Some(k) = t.iter().position(|v| !v.is_finite()) {
            return Err(FfError::arg("reference.t", format!("entry {k} is not finite")));
        }
        if let Some(k) = t.windows(2).position(|w| !(w[1] > w[0])) {
            return Err(FfError::arg("reference.t", format!("times must increase strictly (entry {})", k + 1)));
        }
        if let Some(k) = x.iter().position(|r| r.iter().any(|v| !v.is_finite())) {
            return Err(FfError::arg("reference", format!("twist sample {k} has non-finite entries")));
        }
        let n = t.len();
        let mut m = vec![[0.0; 6]; n];
        for k in 0..n {
            for j in 0..6 {
                m[k][j] = if k == 0 {
                    (x[1][j] - x[0][j]) / (t[1] - t[0])
                } else if k == n - 1 {
                    (x[n - 1][j] - x[n - 2][j]) / (t[n - 1] - t[n - 2])
                } else {
                    // three-point derivative on a non-uniform grid (exact for quadratics)
                    let (h0, h1) = (t[k] - t[k - 1], t[k + 1] - t[k]);
                    let (d0, d1) = ((x[k][j] - x[k - 1][j]) / h0, (x[k + 1][j] - x[k][j]) / h1);
                    (h1 * d0 + h0 * d1) / (h0 + h1)
                };
            }
        }
        Ok(Table { t, x, m })
    }
    fn eval(&self, t: f64) -> ([f64; 6], [f64; 6]) {
        let n = self.t.len();
        if t <= self.t[0] {
            return (self.x[0], [0.0; 6]);
        }
        if t >= self.t[n - 1] {
            return (self.x[n - 1], [0.0; 6]);
        }
        let k = self.t.partition_point(|&s| s <= t) - 1;
        let h = self.t[k + 1] - self.t[k];
        let u = (t - self.t[k]) / h;
        let (u2, u3) = (u * u, u * u * u);
        // cubic Hermite basis and its derivative
        let (h00, h10, h01, h11) = (2.0 * u3 - 3.0 * u2 + 1.0, u3 - 2.0 * u2 + u, -2.0 * u3 + 3.0 * u2, u3 - u2);
        let (d00, d10, d01, d11) =
            (6.0 * u2 - 6.0 * u, 3.0 * u2 - 4.0 * u + 1.0, -6.0 * u2 + 6.0 * u, 3.0 * u2 - 2.0 * u);
        let (mut x, mut dx) = ([0.0; 6], [0.0; 6]);
        for j in 0..6 {
            let (p0, p1, m0, m1) = (self.x[k][j], self.x[k + 1][j], self.m[k][j] * h, self.m[k + 1][j] * h);
            x[j] = h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1;
            dx[j] = (d00 * p0 + d10 * m0 + d01 * p1 + d11 * m1) / h;
        }
        (x, dx)
    }
}

/// The desired frame's twist as a function of time.
#[derive(Clone, Debug, PartialEq)]
pub enum Reference {
    /// Harmonic angular and linear parts.
    Harmonic {
        /// ω̄^D_{D/I}(t).
        angular: Harmonic3,
        /// v̄^D_{D/I}(t).
        linear: Harmonic3,
    },
    /// Interpolated samples.
    Table(Table),
}

impl Reference {
    /// A constant twist `ω̄ + ε v̄` (Valverde 2018 §4.5 example B: ω̄ = v̄ = [1, 0, 0]).
    pub fn constant(w: V3, v: V3) -> Reference {
        Reference::Harmonic { angular: Harmonic3::constant(w), linear: Harmonic3::constant(v) }
    }
    /// Harmonic parts, checked for finite numbers.
    pub fn harmonic(angular: Harmonic3, linear: Harmonic3) -> Result<Reference> {
        angular.check("reference.angular")?;
        linear.check("reference.linear")?;
        Ok(Reference::Harmonic { angular, linear })
    }
    /// `(ω^D_{D/I}(t), ω̇^D_{D/I}(t))` as vector dual quaternions `ω̄ + ε v̄`.
    #[inline]
    pub fn eval(&self, t: f64) -> (DualQuat, DualQuat) {
        match self {
            Reference::Harmonic { angular, linear } => {
                let (w, dw) = angular.eval(t);
                let (v, dv) = linear.eval(t);
                (DualQuat::vector(&w, &v), DualQuat::vector(&dw, &dv))
            }
            Reference::Table(tb) => {
                let (x, dx) = tb.eval(t);
                (
                    DualQuat::vector(&V3::new(x[0], x[1], x[2]), &V3::new(x[3], x[4], x[5])),
                    DualQuat::vector(&V3::new(dx[0], dx[1], dx[2]), &V3::new(dx[3], dx[4], dx[5])),
                )
            }
        }
    }
}

/// Check a user-given reference twist (or its rate) is a finite vector dual quaternion (ℍ_d^v: both scalar parts 0).
pub fn check_vector(name: &str, x: &DualQuat) -> Result<()> {
    if !x.is_finite() {
        return Err(FfError::arg(name, "has non-finite entries"));
    }
    if !x.is_vector(1e-12 * x.norm().max(1.0)) {
        return Err(FfError::arg(
            name,
            format!(
                "must be a vector dual quaternion (entries 0 and 4, the scalar parts, zero), got scalars {} and {}",
                x.r.w, x.d.w
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_reproduces_a_quadratic_and_its_rate_is_the_derivative() {
        let t: Vec<f64> = (0..41).map(|k| 0.25 * k as f64).collect();
        let x: Vec<[f64; 6]> = t.iter().map(|&s| [s.sin(), 0.0, 1.0, 1.0, 0.0, 0.0]).collect();
        let r = Reference::Table(Table::new(t, x).unwrap());
        for &s in &[0.3, 1.7, 4.2, 7.9] {
            let (w, dw) = r.eval(s);
            assert!((w.r.v.x - f64::sin(s)).abs() < 2e-3, "{s}");
            assert!((dw.r.v.x - f64::cos(s)).abs() < 2e-2, "{s}");
            // the rate is the derivative of the interpolant
            let h = 1e-6;
            let fd = (r.eval(s + h).0.r.v.x - r.eval(s - h).0.r.v.x) / (2.0 * h);
            assert!((fd - dw.r.v.x).abs() < 1e-7);
            assert_eq!(w.d.v.x, 1.0);
        }
        assert!(Table::new(vec![0.0, 0.0], vec![[0.0; 6]; 2]).is_err());
    }

    #[test]
    fn harmonic_rate_is_exact() {
        let a =
            Harmonic3 { amplitude: V3::new(0.0, 1.0, 0.0), frequency: V3::new(0.0, 1.0, 0.0), ..Default::default() };
        let r = Reference::harmonic(a, Harmonic3::constant(V3::new(1.0, 0.0, 0.0))).unwrap();
        let (w, dw) = r.eval(0.7);
        assert!((w.r.v.y - 0.7f64.sin()).abs() < 1e-15 && (dw.r.v.y - 0.7f64.cos()).abs() < 1e-15);
        assert!(w.is_vector(0.0) && dw.d.v.norm() == 0.0);
        assert!(check_vector("reference", &DualQuat::ONE).is_err());
    }
}
