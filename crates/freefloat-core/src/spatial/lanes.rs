//! Samples side by side: [`Lanes<L>`] holds one `f64` per sample, and every operation acts lane by lane (each is a
//! loop over the L lanes, which compiles to one vector instruction: four lanes ([`F4`]) fill an AVX2 register,
//! eight an AVX-512 one, in code compiled for it). [`Real`] is what a formula written once needs from its
//! numbers, so the same source serves one sample (`f64`) and L (`Lanes<L>`) with the same operations in the same
//! order: lane l of an L-sample result equals, bit for bit, the one-sample result for sample l.
//!
//! Used where a pass over many independent samples would otherwise run the same small formulas once per sample
//! (the identification's regressor stream: kinematics and the momentum regressor, four or eight samples per step).

use std::ops::{Add, Mul, Neg, Sub};

/// Samples per [`F4`]: the lane count of `trig::sin_cos4` (the four-sample kinematics feeds one to the other).
pub use super::trig::LANES;

/// L `f64`, one per sample.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct Lanes<const L: usize>(pub [f64; L]);

/// Four samples: one AVX2 register, the x86-64-v3 baseline's width.
pub type F4 = Lanes<LANES>;

/// The arithmetic a formula shared by `f64` and [`Lanes`] uses.
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

impl<const L: usize> Lanes<L> {
    /// Lane l from `f(l)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
        // a loop, not `std::array::from_fn`, which is not always inlined (as in `mat_vec`): an out-of-line copy
        // would not be compiled with an AVX-512 caller's registers
        let mut x = [0.0; L];
        for (l, x) in x.iter_mut().enumerate() {
            *x = f(l);
        }
        Lanes(x)
    }
}

impl<const L: usize> Real for Lanes<L> {
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Lanes::from_fn(|l| self.0[l].mul_add(a.0[l], b.0[l]))
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Lanes([x; L])
    }
}

macro_rules! lane_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl<const L: usize> $tr for Lanes<L> {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                Lanes::from_fn(|l| self.0[l] $op o.0[l])
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);

impl<const L: usize> Neg for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Lanes::from_fn(|l| -self.0[l])
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
        check::<4>();
        check::<8>();
    }

    fn check<const L: usize>() {
        let pick = |v: &[f64]| Lanes::<L>::from_fn(|l| v[l % 4] * (1.0 + l as f64));
        let x = pick(&[0.3, -1.7, 2.5e-9, 4.0e5]);
        let y = pick(&[-2.0, 0.125, 7.0, -3.3]);
        let z = pick(&[1.0, 1e-300, -0.0, 9.9]);
        let u = (x * y - z).mul_add(x + y, -z);
        for l in 0..L {
            let (a, b, c) = (x.0[l], y.0[l], z.0[l]);
            assert_eq!(u.0[l], (a * b - c).mul_add(a + b, -c));
        }
    }
}
