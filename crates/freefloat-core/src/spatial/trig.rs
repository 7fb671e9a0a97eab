//! Sine and cosine of joint angles, four at a time.
//!
//! Every revolute joint costs one sine and one cosine per kinematic sweep. The C library's `sincos` takes about
//! 120 instructions per call (18 % of a CRBA call on the seed robot, callgrind) and cannot be vectorised across
//! joints. This routine evaluates four angles in the lanes of one AVX2 register, with the same arithmetic in every
//! lane, so a batch and a single call give bit-identical results. Instructions per call on
//! `naveen_dual_arm_consistent` (callgrind, `kernel_loop K naveen_dual_arm_consistent N wide`, difference of two N):
//! CRBA 6,027 → 5,485, ABA 10,936 → 10,312, forward kinematics 2,927 → 2,303.
//!
//! Method (textbook; all constants derived here):
//! - **Reduction.** `k = round(x · 2/π)` and `r = x − k π/2`, with π/2 split into three doubles
//!   `P1 + P2 + P3` (from 80 digits of π; residual 5.6e-50). `x − k P1` is exact (for k ≠ 0, |x| > π/4: both
//!   terms are multiples of 2⁻⁵³ and their difference is below 1 in magnitude); `k P2` is formed exactly by a fused
//!   multiply-add and the difference by an error-free sum, so `r` is kept as a double-double `r_hi + r_lo`.
//! - **Kernels on |r| ≤ π/4.** Taylor series, sine to r¹⁷ (truncation 1e-19 relative) and cosine to r¹⁶ (3e-18),
//!   with the first-order correction for `r_lo`. The cosine's `1 − r²/2` is summed with its own rounding error
//!   recovered, so the last addition is the only sizeable rounding in either result.
//! - **Quadrant.** `k mod 4` swaps and negates the kernels.
//!
//! Measured against glibc's `sin_cos` (`tests` below): never more than one ulp apart on a million joint angles in
//! [−4π, 4π] and three million angles in [−1.1e6, 1.1e6]. Arguments beyond `LIMIT` (where the three-part split
//! stops being enough) and non-finite ones go to the C library. The sign of a zero result is not kept (sin(−0) is
//! +0 here).

/// Beyond this magnitude the three-part reduction is not used (the C library's call is).
const LIMIT: f64 = 1.0e6;
/// 2/π rounded to a double; only used to choose k, whose rounding errors the exact reduction absorbs.
const FRAC_2_PI: f64 = std::f64::consts::FRAC_2_PI;
/// π/2 = P1 + P2 + P3 + O(1e-49) (hex 3ff921fb54442d18, 3c91a62633145c07, b91f1976b7ed8fbc).
const P1: f64 = std::f64::consts::FRAC_PI_2;
const P2: f64 = 6.123_233_995_736_766e-17;
const P3: f64 = -1.497_384_904_859_169_8e-33;

/// Taylor coefficients of sin r = r + r³ Σ S[j] z^j (z = r²): (−1)^(j+1) / (2j + 3)!.
const S: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];
/// Taylor coefficients of cos r = 1 − z/2 + z² Σ C[j] z^j: (−1)^j / (2j + 4)!.
const C: [f64; 7] = [
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
];

/// Lane count of `sin_cos4`.
pub const LANES: usize = 4;

/// `(sin x, cos x)` of one angle: lane 0 of `sin_cos4`, the same operations, so the same bits.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let (s, c) = sin_cos4([x; LANES]);
    (s[0], c[0])
}

/// Sines and cosines of four angles. Each step is written as a loop over the four lanes so that it compiles to one
/// vector instruction; no lane's result depends on the others.
///
/// Always inlined: forward kinematics calls it for every four bodies at every simulation stage, and as a call its
/// lanes went to the stack and back (10-body RK4 `sim10s_table`: CPU time −5 %, median of 31 interleaved runs).
#[inline(always)]
pub fn sin_cos4(x: [f64; LANES]) -> ([f64; LANES], [f64; LANES]) {
    sin_cos_lanes(x)
}

/// [`sin_cos4`] for L angles (L = 8 fills an AVX-512 register where the caller is compiled for AVX-512): the same
/// operations in every lane, so lane l equals `sin_cos` of angle l to the bit, whatever L. Inlined into its caller
/// so that it is compiled with the caller's target features.
#[inline(always)]
pub fn sin_cos_lanes<const L: usize>(x: [f64; L]) -> ([f64; L], [f64; L]) {
    let mut k = [0.0; L];
    let mut in_range = true;
    for l in 0..L {
        // `abs() <= LIMIT` is false for NaN, so non-finite angles take the library path too
        in_range &= x[l].abs() <= LIMIT;
        k[l] = (x[l] * FRAC_2_PI).round_ties_even();
    }
    if !in_range {
        return library_sin_cos(x);
    }
    // r = x − k π/2 as r_hi + r_lo
    let (mut r_hi, mut r_lo) = ([0.0; L], [0.0; L]);
    for l in 0..L {
        // r1 = x − k P1 is exact (module comment), k P2 = t_hi + t_lo exactly, and r1 − t_hi = hi + err exactly
        // (Knuth's two-sum: near a multiple of π/2, |r1| can be below |t_hi|)
        let r1 = (-k[l]).mul_add(P1, x[l]);
        let t_hi = k[l] * P2;
        let t_lo = k[l].mul_add(P2, -t_hi);
        let hi = r1 - t_hi;
        let back = hi - r1;
        let err = (r1 - (hi - back)) + (-t_hi - back);
        r_hi[l] = hi;
        r_lo[l] = (err - t_lo) - k[l] * P3;
    }
    let (mut s, mut c) = ([0.0; L], [0.0; L]);
    for l in 0..L {
        let (h, lo) = (r_hi[l], r_lo[l]);
        let z = h * h;
        let mut ps = S[7];
        for j in (0..7).rev() {
            ps = ps.mul_add(z, S[j]);
        }
        // sin(h + lo) ≈ h + (h z ps + lo (1 − z/2)); the bracket is a tenth of h at most
        let tail_s = (h * z).mul_add(ps, lo.mul_add(-0.5 * z, lo));
        s[l] = h + tail_s;
        let mut pc = C[6];
        for j in (0..6).rev() {
            pc = pc.mul_add(z, C[j]);
        }
        // cos(h + lo) ≈ (1 − z/2) + (z² pc − h lo); w = 1 − z/2 rounded, (1 − w) − z/2 its rounding error exactly
        let hz = 0.5 * z;
        let w = 1.0 - hz;
        let tail_c = ((1.0 - w) - hz) + (z * z).mul_add(pc, -h * lo);
        c[l] = w + tail_c;
    }
    // quadrant m = k mod 4: (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s)
    let (mut sin, mut cos) = ([0.0; L], [0.0; L]);
    for l in 0..L {
        let m = k[l] - 4.0 * (0.25 * k[l]).floor();
        let swap = m == 1.0 || m == 3.0;
        let (a, b) = if swap { (c[l], s[l]) } else { (s[l], c[l]) };
        sin[l] = if m >= 2.0 { -a } else { a };
        cos[l] = if m == 1.0 || m == 2.0 { -b } else { b };
    }
    (sin, cos)
}

#[cold]
fn library_sin_cos<const L: usize>(x: [f64; L]) -> ([f64; L], [f64; L]) {
    let (mut s, mut c) = ([0.0; L], [0.0; L]);
    for l in 0..L {
        // the in-range lanes must not change with their neighbours: they take the routine, one lane at a time
        (s[l], c[l]) = if x[l].abs() <= LIMIT { sin_cos(x[l]) } else { x[l].sin_cos() };
    }
    (s, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        // distance in representable doubles (same sign here, or across zero for tiny values)
        let key = |v: f64| {
            let bits = v.to_bits() as i64;
            if bits < 0 {
                i64::MIN - bits
            } else {
                bits
            }
        };
        key(a).abs_diff(key(b))
    }

    fn sweep(args: impl Iterator<Item = f64>) -> (u64, usize, usize) {
        let (mut worst, mut differ, mut count) = (0, 0, 0);
        let xs: Vec<f64> = args.collect();
        for chunk in xs.chunks(LANES) {
            let mut lane = [0.0; LANES];
            lane[..chunk.len()].copy_from_slice(chunk);
            let (s, c) = sin_cos4(lane);
            for (l, &x) in chunk.iter().enumerate() {
                let (rs, rc) = x.sin_cos();
                let d = ulps(s[l], rs).max(ulps(c[l], rc));
                assert!(d <= 1, "sin_cos({x:e}) = ({:e}, {:e}), library ({rs:e}, {rc:e}): {d} ulps", s[l], c[l]);
                // the single call takes lane 0 of the same arithmetic: the same bits
                assert_eq!(sin_cos(x), (s[l], c[l]), "single call of {x:e}");
                worst = worst.max(d);
                differ += usize::from(d > 0);
                count += 1;
            }
        }
        // eight lanes (the AVX-512 width): every lane the single call's bits
        for chunk in xs.chunks(8) {
            let mut lane = [0.0; 8];
            lane[..chunk.len()].copy_from_slice(chunk);
            let (s, c) = sin_cos_lanes(lane);
            for (l, &x) in chunk.iter().enumerate() {
                assert_eq!(sin_cos(x), (s[l], c[l]), "lane {l} of eight, {x:e}");
            }
        }
        (worst, differ, count)
    }

    #[test]
    fn within_one_ulp_of_the_c_library_on_joint_angles() {
        // dense on [−4π, 4π] (joint angles), including every multiple of π/4 and its neighbours
        let n = 1_000_000;
        let (worst, differ, count) =
            sweep((0..=n).map(|i| -4.0 * std::f64::consts::PI * (1.0 - 2.0 * i as f64 / n as f64)));
        assert!(worst <= 1 && count == n + 1);
        // most results are the library's bits exactly (a reimplementation that is 1 ulp off everywhere would fail)
        assert!((differ as f64) < 0.2 * count as f64, "{differ} of {count} differ");
        let near = (-64..=64).flat_map(|j| {
            let x = j as f64 * std::f64::consts::FRAC_PI_4;
            [x, x.next_up(), x.next_down(), x.next_up().next_up(), x.next_down().next_down()]
        });
        sweep(near);
    }

    #[test]
    fn within_one_ulp_of_the_c_library_on_large_and_tiny_angles() {
        // wheels spin for long: angles up to the reduction's limit, and around it (the library path)
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let big: Vec<f64> = (0..3_000_000).map(|_| (2.0 * next() - 1.0) * 1.1e6).collect();
        sweep(big.into_iter());
        let tiny = (0..2000).map(|i| (-1.0f64).powi(i) * 10f64.powf(-(i as f64) * 0.16));
        sweep(tiny);
        sweep([0.0, -0.0, f64::MIN_POSITIVE, 5e-324, LIMIT, -LIMIT, LIMIT.next_up(), 1e300, -1e300].into_iter());
    }

    #[test]
    fn the_split_of_half_pi_is_the_derived_one() {
        // from 80 digits of π (Machin's formula in decimal arithmetic): each part the double nearest the remainder
        assert_eq!(P1.to_bits(), 0x3ff9_21fb_5444_2d18);
        assert_eq!(P2.to_bits(), 0x3c91_a626_3314_5c07);
        assert_eq!(P3.to_bits(), 0xb91f_1976_b7ed_8fbc);
    }

    #[test]
    fn non_finite_angles_give_nan_and_leave_the_other_lanes_alone() {
        let x = [0.3, f64::NAN, f64::INFINITY, -2.0];
        let (s, c) = sin_cos4(x);
        assert!(s[1].is_nan() && c[1].is_nan() && s[2].is_nan() && c[2].is_nan());
        assert_eq!((s[0], c[0]), sin_cos(0.3));
        assert_eq!((s[3], c[3]), sin_cos(-2.0));
        let (s, c) = sin_cos_lanes([0.3, -2.0, 1.0, 2.0, 3.0, 4.0, 5.0, f64::NAN]);
        assert!(s[7].is_nan() && c[7].is_nan());
        assert_eq!((s[0], c[0]), sin_cos(0.3));
        assert_eq!((s[6], c[6]), sin_cos(5.0));
    }
}
