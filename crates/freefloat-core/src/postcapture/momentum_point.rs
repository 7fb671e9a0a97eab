//! Angular momentum about the moving base point instead of the inertial origin: the momentum form of
//! Zhang, Yue, Yuan 2020 (eqs. (9)-(10), (16)-(19)) balances the angular momentum about the inertial origin O
//! against `∫ (M + x_F × F) dτ`. After capture the system drifts (kilometres in 100 s for the 3D scenario),
//! so `L_O` is dominated by `r_B × P`; with a measured (gyro-integrated) attitude the integrated base position
//! errs by centimetres, while the impulse side sees the true lever arm: the rows are inconsistent by
//! `δr_B × P`, which is what made the momentum form 24 % off at a gyro noise density of 1e-6 (docs/postcapture.md).
//!
//! About the base frame's origin B (velocity `v_B`, inertial): `L_B = L_O − r_B × P` and
//! `dL_B/dt = M_B − v_B × P` (`M_B` the external moment about B). Integrated from t₀:
//!
//! `L_B(t) − L_B(t₀) + ∫_{t₀}^{t} v_B × P dτ = ∫_{t₀}^{t} M_B dτ`,
//!
//! still linear in the standard parameters (`P = K_lin θ`, the momentum regressor's first three rows). The
//! transport term `∫ [v_B]× K_lin dτ` needs the states between the samples; it is integrated here on the
//! dense record the samples are read from (the telemetry frames, or the simulator's steps). Position never
//! enters, and an attitude error rotates `v_B` and `P` together, so to first order it cancels in `v_B × P`.

use crate::data::Data;
use crate::error::{FfError, Result};
use crate::model::Model;
use crate::regressors::momentum_regressor;
use crate::spatial::skew;
use nalgebra::{DMatrix, Matrix3xX};

use super::equations::PointMotion;

/// The transport term `∫_{t_0}^{t_s} [v_B]× K_lin dτ` (3 × 10·nbodies per output, row-major, outputs
/// stacked) at the dense-record indices `at` (non-decreasing), `t_0 = t[at[0]]`: B the frame origin of body
/// `point`, `K_lin` the momentum regressor's linear rows (`P = K_lin θ`). Simpson's rule on pairs of
/// intervals from `at[0]` (an odd offset adds a last trapezoid) when `t` is evenly spaced (to 1e-9
/// relative), the trapezoid otherwise.
pub fn momentum_transport(m: &Model, t: &[f64], q: &[f64], v: &[f64], at: &[usize], point: usize) -> Result<Vec<f64>> {
    let n = t.len();
    if q.len() != n * m.nq || v.len() != n * m.nv {
        return Err(FfError::arg(
            "q/v",
            format!("expected {n} frames × ({} q, {} v) numbers, got {} and {}", m.nq, m.nv, q.len(), v.len()),
        ));
    }
    if point >= m.nbodies() {
        return Err(FfError::arg("point", format!("body {point} of {}", m.nbodies())));
    }
    if let Some(k) = t.iter().position(|x| !x.is_finite()) {
        return Err(FfError::arg("t", format!("frame {k} is not finite")));
    }
    if let Some(k) = (1..n).find(|&k| t[k] <= t[k - 1]) {
        return Err(FfError::arg("t", format!("frame {k}: times must increase ({} after {})", t[k], t[k - 1])));
    }
    if let Some(k) = (0..at.len()).find(|&k| at[k] >= n || (k > 0 && at[k] < at[k - 1])) {
        return Err(FfError::arg(
            "at",
            format!("entry {k} = {}: indices must be non-decreasing and below the {n} frames", at[k]),
        ));
    }
    let w = 10 * m.nbodies();
    let mut out = Vec::with_capacity(at.len() * 3 * w);
    let Some(&start) = at.first() else { return Ok(out) };
    let stop = *at.last().unwrap_or(&start);
    let even = n < 3 || {
        let h = t[1] - t[0];
        (2..n).all(|k| ((t[k] - t[k - 1]) - h).abs() <= 1e-6 * h)
    };
    let mut d = Data::new(m);
    let mut buf = Vec::with_capacity(m.nq);
    let mut k6 = DMatrix::zeros(6, w);
    // integrand [v_B]× K_lin at frame k (3 × w, column-major in nalgebra)
    let mut integrand = |k: usize| -> Result<Matrix3xX<f64>> {
        let qk = m.checked_q(&q[k * m.nq..(k + 1) * m.nq], &mut buf).map_err(|e| frame(e, k))?;
        momentum_regressor(m, &mut d, qk, &v[k * m.nv..(k + 1) * m.nv], &mut k6).map_err(|e| frame(e, k))?;
        let vb = PointMotion::of_body(&d, point, false).v;
        Ok(skew(&vb) * k6.rows(0, 3))
    };
    let mut f_prev2: Option<Matrix3xX<f64>> = None; // the integrand two frames back, kept at odd offsets
    let mut f_prev = integrand(start)?;
    let mut even_sum = Matrix3xX::zeros(w); // ∫ from t[start] to the last even offset
    let mut odd_tail = Matrix3xX::zeros(w); // the last interval's trapezoid when at an odd offset
    let mut trap_sum = Matrix3xX::zeros(w);
    let mut j = 0;
    let mut emit = |k: usize, even_sum: &Matrix3xX<f64>, odd_tail: &Matrix3xX<f64>, trap: &Matrix3xX<f64>| {
        while j < at.len() && at[j] == k {
            let s = if even { even_sum + odd_tail } else { trap.clone() };
            // row-major 3 × w
            for r in 0..3 {
                out.extend((0..w).map(|c| s[(r, c)]));
            }
            j += 1;
        }
    };
    emit(start, &even_sum, &odd_tail, &trap_sum);
    for k in start + 1..=stop {
        let f = integrand(k)?;
        let h = t[k] - t[k - 1];
        trap_sum += (&f_prev + &f) * (0.5 * h);
        if (k - start) % 2 == 0 {
            // Simpson on [t[k−2], t[k]]: h/3 (f₀ + 4 f₁ + f₂)
            let f0 = f_prev2.take().expect("set at the odd offset before");
            even_sum += (f0 + &f_prev * 4.0 + &f) * (h / 3.0);
            odd_tail.fill(0.0);
        } else {
            f_prev2 = Some(f_prev.clone());
            odd_tail = (&f_prev + &f) * (0.5 * h);
        }
        emit(k, &even_sum, &odd_tail, &trap_sum);
        f_prev = f;
    }
    Ok(out)
}

fn frame(e: FfError, k: usize) -> FfError {
    match e {
        FfError::Argument { name, msg } => FfError::Argument { name, msg: format!("frame {k}: {msg}") },
        other => other,
    }
}
