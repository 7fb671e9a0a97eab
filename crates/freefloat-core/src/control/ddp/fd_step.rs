//! The test oracle of `step_jacobians` (the solver uses the analytic ones): central finite differences of
//! the robot's step in the tangent error state,
//! `Fx e_i ≈ [(F(x ⊕ h eᵢ, u) ⊖ F(x, u)) − (F(x ⊕ −h eᵢ, u) ⊖ F(x, u))] / 2h`, same for u.
//! Cost: 2 (ndx + nu) steps per node, which is why the robot's iterations are slow.

use super::robot::FloatingRobot;
use crate::error::Result;
use nalgebra::DMatrix;

/// Step of the central differences (≈ ε^(1/3) for the rounding/truncation balance).
const H: f64 = 1e-6;

impl FloatingRobot {
    /// `fx` (ndx × ndx) and `fu` (ndx × nu) of the step at (x, u) by central differences (the oracle of `step_jacobians`).
    pub fn fd_step_jacobians(
        &mut self,
        x: &[f64],
        u: &[f64],
        fx: &mut DMatrix<f64>,
        fu: &mut DMatrix<f64>,
    ) -> Result<()> {
        use super::problem::ActionModel;
        let ndx = self.ndx();
        let nu = self.nu();
        let mut xnom = std::mem::take(&mut self.xnom);
        let mut xp = std::mem::take(&mut self.xbuf);
        let mut xn = std::mem::take(&mut self.xbuf2);
        let mut dx = std::mem::take(&mut self.dxbuf2);
        let mut ub = std::mem::take(&mut self.ubuf);
        let mut tangent = std::mem::take(&mut self.tbuf);
        let mut run = || -> Result<()> {
            self.step(x, u, &mut xnom)?;
            for i in 0..ndx {
                for (sgn, col) in [(1.0, 0usize), (-1.0, 1)] {
                    tangent.fill(0.0);
                    tangent[i] = sgn * H;
                    self.integrate(x, &tangent, &mut xp);
                    self.step(&xp, u, &mut xn)?;
                    self.difference(&xnom, &xn, &mut dx);
                    for r in 0..ndx {
                        if col == 0 {
                            fx[(r, i)] = dx[r];
                        } else {
                            fx[(r, i)] = (fx[(r, i)] - dx[r]) / (2.0 * H);
                        }
                    }
                }
            }
            for j in 0..nu {
                for (sgn, col) in [(1.0, 0usize), (-1.0, 1)] {
                    ub.copy_from_slice(u);
                    ub[j] += sgn * H;
                    self.step(x, &ub, &mut xn)?;
                    self.difference(&xnom, &xn, &mut dx);
                    for r in 0..ndx {
                        if col == 0 {
                            fu[(r, j)] = dx[r];
                        } else {
                            fu[(r, j)] = (fu[(r, j)] - dx[r]) / (2.0 * H);
                        }
                    }
                }
            }
            Ok(())
        };
        let out = run();
        self.xnom = xnom;
        self.xbuf = xp;
        self.xbuf2 = xn;
        self.dxbuf2 = dx;
        self.ubuf = ub;
        self.tbuf = tangent;
        out
    }
}
