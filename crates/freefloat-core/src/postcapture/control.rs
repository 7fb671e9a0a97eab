//! The paper's controllers (Zhang, Yue, Yuan 2020, eqs. 39-40) as a generalized-force law for the whole robot.

use crate::data::Data;
use crate::dynamics::{crba_unchecked, rnea_unchecked};
use crate::error::{FfError, Result};
use crate::kinematics::{center_of_mass_from_placements, forward_velocities_unchecked, momentum_from_data_unchecked};
use crate::model::{JointType, Model};
use crate::spatial::{rot_from_quat, so3_log, M3, V3};
use nalgebra::{DMatrix, DVector};

/// Zhang 2020, eq. (40) per component: `−max` if `K x ≤ −max`, `K x` in between, `+max` above.
/// The paper writes it with thresholds on x (`P_max`, `L_max`); with its numbers
/// (|K| x_max = max) both are the same law. For the velocity sweep (F_max = 0.1 N, P_max unchanged)
/// the printed thresholds would make the law jump from 0.1 N to 10 N at |P| = 10; the clip is the
/// continuous reading (docs/postcapture.md, "Corrections to the printed paper").
#[inline]
pub fn saturate(gain: f64, x: f64, max: f64) -> f64 {
    (gain * x).clamp(-max, max)
}

/// Gains and the arm's excitation.
#[derive(Debug, Clone)]
pub struct PostcaptureControl {
    /// eq. (40): thrust `F = clip(K_F P, ±F_max)` per inertial axis, P = total linear momentum
    pub f_max: f64,
    /// Gain K_F of the thrust law, eq. (40).
    pub k_f: f64,
    /// eq. (40): couple `M = clip(K_M L_G, ±M_max)` per inertial axis, L_G = angular momentum about
    /// the system CoM (the paper does not say about which point; our choice is the CoM, so that
    /// translation does not feed the couple)
    pub m_max: f64,
    /// Gain K_M of the couple law, eq. (40).
    pub k_m: f64,
    /// eq. (39): base angular acceleration `−K_D ω − K_P φ` per axis of the base frame (φ: yaw in 2D,
    /// rotation vector in 3D; the paper's gains are diagonal, its 3D values are not printed)
    pub k_d: V3,
    /// Attitude gains K_P, eq. (39).
    pub k_p: V3,
    /// thruster point in the base frame (r'_jet, eq. 15); the thrust's moment about the base origin
    /// is `r'_jet × f`
    pub jet: V3,
    /// null-space motion of the arm: `−damping q̇ + amp sin(freq t + phase)` per arm joint
    pub damping: f64,
    /// Excitation amplitudes per arm joint (rad/s²).
    pub amp: Vec<f64>,
    /// Excitation angular frequencies per arm joint (rad/s).
    pub freq: Vec<f64>,
    /// Excitation phases per arm joint (rad).
    pub phase: Vec<f64>,
}

/// Work buffers and the base layout of one model.
pub(crate) struct Controller {
    pub ctl: PostcaptureControl,
    d: Data,
    /// 3 (planar) or 6 (free)
    nb: usize,
    planar: bool,
}

impl Controller {
    pub fn new(m: &Model, ctl: PostcaptureControl) -> Result<Self> {
        let planar = match m.joint_types.first() {
            Some(JointType::Planar) => true,
            Some(JointType::Free) => false,
            _ => return Err(FfError::arg("model", "the post-capture scenario needs a planar or free base")),
        };
        let nb = if planar { 3 } else { 6 };
        let nj = m.nv - nb;
        if nj == 0 {
            return Err(FfError::arg("model", "no arm joints to stabilise the base attitude with"));
        }
        for (name, x) in
            [("excitation_amp", &ctl.amp), ("excitation_freq", &ctl.freq), ("excitation_phase", &ctl.phase)]
        {
            if x.len() != nj {
                return Err(FfError::arg(name, format!("expected {nj} entries (one per arm joint), got {}", x.len())));
            }
            if x.iter().any(|v| !v.is_finite()) {
                return Err(FfError::arg(name, "entries must be finite"));
            }
        }
        for (name, x) in [("f_max", ctl.f_max), ("m_max", ctl.m_max)] {
            if !(x >= 0.0) || !x.is_finite() {
                return Err(FfError::arg(name, format!("must be finite and ≥ 0, got {x}")));
            }
        }
        if ctl.k_d.iter().chain(ctl.k_p.iter()).any(|g| !g.is_finite()) {
            return Err(FfError::arg("k_d/k_p", "attitude gains must be finite"));
        }
        for (name, x) in [("k_f", ctl.k_f), ("k_m", ctl.k_m), ("damping", ctl.damping)] {
            if !x.is_finite() {
                return Err(FfError::arg(name, format!("must be finite, got {x}")));
            }
        }
        if ctl.jet.iter().any(|v| !v.is_finite()) || (planar && ctl.jet.z != 0.0) {
            return Err(FfError::arg("jet", "thruster point must be finite (and in the plane for a planar base)"));
        }
        Ok(Controller { ctl, d: Data::new(m), nb, planar })
    }

    /// Base attitude (body → inertial) and its log: yaw about z in 2D, rotation vector in 3D.
    fn attitude(&self, q: &[f64]) -> (M3, V3) {
        if self.planar {
            let (s, c) = q[2].sin_cos();
            (M3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0), V3::new(0.0, 0.0, q[2]))
        } else {
            let r = rot_from_quat(&q[3..7]);
            (r, so3_log(&r))
        }
    }

    /// Thruster wrench in the inertial frame, eq. (40): (F, M).
    pub fn thrust(&mut self, m: &Model, q: &[f64], v: &[f64]) -> Result<(V3, V3)> {
        crate::check::check_args(m, Some(&self.d), &crate::check::Args::qv(q, v))?;
        forward_velocities_unchecked(m, &mut self.d, q, v);
        let h = momentum_from_data_unchecked(m, &self.d);
        let c = center_of_mass_from_placements(m, &self.d);
        let lg = h.ang - c.cross(&h.lin);
        let c = &self.ctl;
        let mut f = V3::from_fn(|i, _| saturate(c.k_f, h.lin[i], c.f_max));
        let mut mm = V3::from_fn(|i, _| saturate(c.k_m, lg[i], c.m_max));
        if self.planar {
            f.z = 0.0;
            mm.x = 0.0;
            mm.y = 0.0;
        }
        Ok((f, mm))
    }

    /// Generalized forces: base entries = thruster wrench in the base frame about the base origin;
    /// arm entries = the joint torques that give the joint accelerations solving eq. (39).
    pub fn generalized_forces(&mut self, m: &Model, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<()> {
        let (nb, nv) = (self.nb, m.nv);
        let nj = nv - nb;
        crate::check::check_len("out", out.len(), nv)?;
        let (f_in, m_in) = self.thrust(m, q, v)?; // checks q and v first
        let (rot, phi) = self.attitude(q);
        let fb = rot.transpose() * f_in;
        let tb = rot.transpose() * m_in + self.ctl.jet.cross(&fb);
        let mut wrench = DVector::zeros(nb);
        if self.planar {
            wrench[0] = fb.x;
            wrench[1] = fb.y;
            wrench[2] = tb.z;
        } else {
            for k in 0..3 {
                wrench[k] = fb[k];
                wrench[3 + k] = tb[k];
            }
        }
        // Equations of motion M v̇ + c = τ, split into base (b) and arm (j) rows.
        // q and v were checked by `thrust`: the unchecked cores
        crba_unchecked(m, &mut self.d, q);
        let mass = self.d.mass_matrix.clone();
        let zeros = vec![0.0; nv];
        rnea_unchecked(m, &mut self.d, q, v, &zeros, None);
        let bias = DVector::from_column_slice(&self.d.tau);
        let mbb = mass.view((0, 0), (nb, nb)).into_owned();
        let mbj = mass.view((0, nb), (nb, nj)).into_owned();
        let chol = mbb.cholesky().ok_or_else(|| {
            FfError::Numerical(format!("base block of the mass matrix not positive definite at t = {t}"))
        })?;
        // a_b = z − X q̈ with X = M_bb⁻¹ M_bj, z = M_bb⁻¹ (w − c_b)
        let x = chol.solve(&mbj);
        let z = chol.solve(&(wrench - bias.rows(0, nb)));
        // Eq. (39): angular rows of a_b = α.
        let ang: Vec<usize> = if self.planar { vec![2] } else { vec![3, 4, 5] };
        let w_body = if self.planar { V3::new(0.0, 0.0, v[2]) } else { V3::new(v[3], v[4], v[5]) };
        let alpha = -self.ctl.k_d.component_mul(&w_body) - self.ctl.k_p.component_mul(&phi);
        let k = ang.len();
        let cm = DMatrix::from_fn(k, nj, |r, c| x[(ang[r], c)]);
        let dv = DVector::from_fn(k, |r, _| z[ang[r]] - if self.planar { alpha.z } else { alpha[r] });
        let cct = &cm * cm.transpose();
        let scale = cct.amax().max(f64::MIN_POSITIVE);
        let cchol = cct.clone().cholesky().filter(|c| {
            let dmin = c.l_dirty().diagonal().iter().fold(f64::INFINITY, |a, &b| a.min(b));
            dmin * dmin > 1e-10 * scale
        });
        let cchol = cchol.ok_or_else(|| {
            FfError::Numerical(format!(
                "the arm cannot realise the base attitude law at t = {t}: its reaction on the base rotation is \
                 rank deficient (singular configuration)"
            ))
        })?;
        // q̈ = C⁺ d + (I − C⁺C) e, C⁺ = Cᵀ (CCᵀ)⁻¹
        let c = &self.ctl;
        let e = DVector::from_fn(nj, |i, _| -c.damping * v[nb + i] + c.amp[i] * (c.freq[i] * t + c.phase[i]).sin());
        let corr = cm.transpose() * cchol.solve(&(dv - &cm * &e));
        let qdd = e + corr;
        let ab = z - &x * &qdd;
        // τ_j = M_jb a_b + M_jj q̈ + c_j
        let tj = mass.view((nb, 0), (nj, nb)) * &ab + mass.view((nb, nb), (nj, nj)) * &qdd + bias.rows(nb, nj);
        for i in 0..nb {
            out[i] = if self.planar {
                [fb.x, fb.y, tb.z][i]
            } else if i < 3 {
                fb[i]
            } else {
                tb[i - 3]
            };
        }
        out[nb..].copy_from_slice(tj.as_slice());
        Ok(())
    }
}
