//! Forward kinematics in dual-quaternion form (Valverde 2018, Ch. 3): the chain product of relative poses
//! ((3.43)/(3.61)), the product of exponentials (3.19) and standard Denavit–Hartenberg ((3.20)–(3.29) with
//! the ½ that the printed (3.20)–(3.21) drop restored; (3.26) has it). Both model-based routines reproduce the engine's
//! `kinematics::forward_kinematics` (tests/dualquat_kinematics.rs).

use super::dual_quaternion::DualQuat;
use super::pose::{rotation, translation};
use super::quaternion::Quat;
use super::screw::{screw_exp, screw_log};
use crate::error::{FfError, Result};
use crate::model::{JointType, Model};
use crate::spatial::V3;

/// Relative pose of a joint's child frame in its rest frame, `q_{i/i0}(Γ)` (the thesis uses it in §6.2 but never writes
/// it out; per joint type it is the rotation and/or translation of the joint coordinates along/about the joint axis),
/// for the engine's joint coordinates `q` (length nq). Quaternions are used as given (normalise them first). `axis2` is
/// a universal joint's second axis (ignored by the other joints).
pub fn joint_pose(kind: JointType, axis: &V3, axis2: &V3, q: &[f64]) -> Result<DualQuat> {
    if q.len() != kind.nq() {
        return Err(FfError::arg(
            "q",
            format!("{} joint needs {} coordinates, got {}", kind.name(), kind.nq(), q.len()),
        ));
    }
    Ok(match kind {
        JointType::Revolute => rotation(&Quat::from_axis_angle(axis, q[0])),
        JointType::Prismatic => translation(&(axis * q[0])),
        // rotation and translation along one axis commute
        JointType::Cylindrical => translation(&(axis * q[1])).mul(&rotation(&Quat::from_axis_angle(axis, q[0]))),
        JointType::Spherical => rotation(&Quat::new(q[3], q[0], q[1], q[2])),
        JointType::Free => DualQuat::from_pose_xyzw(&[q[3], q[4], q[5], q[6]], &V3::new(q[0], q[1], q[2])),
        JointType::Planar => {
            translation(&V3::new(q[0], q[1], 0.0)).mul(&rotation(&Quat::from_axis_angle(&V3::z(), q[2])))
        }
        // R(a1, θ1) R(a2, θ2): the second rotation about the intermediate frame's axis
        JointType::Universal => rotation(&Quat::from_axis_angle(axis, q[0]).mul(&Quat::from_axis_angle(axis2, q[1]))),
        JointType::Fixed | JointType::FixedBase => DualQuat::ONE,
    })
}

/// Poses `q_{B_i/I}` of every body frame, as the chain product (3.43) `q_{i/I} = q_{p/I} q_{rest} q_{i/i0}(q)`.
/// Checks `q` (`check::check_q`) and normalises its quaternions.
pub fn body_poses(m: &Model, q: &[f64]) -> Result<Vec<DualQuat>> {
    let mut buf = Vec::new();
    let q = m.checked_q(q, &mut buf)?;
    let mut out: Vec<DualQuat> = Vec::with_capacity(m.nbodies());
    for i in 0..m.nbodies() {
        let qi = &q[m.idx_q[i]..m.idx_q[i] + m.nqs[i]];
        let local =
            DualQuat::from_se3(&m.placements[i]).mul(&joint_pose(m.joint_types[i], &m.axes[i], &m.axes2[i], qi)?);
        let pose = match m.parents[i] {
            Some(p) => out[p].mul(&local),
            None => local,
        };
        out.push(pose);
    }
    Ok(out)
}

/// Product of exponentials (3.19) for a model: the screws of every non-root joint taken at the home
/// configuration (`q` = neutral) in the root body's frame, so that
/// `q_{i/I} = q_{root/I}(q) · Π_{k ∈ path(i)} exp(½ θ̂_k ŝ_k) · q_{i/root,0}`.
#[derive(Clone, Debug)]
pub struct ProductOfExponentials {
    /// Home pose of each body relative to the root body (the root's own is 1).
    home: Vec<DualQuat>,
    /// Joint axis (unit, root-body coordinates at home) and the point of the joint origin at home.
    axes: Vec<V3>,
    points: Vec<V3>,
}

impl ProductOfExponentials {
    /// Revolute, prismatic, spherical, cylindrical, universal and fixed joints below a free, planar or fixed root.
    pub fn new(m: &Model) -> Result<ProductOfExponentials> {
        let n = m.nbodies();
        let mut home = vec![DualQuat::ONE; n];
        let mut axes = vec![V3::zeros(); n];
        let mut points = vec![V3::zeros(); n];
        for i in 0..n {
            let Some(p) = m.parents[i] else { continue };
            // At home every joint pose is 1, so the body sits at its rest placement.
            home[i] = home[p].mul(&DualQuat::from_se3(&m.placements[i]));
            axes[i] = home[i].r.rotate(&m.axes[i]);
            points[i] = home[i].translation();
        }
        Ok(ProductOfExponentials { home, axes, points })
    }

    /// The exponential factor of joint i for coordinates `qi`: a screw (3.10) about the home axis through
    /// the home joint origin. A spherical joint is a rotation about its own axis-angle (from `screw_log` of
    /// its quaternion) through the joint origin.
    fn factor(&self, m: &Model, i: usize, qi: &[f64]) -> Result<DualQuat> {
        let p = &self.points[i];
        Ok(match m.joint_types[i] {
            // m = p × ℓ (3.7), d = 0 for a revolute joint.
            JointType::Revolute => screw_exp(qi[0], 0.0, &self.axes[i], &p.cross(&self.axes[i])),
            // θ = 0: exp(½ d (0 + ε ℓ)), the thesis' prismatic dual angle 0 + ε d; the moment does not enter.
            JointType::Prismatic => screw_exp(0.0, qi[0], &self.axes[i], &V3::zeros()),
            // a general screw (3.10): rotation θ and translation d along the same line
            JointType::Cylindrical => screw_exp(qi[0], qi[1], &self.axes[i], &p.cross(&self.axes[i])),
            JointType::Spherical => {
                let s = screw_log(&rotation(&Quat::new(qi[3], qi[0], qi[1], qi[2])))?;
                let l = self.home[i].r.rotate(&s.l);
                screw_exp(s.theta, 0.0, &l, &p.cross(&l))
            }
            // two screws through the joint origin: a1 (home), then a2 — at home the intermediate frame is the
            // joint frame, so a2's home line is fixed too and (3.19)'s product applies factor by factor
            JointType::Universal => {
                let l2 = self.home[i].r.rotate(&m.axes2[i]);
                screw_exp(qi[0], 0.0, &self.axes[i], &p.cross(&self.axes[i])).mul(&screw_exp(
                    qi[1],
                    0.0,
                    &l2,
                    &p.cross(&l2),
                ))
            }
            JointType::Fixed => DualQuat::ONE,
            other => {
                return Err(FfError::Model(format!("joint type {} below the root is not supported", other.name())))
            }
        })
    }

    /// Poses of every body in the inertial frame.
    pub fn body_poses(&self, m: &Model, q: &[f64]) -> Result<Vec<DualQuat>> {
        let mut buf = Vec::new();
        let q = m.checked_q(q, &mut buf)?;
        if self.home.len() != m.nbodies() {
            return Err(FfError::arg("m", "is not the model this product of exponentials was built for"));
        }
        let n = m.nbodies();
        // prod[i] = product of the factors on the path root → i (root first, left multiplication order).
        let mut prod = vec![DualQuat::ONE; n];
        let mut out = vec![DualQuat::ONE; n];
        let mut root = DualQuat::ONE;
        for i in 0..n {
            let qi = &q[m.idx_q[i]..m.idx_q[i] + m.nqs[i]];
            match m.parents[i] {
                None => {
                    root = DualQuat::from_se3(&m.placements[i]).mul(&joint_pose(
                        m.joint_types[i],
                        &m.axes[i],
                        &m.axes2[i],
                        qi,
                    )?);
                    out[i] = root;
                }
                Some(p) => {
                    prod[i] = prod[p].mul(&self.factor(m, i, qi)?);
                    out[i] = root.mul(&prod[i]).mul(&self.home[i]);
                }
            }
        }
        Ok(out)
    }
}

/// Standard (distal) DH transform in closed form (3.26): `q_{i/i−1}` for `Trans_z(d) Rot_z(θ) Trans_x(a)
/// Rot_x(α)`.
pub fn dh(d: f64, theta: f64, a: f64, alpha: f64) -> DualQuat {
    let (sa, ca) = (0.5 * alpha).sin_cos();
    let (st, ct) = (0.5 * theta).sin_cos();
    DualQuat {
        r: Quat::new(ca * ct, sa * ct, sa * st, ca * st),
        d: Quat::new(
            -0.5 * a * sa * ct - 0.5 * d * ca * st,
            0.5 * a * ca * ct - 0.5 * d * sa * st,
            0.5 * a * ca * st + 0.5 * d * sa * ct,
            0.5 * d * ca * ct - 0.5 * a * sa * st,
        ),
    }
}

/// The same transform as the product of the four elementary motions (3.20)–(3.25), with the factor ½ the
/// printed (3.20)–(3.21) drop (they print `1 + ε r` for `1 + ε½ r`; without it they do not reproduce (3.26)).
pub fn dh_product(d: f64, theta: f64, a: f64, alpha: f64) -> DualQuat {
    translation(&V3::new(0.0, 0.0, d))
        .mul(&rotation(&Quat::from_axis_angle(&V3::z(), theta)))
        .mul(&translation(&V3::new(a, 0.0, 0.0)))
        .mul(&rotation(&Quat::from_axis_angle(&V3::x(), alpha)))
}

/// Remark 2 (3.29): `exp(½(θ + εd) ẑ) exp(½(α + εa) x̂)`.
pub fn dh_exp(d: f64, theta: f64, a: f64, alpha: f64) -> DualQuat {
    screw_exp(theta, d, &V3::z(), &V3::zeros()).mul(&screw_exp(alpha, a, &V3::x(), &V3::zeros()))
}

/// Pose of the last frame of a DH chain: `Π q_{i/i−1}` over rows `[d, θ, a, α]`.
pub fn dh_chain(rows: &[[f64; 4]]) -> DualQuat {
    rows.iter().fold(DualQuat::ONE, |acc, r| acc.mul(&dh(r[0], r[1], r[2], r[3])))
}

/// Body Jacobian of a serial chain in the form of (3.57)–(3.60) (corrected: the printed (3.55) misses a dot on its
/// third term and (3.57) has `q_{e/I}`, `q_{2/I}` where `q_{e/2}`, `q_{2/1}` are meant):
/// `ω^e_{e/I} = Σ_k Ad_{(q_{k+1/k} ⋯ q_{e/n})*} ξ_k α̇_k`. `rel = [q_{1/I}, q_{2/1}, …, q_{e/n}]` are the relative
/// poses (n + 1 of them) and `screws[k]` is joint k's unit twist ξ_k in the frame it moves (Table 3.1). Returns the n
/// columns (8-vectors, `[real; dual]`).
pub fn serial_body_jacobian(rel: &[DualQuat], screws: &[DualQuat]) -> Result<Vec<DualQuat>> {
    if rel.len() != screws.len() + 1 {
        return Err(FfError::arg(
            "rel",
            format!("needs {} poses for {} joints, got {}", screws.len() + 1, screws.len(), rel.len()),
        ));
    }
    let n = screws.len();
    let mut cols = vec![DualQuat::ZERO; n];
    let mut tail = DualQuat::ONE; // q_{k+1/k} ⋯ q_{e/n}
    for k in (0..n).rev() {
        tail = rel[k + 1].mul(&tail);
        cols[k] = tail.shift_in(&screws[k]);
    }
    Ok(cols)
}
