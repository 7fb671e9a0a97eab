//! Second-order terms of the robot's step for full DDP (Valverde 2018, eqs. (8.39)–(8.44)): the Hessian of
//! `φ(δx, δu) = λᵀ [F(x ⊕ δx, u + δu) ⊖ F(x, u)]` at zero, where λ is the value gradient of the next node.
//!
//! It is the central difference of the analytic gradient `[Fx Fu]ᵀ λ` (`step_jacobians`), column by column:
//! 2 (ndx + nu) evaluations of the analytic Jacobians per node, truncation error O(h²), then symmetrised.
//!
//! Why `[Fx Fu]ᵀ λ` at the perturbed point is enough although its Jacobians live in the tangent spaces of the
//! perturbed state and of its successor, not of the nominal ones: moving them there multiplies by `Jr(δx)` on the
//! input side and by `Jr(e)⁻¹` on the output side (free base on SE(3)), both `I ∓ ½ ad(·) + O(h²)`. Their first-order
//! parts add to the difference quotient terms of the form `½ λᵀ [a_i, a_j]` (Lie brackets of two perturbation
//! directions), which are antisymmetric in (i, j) and vanish from the symmetric part. The unit test checks the
//! result against four-point second differences of φ computed from the step and ⊕/⊖ alone.
//!
//! The engine has no exact second derivatives of ABA; this is the one place where a difference quotient feeds
//! the solver, and only in its optional full-DDP mode (iLQG, the default, uses the analytic Jacobians alone).

use super::problem::{ActionModel, DynamicsHessian};
use super::robot::FloatingRobot;
use super::workspace::HessianWork;
use crate::error::{FfError, Result};

/// Step of the central differences of the analytic gradient (≈ ε^(1/3)).
const H: f64 = 6e-6;

impl FloatingRobot {
    /// `g = [Fx Fu]ᵀ λ` (λ in `w.lambda`) at (x ⊕ δx, u + δu), the perturbation `w.dz` = [δx; δu].
    fn perturbed_gradient(&mut self, w: &mut HessianWork, x: &[f64], u: &[f64], plus: bool) -> Result<()> {
        let (nv, ndx) = (self.model.nv, 2 * self.model.nv);
        self.integrate(x, &w.dz[..ndx], &mut w.xp);
        for i in 0..nv {
            w.up[i] = u[i] + w.dz[ndx + i];
        }
        self.step_jacobians(&w.xp, &w.up, &mut w.fx, &mut w.fu)?;
        let g = if plus { &mut w.g_plus } else { &mut w.g_minus };
        g.rows_mut(0, ndx).gemv_tr(1.0, &w.fx, &w.lambda, 0.0);
        g.rows_mut(ndx, nv).gemv_tr(1.0, &w.fu, &w.lambda, 0.0);
        Ok(())
    }

    /// The full-DDP terms at node (x, u) contracted with `lambda` (ndx), into `out`.
    pub fn step_hessian(&mut self, x: &[f64], u: &[f64], lambda: &[f64], out: &mut DynamicsHessian) -> Result<()> {
        let (ndx, nu) = (self.ndx(), self.nu());
        let mut w = self.hess.take().unwrap_or_else(|| HessianWork::new(self.nx(), ndx, nu));
        w.lambda.as_mut_slice().copy_from_slice(lambda);
        let r = (|| -> Result<()> {
            for j in 0..ndx + nu {
                w.dz.fill(0.0);
                w.dz[j] = H;
                self.perturbed_gradient(&mut w, x, u, true)?;
                w.dz[j] = -H;
                self.perturbed_gradient(&mut w, x, u, false)?;
                for i in 0..ndx + nu {
                    w.h[(i, j)] = (w.g_plus[i] - w.g_minus[i]) / (2.0 * H);
                }
            }
            // symmetrise (the difference quotient is symmetric only to O(h²))
            for j in 0..ndx + nu {
                for i in 0..j {
                    let s = 0.5 * (w.h[(i, j)] + w.h[(j, i)]);
                    w.h[(i, j)] = s;
                    w.h[(j, i)] = s;
                }
            }
            out.hxx.copy_from(&w.h.view((0, 0), (ndx, ndx)));
            out.huu.copy_from(&w.h.view((ndx, ndx), (nu, nu)));
            out.hux.copy_from(&w.h.view((ndx, 0), (nu, ndx)));
            if !w.h.iter().all(|v| v.is_finite()) {
                return Err(FfError::Numerical("the second-order dynamics terms are not finite".into()));
            }
            Ok(())
        })();
        self.hess = Some(w);
        r
    }
}

#[cfg(test)]
mod tests {
    use crate::control::ddp::problem::{ActionModel, DynamicsHessian};
    use crate::control::ddp::robot::FloatingRobot;
    use crate::model::builtin;

    /// A generic state of the chapter 8 arm: base moved and turned, joints bent, everything moving.
    fn generic(robot: &FloatingRobot) -> (Vec<f64>, Vec<f64>) {
        let (nq, nv) = (robot.model().nq, robot.model().nv);
        let mut x = vec![0.0_f64; nq + nv];
        x[..6].copy_from_slice(&[0.3, -0.2, 0.1, 0.1, -0.2, 0.3]);
        let n = (x[3] * x[3] + x[4] * x[4] + x[5] * x[5]).sqrt();
        x[6] = (1.0 - n * n).sqrt();
        for i in 7..nq {
            x[i] = 0.3 * (i as f64).sin();
        }
        for i in 0..nv {
            x[nq + i] = 0.4 * (1.7 * i as f64).cos();
        }
        let u = (0..nv).map(|i| 2.0 * (0.9 * i as f64).sin()).collect();
        (x, u)
    }

    /// φ(δz) = λᵀ (F(x ⊕ δx, u + δu) ⊖ F(x, u)), evaluated from the step alone (no Jacobians).
    fn phi(robot: &mut FloatingRobot, x: &[f64], u: &[f64], lambda: &[f64], dz: &[f64]) -> f64 {
        let ndx = robot.ndx();
        let (mut xnom, mut xp, mut y, mut e) =
            (vec![0.0; x.len()], vec![0.0; x.len()], vec![0.0; x.len()], vec![0.0; ndx]);
        robot.step(x, u, &mut xnom).unwrap();
        robot.integrate(x, &dz[..ndx], &mut xp);
        let up: Vec<f64> = u.iter().zip(&dz[ndx..]).map(|(a, b)| a + b).collect();
        robot.step(&xp, &up, &mut y).unwrap();
        robot.difference(&xnom, &y, &mut e);
        e.iter().zip(lambda).map(|(a, b)| a * b).sum()
    }

    #[test]
    fn step_hessian_matches_second_differences_of_the_step() {
        let m = builtin::load("valverde_ch8_arm").unwrap();
        let mut robot = FloatingRobot::new(m, 0.05, 4, vec![], vec![], vec![]).unwrap();
        let (x, u) = generic(&robot);
        let (ndx, nu) = (robot.ndx(), robot.nu());
        let lambda: Vec<f64> = (0..ndx).map(|i| 1.0 + 0.5 * (2.3 * i as f64).sin()).collect();
        let mut out = DynamicsHessian::zeros(ndx, nu);
        robot.step_hessian(&x, &u, &lambda, &mut out).unwrap();
        // Oracle: the four-point second difference of φ, which uses nothing but the step and ⊕/⊖.
        let h = 1e-3; // rounding-limited below (φ is O(h), divided by h²); truncation O(h²) is smaller here
        let nz = ndx + nu;
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for i in 0..nz {
            for j in 0..=i {
                let mut f = [0.0; 4];
                for (c, (si, sj)) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)].iter().enumerate() {
                    let mut dz = vec![0.0; nz];
                    dz[i] += si * h;
                    dz[j] += sj * h;
                    f[c] = phi(&mut robot, &x, &u, &lambda, &dz);
                }
                let fd = (f[0] - f[1] - f[2] + f[3]) / (4.0 * h * h);
                let an = if i < ndx {
                    out.hxx[(i, j)]
                } else if j < ndx {
                    out.hux[(i - ndx, j)]
                } else {
                    out.huu[(i - ndx, j - ndx)]
                };
                worst = worst.max((an - fd).abs());
                scale = scale.max(fd.abs());
            }
        }
        assert!(scale > 1e-3, "the test state has no curvature to check ({scale:.2e})");
        if std::env::var("FF_SHOW").is_ok() {
            eprintln!("rel {:.2e}", worst / scale);
        }
        assert!(worst / scale < 1e-5, "step Hessian vs second differences: {:.2e} relative", worst / scale);
        // symmetric blocks
        assert!((&out.hxx - out.hxx.transpose()).amax() == 0.0);
        assert!((&out.huu - out.huu.transpose()).amax() == 0.0);
    }
}
