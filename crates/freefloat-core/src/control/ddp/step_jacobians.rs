//! Analytic Jacobians of the robot's semi-implicit Euler step in the tangent error state, from the engine's
//! forward-dynamics derivatives (`dynamics::derivatives::aba_derivatives`, Carpentier & Mansard style):
//!
//! `v⁺ = v + Δt a(q, v, u)`, `δ = Δt v⁺`, `q⁺ = q ⊕ δ` with the free base on SE(3) (`M⁺ = M exp6(δ_b)`, the group
//! Crocoddyl integrates on) and the scalar joints additive. Then
//!
//! ```text
//! ∂v⁺/∂q = Δt ∂a/∂q      ∂v⁺/∂v = I + Δt ∂a/∂v      ∂v⁺/∂u = Δt M⁻¹
//! ∂q⁺/∂x = J_q [I 0] + Δt J_δ ∂v⁺/∂x                  ∂q⁺/∂u = Δt J_δ ∂v⁺/∂u
//! ```
//!
//! where, for the base block, `J_q = Ad(exp6(δ_b))⁻¹` (moving the perturbation of M through exp6(δ_b)) and
//! `J_δ = Jr(δ_b)`, the right Jacobian of SE(3) (the inverse of `se3_right_jacobian_inv`); both are the
//! identity for scalar joints. The derivatives' tangent of q (base displacement and rotation vector in base
//! axes) agrees with the SE(3) local tangent to first order, which is all a Jacobian sees.

use super::robot::FloatingRobot;
use crate::dynamics::derivatives::aba_derivatives;
use crate::error::{FfError, Result};
use crate::model::JointType;
use crate::spatial::lie::{exp6, se3_right_jacobian_inv};
use crate::spatial::{skew, M6, V6};
use nalgebra::DMatrix;

impl FloatingRobot {
    /// `fx` (2nv × 2nv) and `fu` (2nv × nv) of the step at (x, u), every entry written; leaves the kinematics of q in `data` (as
    /// `step` does), which the cost derivatives read.
    pub fn step_jacobians(&mut self, x: &[f64], u: &[f64], fx: &mut DMatrix<f64>, fu: &mut DMatrix<f64>) -> Result<()> {
        let (nq, nv) = (self.model.nq, self.model.nv);
        let dt = self.dt;
        let (q, v) = x.split_at(nq);
        if let Some(rd) = self.rate.as_mut() {
            // Rate-driven tail (massless, `set_rate_driven`): the leading bodies' derivatives, which the tail does
            // not affect; the tail's velocity rows are v⁺_w = u_w.
            let nd = rd.model.nv;
            aba_derivatives(&rd.model, &mut rd.data, &mut rd.deriv, &q[..rd.model.nq], &v[..nd], &u[..nd], None)?;
            let w = &rd.deriv;
            for c in 0..nv {
                for r in 0..nv {
                    let (a, b, m) = if r < nd && c < nd {
                        (dt * w.da_dq[(r, c)], dt * w.da_dv[(r, c)], dt * w.minv[(r, c)])
                    } else {
                        (0.0, 0.0, if r == c { 1.0 } else { 0.0 })
                    };
                    fx[(nv + r, c)] = a;
                    fx[(nv + r, nv + c)] = b + if r == c && r < nd { 1.0 } else { 0.0 };
                    fu[(nv + r, c)] = m;
                }
            }
            for i in 0..nv {
                self.dq[i] = dt * if i < nd { v[i] + dt * w.ddq[i] } else { u[i] };
            }
            crate::kinematics::forward_kinematics(&self.model, &mut self.data, q)?;
        } else {
            aba_derivatives(&self.model, &mut self.data, &mut self.deriv, q, v, u, None)?;
            let w = &self.deriv;
            // velocity rows: fx[nv.., ..] = [Δt ∂a/∂q, I + Δt ∂a/∂v], fu[nv.., ..] = Δt M⁻¹
            for c in 0..nv {
                for r in 0..nv {
                    fx[(nv + r, c)] = dt * w.da_dq[(r, c)];
                    fx[(nv + r, nv + c)] = dt * w.da_dv[(r, c)] + if r == c { 1.0 } else { 0.0 };
                    fu[(nv + r, c)] = dt * w.minv[(r, c)];
                }
            }
            for i in 0..nv {
                self.dq[i] = dt * (v[i] + dt * w.ddq[i]);
            }
        }
        // configuration rows, joint by joint: fx[q_i, ..] = J_q,i [I 0]_i + Δt J_δ,i fx[v_i, ..]
        for b in 0..self.model.nbodies() {
            let iv = self.model.idx_v[b];
            match self.model.joint_types[b] {
                JointType::Free => {
                    let delta = V6::from_column_slice(&self.dq[iv..iv + 6]);
                    let e = exp6(&delta);
                    let rt = e.rot.transpose();
                    let mut jq = M6::zeros(); // Ad(E)⁻¹ for [linear; angular] twists
                    jq.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
                    jq.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
                    jq.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-(rt * skew(&e.trans))));
                    let jd = se3_right_jacobian_inv(&delta).try_inverse().ok_or_else(|| {
                        FfError::Numerical(
                            "the SE(3) right Jacobian of the base step is singular (a step of 2π)".into(),
                        )
                    })?;
                    for c in 0..2 * nv {
                        let mut col = V6::zeros();
                        for r in 0..6 {
                            col[r] = fx[(nv + iv + r, c)];
                        }
                        let mut out = dt * (jd * col);
                        if c >= iv && c < iv + 6 {
                            for r in 0..6 {
                                out[r] += jq[(r, c - iv)];
                            }
                        }
                        for r in 0..6 {
                            fx[(iv + r, c)] = out[r];
                        }
                    }
                    for c in 0..nv {
                        let mut col = V6::zeros();
                        for r in 0..6 {
                            col[r] = fu[(nv + iv + r, c)];
                        }
                        let out = dt * (jd * col);
                        for r in 0..6 {
                            fu[(iv + r, c)] = out[r];
                        }
                    }
                }
                JointType::FixedBase => {}
                _ => {
                    for k in 0..self.model.nvs[b] {
                        let r = iv + k;
                        for c in 0..2 * nv {
                            fx[(r, c)] = dt * fx[(nv + r, c)] + if c == r { 1.0 } else { 0.0 };
                        }
                        for c in 0..nv {
                            fu[(r, c)] = dt * fu[(nv + r, c)];
                        }
                    }
                }
            }
        }
        // `aba_derivatives` (or, with a rate-driven tail, `forward_kinematics`) left the kinematics of q in `data`:
        // the cost derivatives read them.
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::control::ddp::problem::ActionModel;
    use crate::control::ddp::robot::FloatingRobot;
    use crate::model::builtin;
    use nalgebra::DMatrix;

    #[test]
    fn analytic_step_jacobians_match_central_differences() {
        let m = builtin::load("valverde_ch8_arm").unwrap();
        let (nq, nv) = (m.nq, m.nv);
        let mut robot = FloatingRobot::new(m, 0.05, 4, vec![], vec![], vec![]).unwrap();
        let mut x = vec![0.0_f64; nq + nv];
        // a generic state: base moved and turned, joints bent, everything moving
        let qb = [0.3, -0.2, 0.1, 0.1, -0.2, 0.3, 0.0];
        x[..7].copy_from_slice(&qb);
        let n = (x[3] * x[3] + x[4] * x[4] + x[5] * x[5]).sqrt();
        x[6] = (1.0 - n * n).sqrt();
        for i in 7..nq {
            x[i] = 0.3 * (i as f64).sin();
        }
        for i in 0..nv {
            x[nq + i] = 0.2 * (1.7 * i as f64).cos();
        }
        let u: Vec<f64> = (0..nv).map(|i| 0.5 * (0.9 * i as f64).sin()).collect();
        let ndx = robot.ndx();
        let (mut fx, mut fu) = (DMatrix::zeros(ndx, ndx), DMatrix::zeros(ndx, nv));
        let (mut gx, mut gu) = (DMatrix::zeros(ndx, ndx), DMatrix::zeros(ndx, nv));
        robot.step_jacobians(&x, &u, &mut fx, &mut fu).unwrap();
        robot.fd_step_jacobians(&x, &u, &mut gx, &mut gu).unwrap();
        let ex = (&fx - &gx).amax() / gx.amax();
        let eu = (&fu - &gu).amax() / gu.amax();
        assert!(ex < 1e-6 && eu < 1e-6, "analytic vs central differences: Fx {ex:.2e}, Fu {eu:.2e}");

        // the thesis' massless wrist driven by its Euler-angle rates (the last three joints)
        robot.set_rate_driven(3).unwrap();
        robot.step_jacobians(&x, &u, &mut fx, &mut fu).unwrap();
        robot.fd_step_jacobians(&x, &u, &mut gx, &mut gu).unwrap();
        let ex = (&fx - &gx).amax() / gx.amax();
        let eu = (&fu - &gu).amax() / gu.amax();
        assert!(ex < 1e-6 && eu < 1e-6, "rate-driven wrist: Fx {ex:.2e}, Fu {eu:.2e}");
        // the wrist's rate controls move only the wrist's own angles and rates: q⁺_w = q_w + Δt u_w, v⁺_w = u_w
        for c in nv - 3..nv {
            for r in 0..ndx {
                let expect = if r == c {
                    robot.dt()
                } else if r == nv + c {
                    1.0
                } else {
                    0.0
                };
                assert!((gu[(r, c)] - expect).abs() < 1e-7, "Fu[{r}, {c}] = {} (expected {expect})", gu[(r, c)]);
            }
        }
    }
}
