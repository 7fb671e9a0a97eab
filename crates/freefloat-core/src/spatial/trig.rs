//! Sine and cosine of one angle together, for the joint rotations of every kinematic pass.
//!
//! glibc's `sincos` costs about 120 instructions per call on joint angles in [-π, π] (its slow path starts above
//! about 0.86 rad), a sixth of the CRBA on a 15-DoF robot (callgrind). Here: one Cody-Waite reduction by π/2 kept
//! as a double-double `hi + lo`, then the Taylor series of sin and cos on |r| ≤ π/4, carried to the first term
//! below half an ulp (x¹⁷/17! and x¹⁶/16!), with the leading terms added last so that their rounding is the only
//! one that counts: within one ulp of the correctly rounded result (the test below checks it against glibc's
//! on a few million angles). Angles beyond `LIMIT`, infinities and NaN take `f64::sin_cos`.

/// π/2 as three doubles (C1 + C2 + C3 = π/2 within 6e-50). C1 is the double nearest π/2.
const C1: f64 = std::f64::consts::FRAC_PI_2;
const C2: f64 = 6.123_233_995_736_766e-17;
const C3: f64 = -1.497_384_904_859_169_8e-33;
/// Largest |x| reduced here: n = round(2x/π) stays below 2²⁰, so x − n C1 is exact (one fused multiply-add: the
/// difference is a multiple of 2⁻⁵³ below 1 in magnitude) and n (C2 + C3) has no error that matters.
const LIMIT: f64 = 1.0e6;

/// `(sin x, cos x)`, each within one ulp of the correctly rounded value.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let a = x.abs();
    if a <= std::f64::consts::FRAC_PI_4 {
        if a < 1.0e-9 {
            // x − x³/6 rounds to x (x²/6 < 2⁻⁵⁵), and the sign of a zero is kept
            return (x, 1.0);
        }
        return kernel(x, 0.0);
    }
    if !(a <= LIMIT) {
        return x.sin_cos();
    }
    let n = (x * std::f64::consts::FRAC_2_PI).round_ties_even();
    // r = x − n π/2 as hi + lo: r1 exact, then n C2 subtracted with a two-sum and the product's own error (fma)
    let r1 = (-n).mul_add(C1, x);
    let p2 = n * C2;
    let e2 = n.mul_add(C2, -p2);
    let hi = r1 - p2;
    let bb = hi - r1;
    let err = (r1 - (hi - bb)) + (-p2 - bb);
    let lo = err - n.mul_add(C3, e2);
    let (s, c) = kernel(hi, lo);
    // x = n π/2 + r: by n mod 4, (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s). Without branches (the quadrant of
    // a joint angle is as good as random, and a mispredicted jump costs more than these integer operations): an odd
    // n swaps the two (bit select), bit 1 of n flips the sine's sign and bit 1 of n + 1 the cosine's. Two's
    // complement keeps the bits right for a negative n.
    // x = n π/2 + r: by n mod 4, (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s). Without branches (the quadrant of
    // a joint angle is as good as random, and a mispredicted jump costs more than these few operations): an odd n
    // swaps the two (a bit select), then the signs come from a table (multiplications by ±1 are exact). Two's
    // complement keeps n mod 4 right for a negative n.
    const SIGN: [[f64; 2]; 4] = [[1.0, 1.0], [1.0, -1.0], [-1.0, -1.0], [-1.0, 1.0]];
    let k = (n as i64 & 3) as usize;
    let swap = 0u64.wrapping_sub((k & 1) as u64);
    let (sb, cb) = (s.to_bits(), c.to_bits());
    let s1 = f64::from_bits((sb & !swap) | (cb & swap));
    let c1 = f64::from_bits((cb & !swap) | (sb & swap));
    (s1 * SIGN[k][0], c1 * SIGN[k][1])
}

/// sin and cos of `hi + lo`, |hi| ≤ π/4 (slightly more after the rounding of n), |lo| ≤ ulp(hi).
#[inline(always)]
fn kernel(hi: f64, lo: f64) -> (f64, f64) {
    // Taylor coefficients 1/k! with alternating signs (each the double nearest the quotient)
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
    const C: [f64; 7] = [
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
        -1.0 / 87_178_291_200.0,
        1.0 / 20_922_789_888_000.0,
    ];
    let z = hi * hi;
    let ez = hi.mul_add(hi, -z); // hi² = z + ez exactly
    let ps = S[7].mul_add(z, S[6]).mul_add(z, S[5]).mul_add(z, S[4]).mul_add(z, S[3]);
    let ps = ps.mul_add(z, S[2]).mul_add(z, S[1]).mul_add(z, S[0]);
    let pc = C[6].mul_add(z, C[5]).mul_add(z, C[4]).mul_add(z, C[3]).mul_add(z, C[2]);
    let pc = pc.mul_add(z, C[1]).mul_add(z, C[0]);
    let hz = 0.5 * z;
    // sin(hi + lo) = hi + hi³ S(hi²) + lo cos(hi) (first order in lo)
    let s = hi + (hi * z).mul_add(ps, lo * (1.0 - hz));
    // cos(hi + lo) = 1 − hi²/2 + hi⁴ C(hi²) − hi lo; 1 − hz rounded to w, its error (1 − w) − hz (exact) carried
    let w = 1.0 - hz;
    let tail = (z * z).mul_add(pc, (-0.5f64).mul_add(ez, -(hi * lo)));
    let c = w + (((1.0 - w) - hz) + tail);
    (s, c)
}

#[cfg(test)]
mod tests {
    use super::sin_cos;

    /// Distance in ulps between two finite doubles of one sign (0 when equal).
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        let key = |x: f64| {
            let i = x.to_bits() as i64;
            if i < 0 {
                i64::MIN - i
            } else {
                i
            }
        };
        key(a).abs_diff(key(b))
    }

    #[test]
    fn within_one_ulp_of_glibc() {
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut unit = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst = 0;
        for &scale in &[0.8, std::f64::consts::PI, 10.0, 1.0e3, 1.0e6, 2.0e6] {
            for _ in 0..400_000 {
                let x = scale * (2.0 * unit() - 1.0);
                let (s, c) = sin_cos(x);
                let (s0, c0) = x.sin_cos();
                worst = worst.max(ulps(s, s0)).max(ulps(c, c0));
                assert!(ulps(s, s0) <= 1 && ulps(c, c0) <= 1, "x = {x:e}: ({s:e}, {c:e}) vs ({s0:e}, {c0:e})");
            }
        }
        // near the multiples of π/2, where the reduction cancels most digits
        for k in -2000i32..2000 {
            let x0 = f64::from(k) * std::f64::consts::FRAC_PI_2;
            let mut x = x0;
            for _ in 0..8 {
                let (s, c) = sin_cos(x);
                let (s0, c0) = x.sin_cos();
                assert!(ulps(s, s0) <= 1 && ulps(c, c0) <= 1, "x = {x:e}: ({s:e}, {c:e}) vs ({s0:e}, {c0:e})");
                x = x.next_up();
            }
        }
        for x in [0.0, -0.0, 1e-300, -1e-300, f64::MIN_POSITIVE, 1e-8, 0.5, 1e7, -3e10] {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            assert!(ulps(s, s0) <= 1 && ulps(c, c0) <= 1, "x = {x:e}");
        }
        assert!(sin_cos(f64::NAN).0.is_nan() && sin_cos(f64::INFINITY).1.is_nan());
        assert!(worst <= 1);
    }
}
