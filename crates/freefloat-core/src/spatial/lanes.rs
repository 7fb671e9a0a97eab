//! Four samples side by side: [`F4`] holds one `f64` per sample, and every operation acts lane by lane (each is a
//! loop over the four lanes, which compiles to one AVX2 instruction). [`Real`] is what a formula written once needs
//! from its numbers, so the same source serves one sample (`f64`) and four (`F4`) with the same operations in the
//! same order: lane l of a four-sample result equals, bit for bit, the one-sample result for sample l.
//!
//! Used where a pass over many independent samples would otherwise run the same small formulas once per sample
//! (the identification's regressor stream: kinematics and the momentum regressor, four samples per step).

use std::ops::{Add, Mul, Neg, Sub};

/// Samples per [`F4`]: the lane count of `trig::sin_cos4` (the four-sample kinematics feeds one to the other).
pub use super::trig::LANES;

/// Four `f64`, one per sample.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct F4(pub [f64; LANES]);

/// The arithmetic a formula shared by `f64` and [`F4`] uses.
pub trait Real: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self> {
    /// `self · a + b` with one rounding (a fused multiply-add in every lane).
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// The number `x` (in every lane).
    fn splat(x: f64) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn mul_add(self, a: f64, b: f64) -> f64 {
        f64::mul_add(self, a, b)
    }
    #[inline(always)]
    fn splat(x: f64) -> f64 {
        x
    }
}

impl F4 {
    /// Lane l from `f(l)`.
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f64) -> F4 {
        F4(std::array::from_fn(f))
    }
}

impl Real for F4 {
    #[inline(always)]
    fn mul_add(self, a: F4, b: F4) -> F4 {
        F4::from_fn(|l| self.0[l].mul_add(a.0[l], b.0[l]))
    }
    #[inline(always)]
    fn splat(x: f64) -> F4 {
        F4([x; LANES])
    }
}

macro_rules! lane_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: F4) -> F4 {
                F4::from_fn(|l| self.0[l] $op o.0[l])
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);

impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        F4::from_fn(|l| -self.0[l])
    }
}

/// A 3-vector of numbers `T`.
pub type Vec3<T> = [T; 3];

/// `a × b`, in the order of operations of nalgebra's `Vector3::cross` (so `f64` results match it bit for bit).
#[inline(always)]
pub fn cross<T: Real>(a: &Vec3<T>, b: &Vec3<T>) -> Vec3<T> {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `a + b`.
#[inline(always)]
pub fn add<T: Real>(a: &Vec3<T>, b: &Vec3<T>) -> Vec3<T> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a · s`.
#[inline(always)]
pub fn scale<T: Real>(a: &Vec3<T>, s: T) -> Vec3<T> {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// `R x` for R given by its columns `r`, as nalgebra's 3×3 product sums it: `(r₀ x₀ + r₁ x₁) + r₂ x₂`.
#[inline(always)]
pub fn mat_vec<T: Real>(r: &[Vec3<T>; 3], x: &Vec3<T>) -> Vec3<T> {
    // written out, not `std::array::from_fn`: with F4 that stayed a call (`core::array::try_from_fn`, its result
    // through memory), 3 % of the identification's time (perf)
    let row = |a: usize| r[0][a] * x[0] + r[1][a] * x[1] + r[2][a] * x[2];
    [row(0), row(1), row(2)]
}

/// `Rᵀ x` for R given by its columns `r`: the dot product of every column with x, in the same order.
#[inline(always)]
pub fn mat_t_vec<T: Real>(r: &[Vec3<T>; 3], x: &Vec3<T>) -> Vec3<T> {
    // written out, as in `mat_vec`
    let dot = |a: usize| r[a][0] * x[0] + r[a][1] * x[1] + r[a][2] * x[2];
    [dot(0), dot(1), dot(2)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::{M3, V3};

    fn mix(i: usize) -> f64 {
        ((i * 7919 + 13) % 1009) as f64 / 1009.0 * 2.0 - 1.0 + 1e-3 * (i as f64).sin()
    }

    #[test]
    fn the_shared_formulas_match_nalgebra_bit_for_bit() {
        for t in 0..2000 {
            let a = V3::new(mix(6 * t), mix(6 * t + 1), mix(6 * t + 2));
            let b = V3::new(mix(6 * t + 3), mix(6 * t + 4), mix(6 * t + 5));
            let r = M3::from_fn(|i, j| mix(9 * t + 3 * i + j + 50_000));
            let cols = [0, 1, 2].map(|k| [r[(0, k)], r[(1, k)], r[(2, k)]]);
            let (av, bv) = ([a.x, a.y, a.z], [b.x, b.y, b.z]);
            assert_eq!(cross(&av, &bv), <[f64; 3]>::from(a.cross(&b)));
            assert_eq!(mat_vec(&cols, &av), <[f64; 3]>::from(r * a));
            assert_eq!(mat_t_vec(&cols, &av), <[f64; 3]>::from(r.transpose() * a));
        }
    }

    #[test]
    fn every_lane_is_the_one_sample_result() {
        let x = F4([0.3, -1.7, 2.5e-9, 4.0e5]);
        let y = F4([-2.0, 0.125, 7.0, -3.3]);
        let z = F4([1.0, 1e-300, -0.0, 9.9]);
        let u = (x * y - z).mul_add(x + y, -z);
        for l in 0..LANES {
            let (a, b, c) = (x.0[l], y.0[l], z.0[l]);
            assert_eq!(u.0[l], (a * b - c).mul_add(a + b, -c));
        }
    }
}
