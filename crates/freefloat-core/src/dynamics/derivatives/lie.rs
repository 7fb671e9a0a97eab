//! `⊕` (integrate) and `⊖` (difference) on the configuration space and their Jacobians, in the local
//! tangent of the module documentation; SO(3) Jacobians used by them and by the RK4 derivatives.

use crate::check::{check_len, check_q, check_shape, check_vec};
use crate::error::Result;
use crate::model::{JointType, Model};
use crate::spatial::{quat_exp, quat_mul, quat_normalize, rot_from_quat, skew, M3, V3};
use nalgebra::DMatrix;

// ---------------------------------------------------------------- SO(3) helpers

/// Rotation matrix `Exp(θ)` (Rodrigues).
#[inline]
pub(crate) fn so3_exp(th: &V3) -> M3 {
    rot_from_quat(&quat_exp(th))
}

/// Right Jacobian of SO(3): `Exp(θ + η) ≈ Exp(θ) Exp(Jr(θ) η)`;
/// `Jr = I − (1 − cos t)/t² [θ] + (t − sin t)/t³ [θ]²` (Barfoot, State Estimation, eq. 7.77 with θ → −θ).
#[inline]
pub(crate) fn so3_jr(th: &V3) -> M3 {
    let t2 = th.norm_squared();
    let (a, b) = if t2 < 1e-4 {
        (0.5 - t2 / 24.0 + t2 * t2 / 720.0, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0)
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    let k = skew(th);
    M3::identity() - k * a + k * k * b
}

/// Coefficient of `[θ]²` in Jr⁻¹: `1/t² − (1 + cos t)/(2 t sin t)`, and its derivative divided by t.
#[inline]
fn jrinv_coeffs(t2: f64) -> (f64, f64) {
    if t2 < 1e-2 {
        // 1/t² − cot(t/2)/(2t) = 1/12 + t²/720 + t⁴/30240 + t⁶/1209600 + …
        (
            1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0 + t2 * t2 * t2 / 1_209_600.0,
            1.0 / 360.0 + t2 / 7560.0 + t2 * t2 / 201_600.0,
        )
    } else {
        let t = t2.sqrt();
        let (s, c) = (0.5 * t).sin_cos();
        let cot = c / s;
        let c2 = 1.0 / t2 - cot / (2.0 * t);
        // c2'(t) = −2/t³ + csc²(t/2)/(4t) + cot(t/2)/(2t²)
        let dc2 = -2.0 / (t2 * t) + 1.0 / (4.0 * t * s * s) + cot / (2.0 * t2);
        (c2, dc2 / t)
    }
}

/// Inverse right Jacobian `Jr(θ)⁻¹ = I + ½[θ] + c₂(t)[θ]²`.
#[inline]
pub(crate) fn so3_jr_inv(th: &V3) -> M3 {
    let (c2, _) = jrinv_coeffs(th.norm_squared());
    let k = skew(th);
    M3::identity() + k * 0.5 + k * k * c2
}

/// `∂/∂θ (Jr(θ)⁻¹ w)` (3×3): `−½[w] + c₂ ((θ·w)I + θwᵀ − 2wθᵀ) + (θ×(θ×w)) (c₂'/t) θᵀ`.
#[inline]
pub(crate) fn so3_jr_inv_dtheta(th: &V3, w: &V3) -> M3 {
    let (c2, dc2_t) = jrinv_coeffs(th.norm_squared());
    let ttw = th.cross(&th.cross(w));
    -skew(w) * 0.5
        + (M3::identity() * th.dot(w) + th * w.transpose() - w * th.transpose() * 2.0) * c2
        + ttw * th.transpose() * dc2_t
}

/// Rotation vector of a unit quaternion (x, y, z, w), angle in [0, π].
#[inline]
pub(crate) fn quat_log(q: &[f64; 4]) -> V3 {
    let sign = if q[3] < 0.0 { -1.0 } else { 1.0 };
    let v = V3::new(q[0], q[1], q[2]) * sign;
    let w = q[3] * sign;
    let s = v.norm();
    // θ/s with θ = 2 atan2(s, w); 2/w (1 − s²/(3w²)) near s = 0
    let k = if s < 1e-8 { 2.0 / w } else { 2.0 * s.atan2(w) / s };
    v * k
}

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
    for i in 0..m.nbodies() {
        let (iq, iv) = (m.idx_q[i], m.idx_v[i]);
        match m.joint_types[i] {
            JointType::Free => {
                let r = rot_from_quat(&q[iq + 3..iq + 7]);
                let p = V3::new(q[iq], q[iq + 1], q[iq + 2]) + r * V3::new(delta[iv], delta[iv + 1], delta[iv + 2]);
                out[iq..iq + 3].copy_from_slice(p.as_slice());
                rotate(&q[iq + 3..iq + 7], &delta[iv + 3..iv + 6], &mut out[iq + 3..iq + 7]);
            }
            JointType::Planar => {
                let (s, c) = q[iq + 2].sin_cos();
                let (dx, dy) = (delta[iv], delta[iv + 1]);
                out[iq] = q[iq] + c * dx - s * dy;
                out[iq + 1] = q[iq + 1] + s * dx + c * dy;
                out[iq + 2] = q[iq + 2] + delta[iv + 2];
            }
            JointType::Spherical => rotate(&q[iq..iq + 4], &delta[iv..iv + 3], &mut out[iq..iq + 4]),
            _ => {
                for k in 0..m.nqs[i] {
                    out[iq + k] = q[iq + k] + delta[iv + k];
                }
            }
        }
    }
}

fn rotate(q0: &[f64], phi: &[f64], out: &mut [f64]) {
    let mut r = quat_mul(&quat_of(q0), &quat_exp(&V3::new(phi[0], phi[1], phi[2])));
    quat_normalize(&mut r);
    out.copy_from_slice(&r);
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
                    set3(j, iv + 3, iv + 3, &so3_jr(&da));
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
                    set3(j, iv, iv, &so3_jr(&da));
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
                let ji = so3_jr_inv(&da);
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
                let ji = so3_jr_inv(&da);
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
                let a = so3_jr_inv(&da) * V3::new(v[iv + 3], v[iv + 4], v[iv + 5]);
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
                let a = so3_jr_inv(&da) * V3::new(v[iv], v[iv + 1], v[iv + 2]);
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
                set3(td, iv, iv + 3, &(-e * skew(&vl) * so3_jr(&da)));
                set3(td, iv + 3, iv + 3, &so3_jr_inv_dtheta(&da, &w));
                set3(tv, iv, iv, &e);
                set3(tv, iv + 3, iv + 3, &so3_jr_inv(&da));
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
                set3(td, iv, iv, &so3_jr_inv_dtheta(&da, &w));
                set3(tv, iv, iv, &so3_jr_inv(&da));
            }
            _ => {}
        }
    }
}
