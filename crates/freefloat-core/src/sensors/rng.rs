//! The sensors' random numbers: ChaCha8 (a counter-based cipher stream, the same numbers on every
//! machine and platform for the same seed) turned into standard normal deviates by Box-Muller.

use rand_chacha::rand_core::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Standard normal deviates from a seeded ChaCha8 stream.
///
/// Each sensor draws from its own stream (`seed`, plus a stream number made from the sensor's name),
/// so adding, removing or reordering sensors leaves the other sensors' errors unchanged.
#[derive(Clone, Debug)]
pub struct GaussianRng {
    rng: ChaCha8Rng,
    spare: Option<f64>,
}

impl GaussianRng {
    /// The stream of `seed` for the sensor called `name`.
    pub fn new(seed: u64, name: &str) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(fnv1a(name));
        GaussianRng { rng, spare: None }
    }

    /// A uniform deviate in the open interval (0, 1): 53 random bits, offset by half a unit so that
    /// neither end is reached (Box-Muller takes its logarithm).
    pub fn uniform(&mut self) -> f64 {
        ((self.rng.next_u64() >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal deviate (Box-Muller: two uniforms give two independent normals; the second
    /// is kept for the next call).
    pub fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
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
        let (mut s, mut s2, mut diff) = (0.0, 0.0, 0usize);
        for _ in 0..n {
            let x = a.normal();
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
        assert!(diff > n - 10, "streams of two names must differ");
    }
}
