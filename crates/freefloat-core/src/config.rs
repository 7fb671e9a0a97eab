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
    // The rate is v itself except on a free or planar base: one copy of all of it, then the base's block (only
    // the base can have those joints: `ModelBuilder` refuses them elsewhere). Copying joint by joint cost a
    // memcpy call per joint.
    out.copy_from_slice(&v[..out.len()]);
    match m.joint_types[0] {
        JointType::Free => {
            let r = rot_from_quat(&q[3..7]);
            let lin = r * V3::new(v[0], v[1], v[2]);
            out[..3].copy_from_slice(lin.as_slice());
        }
        JointType::Planar => {
            let (s, c) = q[2].sin_cos();
            out[0] = c * v[0] - s * v[1];
            out[1] = s * v[0] + c * v[1];
        }
        _ => {}
    }
    debug_assert!(m.joint_types.iter().skip(1).all(|j| !matches!(j, JointType::Free | JointType::Planar)));
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
    // The layout of q and δ: every coordinate is additive except the unit quaternions (free base, spherical
    // joints: 4 entries in q, a rotation vector of 3 in δ), and the additive ones appear in q and in δ in the
    // same order. So between two quaternions lies one run of additive coordinates, added in one sliced loop;
    // walking the model's quaternion list replaces a walk over every body with its per-joint loops and bounds
    // checks (three fifths of the retraction on a 15-DoF robot, callgrind).
    let (mut iq, mut iv) = (0, 0);
    for &(_, oq) in m.quaternions() {
        let len = oq - iq;
        add(q0, delta, out, (iq, iv, len));
        iv += len;
        rotate(&q0[oq..oq + 4], &delta[iv..iv + 3], &mut out[oq..oq + 4]);
        (iq, iv) = (oq + 4, iv + 3);
    }
    add(q0, delta, out, (iq, iv, m.nq - iq));
    debug_assert_eq!(iv + m.nq - iq, m.nv, "q and v layouts differ by one entry per quaternion");
}

/// `out = q0 + delta` on the run (q index, v index, length) of additive coordinates.
#[inline]
fn add(q0: &[f64], delta: &[f64], out: &mut [f64], (iq, iv, len): (usize, usize, usize)) {
    for ((o, a), d) in out[iq..iq + len].iter_mut().zip(&q0[iq..iq + len]).zip(&delta[iv..iv + len]) {
        *o = a + d;
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
    // The rotation blocks: the j-th quaternion of q, at q offset oq, has its rotation vector at oq - j in δ (each
    // quaternion before it takes one entry more in q than in δ; see `retract_unchecked`).
    for (j, &(_, oq)) in m.quaternions().iter().enumerate() {
        let off = oq - j;
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
