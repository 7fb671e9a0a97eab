//! The gains of the adaptive pose-tracking law (Valverde 2018, (4.11)–(4.12) = (4.27)–(4.28)): `K_p =
//! blkdiag(K_r, K_q)` on the pose error, `K_d = blkdiag(K_v, K_ω)` on the swapped sliding variable, `K_i` on the
//! update law and the concurrent-learning weight α.

use crate::dualquat::{DualQuat, Quat};
use crate::error::{FfError, Result};
use crate::spatial::M3;
use nalgebra::SMatrix;

/// 7×7 matrix on dual-inertia parameter vectors.
pub type M7 = SMatrix<f64, 7, 7>;

/// The gain matrices of (4.11)–(4.12) and (4.13), each symmetric positive definite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains {
    /// K̄_r: position block of K_p (acts on the real part of e, ½ r̄).
    pub k_r: M3,
    /// K̄_q: attitude block of K_p (acts on the dual part of e, q̄).
    pub k_q: M3,
    /// K̄_v: linear block of K_d (acts on the real part of s^s, v̄ + ½ K̄_r r̄).
    pub k_v: M3,
    /// K̄_ω: angular block of K_d (acts on the dual part of s^s, ω̄ + K̄_q q̄).
    pub k_w: M3,
    /// K_i: the adaptation gain of (4.13)/(4.29).
    pub k_i: M7,
    /// K_i⁻¹, for the Lyapunov function (4.17).
    k_i_inv: M7,
}

fn check_spd<const N: usize>(name: &str, k: &SMatrix<f64, N, N>) -> Result<()> {
    if k.iter().any(|x| !x.is_finite()) {
        return Err(FfError::arg(name, "has non-finite entries"));
    }
    if (k - k.transpose()).amax() > 1e-12 * k.amax().max(1.0) {
        return Err(FfError::arg(name, "must be symmetric"));
    }
    let min = nalgebra::DMatrix::from_column_slice(N, N, k.as_slice()).symmetric_eigenvalues().min();
    if !(min > 0.0) {
        return Err(FfError::arg(
            name,
            format!("must be positive definite (smallest eigenvalue {min:.4}; a gain must be > 0)"),
        ));
    }
    Ok(())
}

impl Gains {
    /// From the four 3×3 blocks and K_i; each must be symmetric positive definite (the error names the gain).
    pub fn new(k_r: M3, k_q: M3, k_v: M3, k_w: M3, k_i: M7) -> Result<Gains> {
        check_spd("K_r", &k_r)?;
        check_spd("K_q", &k_q)?;
        check_spd("K_v", &k_v)?;
        check_spd("K_w", &k_w)?;
        check_spd("K_i", &k_i)?;
        let k_i_inv = k_i.cholesky().ok_or_else(|| FfError::arg("K_i", "must be positive definite"))?.inverse();
        Ok(Gains { k_r, k_q, k_v, k_w, k_i, k_i_inv })
    }
    /// Scalar gains `K̄ = k I₃`, `K_i = k_i I₇` (the form of the thesis' examples, §4.5).
    pub fn scalar(k_r: f64, k_q: f64, k_v: f64, k_w: f64, k_i: f64) -> Result<Gains> {
        let i3 = M3::identity();
        Gains::new(k_r * i3, k_q * i3, k_v * i3, k_w * i3, k_i * M7::identity())
    }
    /// K_i⁻¹.
    pub fn k_i_inverse(&self) -> &M7 {
        &self.k_i_inv
    }
    /// `K_p ⋆ x` (4.11): K̄_r on the real vector part, K̄_q on the dual vector part, the scalar slots zeroed.
    #[inline]
    pub fn kp(&self, x: &DualQuat) -> DualQuat {
        DualQuat::new(Quat::pure(&(self.k_r * x.r.v)), Quat::pure(&(self.k_q * x.d.v)))
    }
    /// `K_d ⋆ x` (4.12): K̄_v on the real vector part, K̄_ω on the dual vector part, the scalar slots zeroed.
    #[inline]
    pub fn kd(&self, x: &DualQuat) -> DualQuat {
        DualQuat::new(Quat::pure(&(self.k_v * x.r.v)), Quat::pure(&(self.k_w * x.d.v)))
    }
}
