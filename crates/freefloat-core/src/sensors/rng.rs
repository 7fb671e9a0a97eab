//! The sensors' random numbers: ChaCha8 (a counter-based cipher stream, the same numbers on every
//! machine and platform for the same seed) turned into standard normal deviates by the ziggurat method
//! in Doornik's form (J. A. Doornik, "An Improved Ziggurat Method to Generate Normal Random Samples",
//! 2005: 128 layers, one 64-bit draw gives both the layer and the abscissa, Marsaglia's exact tail).

use rand_chacha::rand_core::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::sync::OnceLock;

/// Number of ziggurat layers.
const ZIG_C: usize = 128;
/// Start of the tail (Doornik 2005, for 128 layers).
const ZIG_R: f64 = 3.442_619_855_899;
/// Area of each layer.
const ZIG_V: f64 = 9.912_563_035_262_17e-3;

/// Layer abscissae x_0 … x_C and the ratios x_{i+1}/x_i (Doornik 2005, `zigNorInit`).
struct Ziggurat {
    x: [f64; ZIG_C + 1],
    ratio: [f64; ZIG_C],
}

fn ziggurat() -> &'static Ziggurat {
    static Z: OnceLock<Ziggurat> = OnceLock::new();
    Z.get_or_init(|| {
        let mut x = [0.0; ZIG_C + 1];
        let mut f = (-0.5 * ZIG_R * ZIG_R).exp();
        x[0] = ZIG_V / f;
        x[1] = ZIG_R;
        for i in 2..ZIG_C {
            x[i] = (-2.0 * (ZIG_V / x[i - 1] + f).ln()).sqrt();
            f = (-0.5 * x[i] * x[i]).exp();
        }
        x[ZIG_C] = 0.0;
        let mut ratio = [0.0; ZIG_C];
        for i in 0..ZIG_C {
            ratio[i] = x[i + 1] / x[i];
        }
        Ziggurat { x, ratio }
    })
}

/// Standard normal deviates from a seeded ChaCha8 stream (ziggurat).
///
/// Each sensor draws from its own stream (`seed`, plus a stream number made from the sensor's name),
/// so adding, removing or reordering sensors leaves the other sensors' errors unchanged.
#[derive(Clone, Debug)]
pub struct GaussianRng {
    rng: ChaCha8Rng,
}

impl GaussianRng {
    /// The stream of `seed` for the sensor called `name`.
    pub fn new(seed: u64, name: &str) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(fnv1a(name));
        GaussianRng { rng }
    }

    /// A uniform deviate in the open interval (0, 1): 53 random bits, offset by half a unit so that
    /// neither end is reached (the tail takes its logarithm).
    pub fn uniform(&mut self) -> f64 {
        ((self.rng.next_u64() >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal deviate (Doornik 2005, `DRanNormalZig`): the low 7 bits of one draw pick
    /// the layer, its top 53 bits the abscissa; about 99 % of draws return from the first test.
    pub fn normal(&mut self) -> f64 {
        let z = ziggurat();
        loop {
            let b = self.rng.next_u64();
            let i = (b & 0x7f) as usize;
            let u = 2.0 * ((b >> 11) as f64 * (1.0 / (1u64 << 53) as f64)) - 1.0;
            if u.abs() < z.ratio[i] {
                return u * z.x[i];
            }
            if i == 0 {
                return self.tail(u < 0.0);
            }
            let x = u * z.x[i];
            let f0 = (-0.5 * (z.x[i] * z.x[i] - x * x)).exp();
            let f1 = (-0.5 * (z.x[i + 1] * z.x[i + 1] - x * x)).exp();
            if f1 + self.uniform() * (f0 - f1) < 1.0 {
                return x;
            }
        }
    }

    /// A deviate from the normal tail beyond `ZIG_R` (Marsaglia 1964), with the given sign.
    fn tail(&mut self, negative: bool) -> f64 {
        loop {
            let x = self.uniform().ln() / ZIG_R;
            let y = self.uniform().ln();
            if -2.0 * y >= x * x {
                return if negative { x - ZIG_R } else { ZIG_R - x };
            }
        }
    }
}

/// 64-bit FNV-1a hash of a name: a stable stream number (not a security measure).
fn fnv1a(s: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in s.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_numbers_and_unit_variance() {
        let mut a = GaussianRng::new(7, "gyro");
        let mut b = GaussianRng::new(7, "gyro");
        let mut c = GaussianRng::new(7, "tacho");
        let n = 200_000;
        let (mut s, mut s2, mut s4, mut diff, mut beyond3) = (0.0, 0.0, 0.0, 0usize, 0usize);
        for _ in 0..n {
            let x = a.normal();
            s4 += x * x * x * x;
            if x.abs() > 3.0 {
                beyond3 += 1;
            }
            assert_eq!(x, b.normal());
            if x != c.normal() {
                diff += 1;
            }
            s += x;
            s2 += x * x;
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        assert!(mean.abs() < 5.0 / (n as f64).sqrt(), "mean {mean}");
        assert!((var - 1.0).abs() < 0.02, "variance {var}");
        let kurt = s4 / n as f64;
        assert!((kurt - 3.0).abs() < 0.1, "fourth moment {kurt}");
        // P(|z| > 3) = 0.0027: 540 expected, Poisson spread ~23
        assert!((beyond3 as f64 - 540.0).abs() < 100.0, "{beyond3} beyond 3 sigma");
        assert!(diff > n - 10, "streams of two names must differ");
    }
}
