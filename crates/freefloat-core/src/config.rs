//! Configuration-space geometry used by the integrators.
//!
//! The configuration is a product group: R³ × SO(3) for a free base (position in the inertial
//! frame, attitude), SO(3) for a spherical joint, and plain reals for everything else. The
//! integrators work in tangent coordinates `δ` (length nv) about a fixed configuration `q0`:
//! `q = retract(q0, δ)`, with `δ` = [inertial-frame displacement, body rotation vector] for a free
//! base. On this group the stage velocities need the dexp⁻¹ correction (Munthe-Kaas) for Runge-Kutta
//! to keep its order; see `so3_right_jacobian_inv`.
//!
//! This is the one copy of the configuration space's `⊕`/`⊖` and of their Jacobians: `retract` (δ's base position in
//! inertial axes, the simulator's chart) and `integrate`/`difference` (base axes, the chart of
//! `dynamics::derivatives`, re-exported there) share the rotations' update. The SO(3) functions are
//! `spatial::lie`'s.

use crate::check::{check_len, check_q, check_shape, check_vec};
use crate::error::Result;
use crate::model::{JointType, Model};
use crate::spatial::lie::{
    quat_exp, quat_log, so3_exp, so3_right_jacobian, so3_right_jacobian_inv, so3_right_jacobian_inv_dtheta,
    so3_right_jacobian_inv_matrix,
};
use crate::spatial::{quat_mul, quat_normalize, rot_from_quat, skew, M3, V3};
use nalgebra::DMatrix;

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

// ---------------------------------------------------------------- ⊕ and ⊖ in the derivatives' chart, and their Jacobians
//
// `integrate`/`difference` use the local (right) tangent of `dynamics::derivatives` (the base's linear part in
// base axes); `retract` above uses inertial axes for it. Both are the same group operation on R³ × SO(3).

#[inline]
fn quat_of(q: &[f64]) -> [f64; 4] {
    [q[0], q[1], q[2], q[3]]
}

#[inline]
fn conj(q: &[f64; 4]) -> [f64; 4] {
    [-q[0], -q[1], -q[2], q[3]]
}

#[inline]
fn set3(j: &mut DMatrix<f64>, r: usize, c: usize, b: &M3) {
    for i in 0..3 {
        for k in 0..3 {
            j[(r + i, c + k)] = b[(i, k)];
        }
    }
}

// ---------------------------------------------------------------- ⊕ and ⊖

/// `out = q ⊕ δ` (module documentation): free base `p + R δ_lin`, `quat ⊗ exp(δ_ang)` (δ in base
/// axes); planar base `[x, y] + R(yaw) δ_xy`, `yaw + δ_θ`; spherical `quat ⊗ exp(δ)`; others `q + δ`.
/// With `δ = v dt` this is one step at constant body velocity on R³ × SO(3). `q`, `out`: nq; `delta`: nv.
pub fn integrate(m: &Model, q: &[f64], delta: &[f64], out: &mut [f64]) -> Result<()> {
    check_q(m, q)?;
    check_vec("delta", delta, m.nv)?;
    check_len("out", out.len(), m.nq)?;
    integrate_unchecked(m, q, delta, out);
    Ok(())
}

pub(crate) fn integrate_unchecked(m: &Model, q: &[f64], delta: &[f64], out: &mut [f64]) {
    // The same group operation as `retract` (one copy of the rotations' ⊗ exp); only the chart of the base's
    // position differs (base axes here, inertial axes there), so the base's position is redone in base axes.
    retract_unchecked(m, q, delta, out);
    match m.joint_types[0] {
        JointType::Free => {
            let r = rot_from_quat(&q[3..7]);
            let p = V3::new(q[0], q[1], q[2]) + r * V3::new(delta[0], delta[1], delta[2]);
            out[..3].copy_from_slice(p.as_slice());
        }
        JointType::Planar => {
            let (s, c) = q[2].sin_cos();
            let (dx, dy) = (delta[0], delta[1]);
            out[0] = q[0] + c * dx - s * dy;
            out[1] = q[1] + s * dx + c * dy;
        }
        _ => {}
    }
}

/// `out = q1 ⊖ q0`, the δ with `q0 ⊕ δ = q1` (rotations: the one of angle ≤ π). `q0`, `q1`: nq;
/// `out`: nv.
pub fn difference(m: &Model, q0: &[f64], q1: &[f64], out: &mut [f64]) -> Result<()> {
    check_q(m, q0).map_err(|e| rename(e, "q0"))?;
    check_q(m, q1).map_err(|e| rename(e, "q1"))?;
    check_len("out", out.len(), m.nv)?;
    difference_unchecked(m, q0, q1, out);
    Ok(())
}

fn rename(e: crate::error::FfError, name: &str) -> crate::error::FfError {
    match e {
        crate::error::FfError::Argument { msg, .. } => crate::error::FfError::arg(name, msg),
        other => other,
    }
}

pub(crate) fn difference_unchecked(m: &Model, q0: &[f64], q1: &[f64], out: &mut [f64]) {
    for i in 0..m.nbodies() {
        let (iq, iv) = (m.idx_q[i], m.idx_v[i]);
        match m.joint_types[i] {
            JointType::Free => {
                let r0 = rot_from_quat(&q0[iq + 3..iq + 7]);
                let dp = V3::new(q1[iq] - q0[iq], q1[iq + 1] - q0[iq + 1], q1[iq + 2] - q0[iq + 2]);
                out[iv..iv + 3].copy_from_slice((r0.transpose() * dp).as_slice());
                let rel = quat_mul(&conj(&quat_of(&q0[iq + 3..])), &quat_of(&q1[iq + 3..]));
                out[iv + 3..iv + 6].copy_from_slice(quat_log(&rel).as_slice());
            }
            JointType::Planar => {
                let (s, c) = q0[iq + 2].sin_cos();
                let (dx, dy) = (q1[iq] - q0[iq], q1[iq + 1] - q0[iq + 1]);
                out[iv] = c * dx + s * dy;
                out[iv + 1] = -s * dx + c * dy;
                out[iv + 2] = q1[iq + 2] - q0[iq + 2];
            }
            JointType::Spherical => {
                let rel = quat_mul(&conj(&quat_of(&q0[iq..])), &quat_of(&q1[iq..]));
                out[iv..iv + 3].copy_from_slice(quat_log(&rel).as_slice());
            }
            _ => {
                for k in 0..m.nqs[i] {
                    out[iv + k] = q1[iq + k] - q0[iq + k];
                }
            }
        }
    }
}

/// Jacobians of `q ⊕ δ` (nv × nv each, local tangents at q and at q ⊕ δ): `jq = ∂(q ⊕ δ)/∂q`,
/// `jd = ∂(q ⊕ δ)/∂δ`. Block diagonal; for a free base, with E = Exp(δ_ang),
/// `jq = [[Eᵀ, −Eᵀ[δ_lin]×], [0, Eᵀ]]`, `jd = [[Eᵀ, 0], [0, Jr(δ_ang)]]`.
pub fn integrate_jacobians(
    m: &Model,
    q: &[f64],
    delta: &[f64],
    jq: &mut DMatrix<f64>,
    jd: &mut DMatrix<f64>,
) -> Result<()> {
    check_q(m, q)?;
    check_vec("delta", delta, m.nv)?;
    check_shape("jq", jq.nrows(), jq.ncols(), (m.nv, m.nv))?;
    check_shape("jd", jd.nrows(), jd.ncols(), (m.nv, m.nv))?;
    integrate_jacobians_unchecked(m, delta, Some(jq), Some(jd));
    Ok(())
}

/// Either Jacobian may be skipped. (They do not depend on q itself.)
pub(crate) fn integrate_jacobians_unchecked(
    m: &Model,
    delta: &[f64],
    mut jq: Option<&mut DMatrix<f64>>,
    mut jd: Option<&mut DMatrix<f64>>,
) {
    if let Some(j) = jq.as_deref_mut() {
        j.fill_with_identity();
    }
    if let Some(j) = jd.as_deref_mut() {
        j.fill_with_identity();
    }
    for i in 0..m.nbodies() {
        let iv = m.idx_v[i];
        match m.joint_types[i] {
            JointType::Free => {
                let dl = V3::new(delta[iv], delta[iv + 1], delta[iv + 2]);
                let da = V3::new(delta[iv + 3], delta[iv + 4], delta[iv + 5]);
                let et = so3_exp(&da).transpose();
                if let Some(j) = jq.as_deref_mut() {
                    set3(j, iv, iv, &et);
                    set3(j, iv, iv + 3, &(-et * skew(&dl)));
                    set3(j, iv + 3, iv + 3, &et);
                }
                if let Some(j) = jd.as_deref_mut() {
                    set3(j, iv, iv, &et);
                    set3(j, iv + 3, iv + 3, &so3_right_jacobian(&da));
                }
            }
            JointType::Planar => {
                let (s, c) = delta[iv + 2].sin_cos();
                let (dx, dy) = (delta[iv], delta[iv + 1]);
                // Eᵀ = R(δθ)ᵀ; the yaw column is Eᵀ J δ_xy with J = [[0, −1], [1, 0]].
                let (jx, jy) = (-dy, dx);
                for j in [jq.as_deref_mut(), jd.as_deref_mut()].into_iter().flatten() {
                    j[(iv, iv)] = c;
                    j[(iv, iv + 1)] = s;
                    j[(iv + 1, iv)] = -s;
                    j[(iv + 1, iv + 1)] = c;
                }
                if let Some(j) = jq.as_deref_mut() {
                    j[(iv, iv + 2)] = c * jx + s * jy;
                    j[(iv + 1, iv + 2)] = -s * jx + c * jy;
                }
            }
            JointType::Spherical => {
                let da = V3::new(delta[iv], delta[iv + 1], delta[iv + 2]);
                if let Some(j) = jq.as_deref_mut() {
                    set3(j, iv, iv, &so3_exp(&da).transpose());
                }
                if let Some(j) = jd.as_deref_mut() {
                    set3(j, iv, iv, &so3_right_jacobian(&da));
                }
            }
            _ => {}
        }
    }
}

/// Jacobians of `δ = q1 ⊖ q0` (nv × nv each, local tangents): `j0 = ∂δ/∂q0`, `j1 = ∂δ/∂q1`.
/// Free base, with E = Exp(δ_ang): `j0 = [[−I, [δ_lin]×], [0, −Jr(δ_ang)⁻ᵀ]]`,
/// `j1 = [[E, 0], [0, Jr(δ_ang)⁻¹]]`.
pub fn difference_jacobians(
    m: &Model,
    q0: &[f64],
    q1: &[f64],
    j0: &mut DMatrix<f64>,
    j1: &mut DMatrix<f64>,
    delta_buf: &mut [f64],
) -> Result<()> {
    check_q(m, q0).map_err(|e| rename(e, "q0"))?;
    check_q(m, q1).map_err(|e| rename(e, "q1"))?;
    check_shape("j0", j0.nrows(), j0.ncols(), (m.nv, m.nv))?;
    check_shape("j1", j1.nrows(), j1.ncols(), (m.nv, m.nv))?;
    check_len("delta_buf", delta_buf.len(), m.nv)?;
    difference_unchecked(m, q0, q1, delta_buf);
    let delta = &*delta_buf;
    j0.fill_with_identity();
    *j0 *= -1.0;
    j1.fill_with_identity();
    for i in 0..m.nbodies() {
        let iv = m.idx_v[i];
        match m.joint_types[i] {
            JointType::Free => {
                let dl = V3::new(delta[iv], delta[iv + 1], delta[iv + 2]);
                let da = V3::new(delta[iv + 3], delta[iv + 4], delta[iv + 5]);
                let ji = so3_right_jacobian_inv_matrix(&da);
                set3(j0, iv, iv + 3, &skew(&dl));
                set3(j0, iv + 3, iv + 3, &(-ji.transpose()));
                set3(j1, iv, iv, &so3_exp(&da));
                set3(j1, iv + 3, iv + 3, &ji);
            }
            JointType::Planar => {
                let (s, c) = delta[iv + 2].sin_cos();
                j0[(iv, iv + 2)] = delta[iv + 1];
                j0[(iv + 1, iv + 2)] = -delta[iv];
                j1[(iv, iv)] = c;
                j1[(iv, iv + 1)] = -s;
                j1[(iv + 1, iv)] = s;
                j1[(iv + 1, iv + 1)] = c;
            }
            JointType::Spherical => {
                let da = V3::new(delta[iv], delta[iv + 1], delta[iv + 2]);
                let ji = so3_right_jacobian_inv_matrix(&da);
                set3(j0, iv, iv, &(-ji.transpose()));
                set3(j1, iv, iv, &ji);
            }
            _ => {}
        }
    }
    Ok(())
}

/// RKMK tangent map at `q0 ⊕ δ`: the rate of δ for body velocity `v` (module `step`):
/// free base `[Exp(δ_ang) v_lin, Jr(δ_ang)⁻¹ ω]`, planar `[R(δθ) v_xy, ω]`, spherical `Jr(δ)⁻¹ ω`.
pub(crate) fn tangent_map(m: &Model, delta: &[f64], v: &[f64], out: &mut [f64]) {
    for i in 0..m.nbodies() {
        let iv = m.idx_v[i];
        match m.joint_types[i] {
            JointType::Free => {
                let da = V3::new(delta[iv + 3], delta[iv + 4], delta[iv + 5]);
                let l = so3_exp(&da) * V3::new(v[iv], v[iv + 1], v[iv + 2]);
                let a = so3_right_jacobian_inv_matrix(&da) * V3::new(v[iv + 3], v[iv + 4], v[iv + 5]);
                out[iv..iv + 3].copy_from_slice(l.as_slice());
                out[iv + 3..iv + 6].copy_from_slice(a.as_slice());
            }
            JointType::Planar => {
                let (s, c) = delta[iv + 2].sin_cos();
                out[iv] = c * v[iv] - s * v[iv + 1];
                out[iv + 1] = s * v[iv] + c * v[iv + 1];
                out[iv + 2] = v[iv + 2];
            }
            JointType::Spherical => {
                let da = V3::new(delta[iv], delta[iv + 1], delta[iv + 2]);
                let a = so3_right_jacobian_inv_matrix(&da) * V3::new(v[iv], v[iv + 1], v[iv + 2]);
                out[iv..iv + 3].copy_from_slice(a.as_slice());
            }
            _ => out[iv..iv + m.nvs[i]].copy_from_slice(&v[iv..iv + m.nvs[i]]),
        }
    }
}

/// Jacobians of `tangent_map(δ, v)`: `td = ∂/∂δ`, `tv = ∂/∂v` (nv × nv, block diagonal).
pub(crate) fn tangent_map_jacobians(m: &Model, delta: &[f64], v: &[f64], td: &mut DMatrix<f64>, tv: &mut DMatrix<f64>) {
    td.fill(0.0);
    tv.fill_with_identity();
    for i in 0..m.nbodies() {
        let iv = m.idx_v[i];
        match m.joint_types[i] {
            JointType::Free => {
                let da = V3::new(delta[iv + 3], delta[iv + 4], delta[iv + 5]);
                let vl = V3::new(v[iv], v[iv + 1], v[iv + 2]);
                let w = V3::new(v[iv + 3], v[iv + 4], v[iv + 5]);
                let e = so3_exp(&da);
                // d/dθ (Exp(θ) v) = −Exp(θ) [v]× Jr(θ)
                set3(td, iv, iv + 3, &(-e * skew(&vl) * so3_right_jacobian(&da)));
                set3(td, iv + 3, iv + 3, &so3_right_jacobian_inv_dtheta(&da, &w));
                set3(tv, iv, iv, &e);
                set3(tv, iv + 3, iv + 3, &so3_right_jacobian_inv_matrix(&da));
            }
            JointType::Planar => {
                let (s, c) = delta[iv + 2].sin_cos();
                let (x, y) = (v[iv], v[iv + 1]);
                td[(iv, iv + 2)] = -s * x - c * y;
                td[(iv + 1, iv + 2)] = c * x - s * y;
                tv[(iv, iv)] = c;
                tv[(iv, iv + 1)] = -s;
                tv[(iv + 1, iv)] = s;
                tv[(iv + 1, iv + 1)] = c;
            }
            JointType::Spherical => {
                let da = V3::new(delta[iv], delta[iv + 1], delta[iv + 2]);
                let w = V3::new(v[iv], v[iv + 1], v[iv + 2]);
                set3(td, iv, iv, &so3_right_jacobian_inv_dtheta(&da, &w));
                set3(tv, iv, iv, &so3_right_jacobian_inv_matrix(&da));
            }
            _ => {}
        }
    }
}
