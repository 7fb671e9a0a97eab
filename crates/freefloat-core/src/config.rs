//! Configuration-space geometry used by the integrators.
//!
//! The configuration is a product group: R³ × SO(3) for a free base (position in the inertial
//! frame, attitude), SO(3) for a spherical joint, and plain reals for everything else. The
//! integrators work in tangent coordinates `δ` (length nv) about a fixed configuration `q0`:
//! `q = retract(q0, δ)`, with `δ` = [inertial-frame displacement, body rotation vector] for a free
//! base. On this group the stage velocities need the dexp⁻¹ correction (Munthe-Kaas) for Runge-Kutta
//! to keep its order; see `so3_right_jacobian_inv`.

use crate::check::{check_len, check_vec};
use crate::error::Result;
use crate::model::{JointType, Model};
use crate::spatial::{quat_exp, quat_mul, quat_normalize, rot_from_quat, so3_right_jacobian_inv, V3};

/// Time derivative of the tangent coordinates at `q` for velocity `v` (at δ = 0):
/// free base [R v_lin, ω], planar base [R(yaw) v_xy, ω_z], spherical ω, scalar joints v.
/// `q`: nq, `v`, `out`: nv.
pub fn tangent_rate(m: &Model, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<()> {
    check_vec("q", q, m.nq)?;
    check_vec("v", v, m.nv)?;
    check_len("out", out.len(), m.nv)?;
    tangent_rate_unchecked(m, q, v, out);
    Ok(())
}

pub(crate) fn tangent_rate_unchecked(m: &Model, q: &[f64], v: &[f64], out: &mut [f64]) {
    for i in 0..m.nbodies() {
        let (iq, iv) = (m.idx_q[i], m.idx_v[i]);
        match m.joint_types[i] {
            JointType::Free => {
                let r = rot_from_quat(&q[iq + 3..iq + 7]);
                let lin = r * V3::new(v[iv], v[iv + 1], v[iv + 2]);
                out[iv..iv + 3].copy_from_slice(lin.as_slice());
                out[iv + 3..iv + 6].copy_from_slice(&v[iv + 3..iv + 6]);
            }
            JointType::Planar => {
                let (s, c) = q[iq + 2].sin_cos();
                out[iv] = c * v[iv] - s * v[iv + 1];
                out[iv + 1] = s * v[iv] + c * v[iv + 1];
                out[iv + 2] = v[iv + 2];
            }
            _ => out[iv..iv + m.nvs[i]].copy_from_slice(&v[iv..iv + m.nvs[i]]),
        }
    }
}

/// `q = q0 ⊕ δ`: additive on reals and positions, `quat0 ⊗ exp(δθ)` on rotations.
/// `q0`, `out`: nq, `delta`: nv.
pub fn retract(m: &Model, q0: &[f64], delta: &[f64], out: &mut [f64]) -> Result<()> {
    check_vec("q0", q0, m.nq)?;
    check_vec("delta", delta, m.nv)?;
    check_len("out", out.len(), m.nq)?;
    retract_unchecked(m, q0, delta, out);
    Ok(())
}

pub(crate) fn retract_unchecked(m: &Model, q0: &[f64], delta: &[f64], out: &mut [f64]) {
    for i in 0..m.nbodies() {
        let (iq, iv) = (m.idx_q[i], m.idx_v[i]);
        match m.joint_types[i] {
            JointType::Free => {
                for k in 0..3 {
                    out[iq + k] = q0[iq + k] + delta[iv + k];
                }
                rotate(&q0[iq + 3..iq + 7], &delta[iv + 3..iv + 6], &mut out[iq + 3..iq + 7]);
            }
            JointType::Spherical => rotate(&q0[iq..iq + 4], &delta[iv..iv + 3], &mut out[iq..iq + 4]),
            _ => {
                for k in 0..m.nqs[i] {
                    out[iq + k] = q0[iq + k] + delta[iv + k];
                }
            }
        }
    }
}

fn rotate(q0: &[f64], phi: &[f64], out: &mut [f64]) {
    let a = [q0[0], q0[1], q0[2], q0[3]];
    let mut r = quat_mul(&a, &quat_exp(&V3::new(phi[0], phi[1], phi[2])));
    quat_normalize(&mut r);
    out.copy_from_slice(&r);
}

/// Map a velocity `k` (in the algebra at `q0 ⊕ δ`) to the rate of the tangent coordinates δ:
/// `Jr(δθ)⁻¹ k` on rotation blocks, identity elsewhere. Applied in place. `delta`, `k`: nv.
pub fn dexpinv(m: &Model, delta: &[f64], k: &mut [f64]) -> Result<()> {
    check_vec("delta", delta, m.nv)?;
    check_vec("k", k, m.nv)?;
    dexpinv_unchecked(m, delta, k);
    Ok(())
}

pub(crate) fn dexpinv_unchecked(m: &Model, delta: &[f64], k: &mut [f64]) {
    for i in 0..m.nbodies() {
        let off = match m.joint_types[i] {
            JointType::Free => m.idx_v[i] + 3,
            JointType::Spherical => m.idx_v[i],
            _ => continue,
        };
        let th = V3::new(delta[off], delta[off + 1], delta[off + 2]);
        let w = V3::new(k[off], k[off + 1], k[off + 2]);
        let r = so3_right_jacobian_inv(&th, &w);
        k[off..off + 3].copy_from_slice(r.as_slice());
    }
}

/// Scale used by adaptive error control for each tangent coordinate (rotations: 1 rad).
/// `q`: nq, `out`: nv.
pub fn tangent_magnitude(m: &Model, q: &[f64], out: &mut [f64]) -> Result<()> {
    check_vec("q", q, m.nq)?;
    check_len("out", out.len(), m.nv)?;
    tangent_magnitude_unchecked(m, q, out);
    Ok(())
}

pub(crate) fn tangent_magnitude_unchecked(m: &Model, q: &[f64], out: &mut [f64]) {
    for i in 0..m.nbodies() {
        let (iq, iv) = (m.idx_q[i], m.idx_v[i]);
        match m.joint_types[i] {
            JointType::Free => {
                for k in 0..3 {
                    out[iv + k] = q[iq + k].abs();
                }
                out[iv + 3..iv + 6].fill(1.0);
            }
            JointType::Spherical => out[iv..iv + 3].fill(1.0),
            _ => {
                for k in 0..m.nqs[i] {
                    out[iv + k] = q[iq + k].abs();
                }
            }
        }
    }
}
