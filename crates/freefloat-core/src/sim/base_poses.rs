//! Base poses from sampled base twists: the trapezoidal rule on the group, or with the twists' rates its
//! fourth-order (Hermite) correction. The one copy of this formula: the exciting-trajectory design
//! (`excitation::response`, the base response along a joint path) and the telemetry tools (pose reconstruction
//! from measured rates, Python `telemetry.integrate_poses`) use it.
//!
//! Free base, twists `[v; ω]` in the base frame at samples k = 0, 1, …, step `h_k = t_{k+1} − t_k`:
//! - attitude `Q_{k+1} = normalise(Q_k ⊗ exp(Ω_k))`, `Ω_k = h_k (ω_k + ω_{k+1}) / 2` (body-frame ω, right
//!   product);
//! - position `r_{k+1} = r_k + h_k (u_k + u_{k+1}) / 2`, `u_k = R_k v_k` the inertial velocity.
//!
//! Planar base, `[vx, vy, ω_z]` in the base frame: `ψ_{k+1} = ψ_k + h_k (ω_k + ω_{k+1}) / 2` and the
//! position as above with `R(ψ)`.
//!
//! Second order; it uses both samples of a step, which is what a sampled measurement gives. (Naveen, Shah,
//! Misra's Appendix C, eqs. 44-47, integrates Euler angles by explicit Euler; we keep the attitude on the group.)
//!
//! With the twists' time derivatives at the samples (`rates`), each step adds the endpoint (Euler-Maclaurin)
//! correction of the cubic Hermite interpolant, which makes it fourth order:
//! - `∫ x dt ≈ h (x_k + x_{k+1}) / 2 + h² (ẋ_k − ẋ_{k+1}) / 12` for the position (x = u, u̇ = R (ω × v + v̇))
//!   and the planar yaw;
//! - the attitude's Magnus exponent to fourth order, `Ω_k = h (ω_k + ω_{k+1}) / 2 + h² (ω̇_k − ω̇_{k+1}) / 12
//!   + h² (ω_k × ω_{k+1}) / 12` (Iserles, Munthe-Kaas, Nørsett, Zanna 2000, the second Magnus term for a
//!   linearly varying body rate; the sign is that of the right product `Q̇ = Q ⊗ ω/2`).
//!
//! `tests::hermite_correction_converges_at_fourth_order` checks the orders.

use crate::error::{FfError, Result};
use crate::spatial::{quat_exp, quat_mul, quat_normalize, rot_from_quat, V3};

/// The sample times: a uniform step, or the times themselves (uneven steps allowed, increasing).
#[derive(Clone, Copy, Debug)]
pub enum Steps<'a> {
    /// A uniform step (s).
    Uniform(f64),
    /// The sample times (s), increasing.
    Times(&'a [f64]),
}

impl Steps<'_> {
    fn check(&self, samples: usize) -> Result<()> {
        match self {
            Steps::Uniform(h) if !(*h > 0.0) || !h.is_finite() => {
                Err(FfError::arg("step", format!("must be positive and finite, got {h}")))
            }
            Steps::Uniform(_) => Ok(()),
            Steps::Times(t) => {
                if t.len() != samples {
                    return Err(FfError::arg(
                        "t",
                        format!("expected {samples} times (one per twist), got {}", t.len()),
                    ));
                }
                if let Some(k) = t.iter().position(|x| !x.is_finite()) {
                    return Err(FfError::arg("t", format!("entry {k} is {} (must be finite)", t[k])));
                }
                if let Some(k) = (1..t.len()).find(|&k| !(t[k] > t[k - 1])) {
                    return Err(FfError::arg(
                        "t",
                        format!("times must increase: t[{k}] = {} after {}", t[k], t[k - 1]),
                    ));
                }
                Ok(())
            }
        }
    }

    /// Length of the step from sample k − 1 to k.
    #[inline]
    fn step(&self, k: usize) -> f64 {
        match self {
            Steps::Uniform(h) => *h,
            Steps::Times(t) => t[k] - t[k - 1],
        }
    }
}

fn check_samples(twists: &[f64], width: usize, pose0: &[f64], nq: usize, out: &[f64]) -> Result<usize> {
    if twists.is_empty() || !twists.len().is_multiple_of(width) {
        return Err(FfError::arg("twists", format!("expected (samples × {width}) numbers, got {}", twists.len())));
    }
    if let Some(k) = twists.iter().position(|x| !x.is_finite()) {
        return Err(FfError::arg("twists", format!("sample {}, entry {} is not finite", k / width, k % width)));
    }
    crate::check::check_vec("pose0", pose0, nq)?;
    let n = twists.len() / width;
    if out.len() != n * nq {
        return Err(FfError::arg("out", format!("expected {} numbers ({n} × {nq}), got {}", n * nq, out.len())));
    }
    Ok(n)
}

fn check_rates(rates: Option<&[f64]>, len: usize, width: usize) -> Result<()> {
    let Some(d) = rates else { return Ok(()) };
    if d.len() != len {
        return Err(FfError::arg("rates", format!("expected {len} numbers (one per twist entry), got {}", d.len())));
    }
    if let Some(k) = d.iter().position(|x| !x.is_finite()) {
        return Err(FfError::arg("rates", format!("sample {}, entry {} is not finite", k / width, k % width)));
    }
    Ok(())
}

/// Free-base poses `out` (samples × 7: position, quaternion x y z w) from base-frame twists `twists`
/// (samples × 6: `[v; ω]`) starting at `pose0` (7: position, quaternion; its norm must be within 1e-6 of 1).
/// `rates` (samples × 6, the twists' time derivatives): the fourth-order correction (module docs).
pub fn integrate_base_poses(
    steps: Steps,
    twists: &[f64],
    rates: Option<&[f64]>,
    pose0: &[f64],
    out: &mut [f64],
) -> Result<()> {
    let n = check_samples(twists, 6, pose0, 7, out)?;
    steps.check(n)?;
    check_rates(rates, twists.len(), 6)?;
    let mut quat = [pose0[3], pose0[4], pose0[5], pose0[6]];
    let norm = quat.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > 1e-6 {
        return Err(FfError::arg(
            "pose0",
            format!("the quaternion (x y z w) has norm {norm:.6}; it must be a unit quaternion"),
        ));
    }
    quat_normalize(&mut quat);
    let v3 = |x: &[f64], k: usize, i: usize| V3::new(x[6 * k + i], x[6 * k + i + 1], x[6 * k + i + 2]);
    // the inertial velocity u = R v and, with rates, its derivative u̇ = R (ω × v + v̇) at sample k
    let inertial = |quat: &[f64; 4], k: usize| {
        let r = rot_from_quat(quat);
        let (v, w) = (v3(twists, k, 0), v3(twists, k, 3));
        (r * v, rates.map(|d| r * (w.cross(&v) + v3(d, k, 0))))
    };
    let mut pos = V3::new(pose0[0], pose0[1], pose0[2]);
    let (mut vel0, mut acc0) = inertial(&quat, 0);
    out[..3].copy_from_slice(pos.as_slice());
    out[3..7].copy_from_slice(&quat);
    for k in 1..n {
        let h = steps.step(k);
        let (wa, wb) = (v3(twists, k - 1, 3), v3(twists, k, 3));
        let mut w = (wa + wb) * (0.5 * h);
        if let Some(d) = rates {
            w += ((v3(d, k - 1, 3) - v3(d, k, 3)) + wa.cross(&wb)) * (h * h / 12.0);
        }
        quat = quat_mul(&quat, &quat_exp(&w));
        quat_normalize(&mut quat);
        let (vel, acc) = inertial(&quat, k);
        pos += (vel0 + vel) * (0.5 * h);
        if let (Some(a0), Some(a1)) = (acc0, acc) {
            pos += (a0 - a1) * (h * h / 12.0);
        }
        (vel0, acc0) = (vel, acc);
        out[7 * k..7 * k + 3].copy_from_slice(pos.as_slice());
        out[7 * k + 3..7 * k + 7].copy_from_slice(&quat);
    }
    Ok(())
}

/// Planar-base poses `out` (samples × 3: x, y, yaw) from base-frame rates `twists` (samples × 3:
/// vx, vy, yaw rate) starting at `pose0` (3). `rates` (samples × 3, their time derivatives): the
/// fourth-order correction (module docs).
pub fn integrate_planar_base_poses(
    steps: Steps,
    twists: &[f64],
    rates: Option<&[f64]>,
    pose0: &[f64],
    out: &mut [f64],
) -> Result<()> {
    let n = check_samples(twists, 3, pose0, 3, out)?;
    steps.check(n)?;
    check_rates(rates, twists.len(), 3)?;
    let world = |yaw: f64, t: [f64; 2]| {
        let (s, c) = yaw.sin_cos();
        [c * t[0] - s * t[1], s * t[0] + c * t[1]]
    };
    // inertial velocity and, with rates, its derivative R(ψ) (ω ẑ × v + v̇) at sample k
    let inertial = |yaw: f64, k: usize| {
        let t = &twists[3 * k..3 * k + 3];
        let acc = rates.map(|d| world(yaw, [d[3 * k] - t[2] * t[1], d[3 * k + 1] + t[2] * t[0]]));
        (world(yaw, [t[0], t[1]]), acc)
    };
    let (mut x, mut y, mut yaw) = (pose0[0], pose0[1], pose0[2]);
    let (mut vel0, mut acc0) = inertial(yaw, 0);
    out[..3].copy_from_slice(&[x, y, yaw]);
    for k in 1..n {
        let h = steps.step(k);
        let (a, b) = (&twists[3 * k - 3..3 * k], &twists[3 * k..3 * k + 3]);
        yaw += (a[2] + b[2]) * (0.5 * h);
        if let Some(d) = rates {
            yaw += (d[3 * k - 1] - d[3 * k + 2]) * (h * h / 12.0);
        }
        let (vel, acc) = inertial(yaw, k);
        x += (vel0[0] + vel[0]) * (0.5 * h);
        y += (vel0[1] + vel[1]) * (0.5 * h);
        if let (Some(a0), Some(a1)) = (acc0, acc) {
            x += (a0[0] - a1[0]) * (h * h / 12.0);
            y += (a0[1] - a1[1]) * (h * h / 12.0);
        }
        (vel0, acc0) = (vel, acc);
        out[3 * k..3 * k + 3].copy_from_slice(&[x, y, yaw]);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::{so3_log, M3};

    /// Constant body twist: the exact motion is R(t) = R0 exp(t ω), r(t) = r0 + R0 ∫ exp(s ω) v ds; the
    /// attitude of the trapezoidal rule is then exact (ω constant) and the position second order.
    #[test]
    fn constant_twist_converges_at_second_order() {
        let (v, w) = (V3::new(0.3, -0.2, 0.5), V3::new(0.4, 0.1, -0.7));
        let exact_pos = |t: f64| {
            // ∫0^t exp(s[ω]) v ds by fine Simpson quadrature
            let n = 20000;
            let h = t / n as f64;
            let f = |s: f64| rot_from_quat(&quat_exp(&(w * s))) * v;
            let mut acc = f(0.0) + f(t);
            for i in 1..n {
                acc += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
            }
            acc * (h / 3.0)
        };
        let t_end = 2.0;
        let target = exact_pos(t_end);
        let mut errs = vec![];
        for n in [41usize, 81] {
            let twists: Vec<f64> = (0..n).flat_map(|_| [v.x, v.y, v.z, w.x, w.y, w.z]).collect();
            let mut out = vec![0.0; 7 * n];
            integrate_base_poses(
                Steps::Uniform(t_end / (n - 1) as f64),
                &twists,
                None,
                &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
                &mut out,
            )
            .unwrap();
            let last = &out[7 * (n - 1)..];
            let r = rot_from_quat(&last[3..7]);
            let r_exact = rot_from_quat(&quat_exp(&(w * t_end)));
            assert!(so3_log(&(r_exact.transpose() * r)).norm() < 1e-13);
            errs.push((V3::new(last[0], last[1], last[2]) - target).norm());
        }
        let order = (errs[0] / errs[1]).log2();
        assert!((order - 2.0).abs() < 0.1, "observed order {order} (errors {errs:?})");
    }

    /// The reference: classical RK4 of `ẏ = f(t, y)` from 0 to `t_end` in 20,000 steps (error far below the rules').
    fn rk4<const N: usize>(f: impl Fn(f64, &[f64; N]) -> [f64; N], y0: [f64; N], t_end: f64) -> [f64; N] {
        let (m, mut y) = (20_000, y0);
        let h = t_end / m as f64;
        let add = |y: &[f64; N], k: &[f64; N], c: f64| std::array::from_fn::<f64, N, _>(|j| y[j] + c * k[j]);
        for i in 0..m {
            let t = i as f64 * h;
            let k1 = f(t, &y);
            let k2 = f(t + h / 2.0, &add(&y, &k1, h / 2.0));
            let k3 = f(t + h / 2.0, &add(&y, &k2, h / 2.0));
            let k4 = f(t + h, &add(&y, &k3, h));
            y = std::array::from_fn(|j| y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
        }
        y
    }

    /// A time-varying twist: the trapezoidal rule is second order, the Hermite correction fourth order, both
    /// against a fine RK4 integration of `Q̇ = Q ⊗ ω/2`, `ṙ = R v` (free base) and `ψ̇ = ω`, `ṙ = R(ψ) v`
    /// (planar), written here without the rule.
    #[test]
    fn hermite_correction_converges_at_fourth_order() {
        let tw = |t: f64| {
            [
                0.3 + 0.2 * t.sin(),
                -0.1 * t,
                0.4 * (2.0 * t).cos(),
                0.3 * (2.0 * t).sin() + 0.2,
                0.5 * (3.0 * t).cos(),
                -0.4 * (1.3 * t + 0.5).sin(),
            ]
        };
        let dtw = |t: f64| {
            [
                0.2 * t.cos(),
                -0.1,
                -0.8 * (2.0 * t).sin(),
                0.6 * (2.0 * t).cos(),
                -1.5 * (3.0 * t).sin(),
                -0.52 * (1.3 * t + 0.5).cos(),
            ]
        };
        let t_end = 2.0;
        // reference: RK4 on (r, Q) with a small step
        let f = |t: f64, y: &[f64; 7]| -> [f64; 7] {
            let x = tw(t);
            let q = [y[3], y[4], y[5], y[6]];
            let u = rot_from_quat(&q) * V3::new(x[0], x[1], x[2]);
            let dq = quat_mul(&q, &[0.5 * x[3], 0.5 * x[4], 0.5 * x[5], 0.0]);
            [u.x, u.y, u.z, dq[0], dq[1], dq[2], dq[3]]
        };
        let y = rk4(f, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], t_end);
        let q_ref = [y[3], y[4], y[5], y[6]];
        let err = |n: usize, hermite: bool| {
            let h = t_end / (n - 1) as f64;
            let twists: Vec<f64> = (0..n).flat_map(|k| tw(k as f64 * h)).collect();
            let rates: Vec<f64> = (0..n).flat_map(|k| dtw(k as f64 * h)).collect();
            let mut out = vec![0.0; 7 * n];
            let d = hermite.then_some(&rates[..]);
            integrate_base_poses(Steps::Uniform(h), &twists, d, &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], &mut out)
                .unwrap();
            let last = &out[7 * (n - 1)..];
            let dr = so3_log(&(rot_from_quat(&q_ref).transpose() * rot_from_quat(&last[3..7]))).norm();
            (dr, (V3::new(last[0], last[1], last[2]) - V3::new(y[0], y[1], y[2])).norm())
        };
        for (hermite, want) in [(false, 2.0), (true, 4.0)] {
            let (a, b) = (err(21, hermite), err(41, hermite));
            let (oa, op) = ((a.0 / b.0).log2(), (a.1 / b.1).log2());
            assert!((oa - want).abs() < 0.2 && (op - want).abs() < 0.2, "hermite {hermite}: orders {oa}, {op}");
        }
        assert!(err(41, true).0 < 1e-3 * err(41, false).0);
        // planar: yaw and position against RK4 of the planar ODE
        let ptw = |t: f64| [0.5 + t.sin(), -0.3 * t, 0.2 + 0.4 * t.cos()];
        let pdtw = |t: f64| [t.cos(), -0.3, -0.4 * t.sin()];
        let fp = |t: f64, y: &[f64; 3]| -> [f64; 3] {
            let x = ptw(t);
            let (s, c) = y[2].sin_cos();
            [c * x[0] - s * x[1], s * x[0] + c * x[1], x[2]]
        };
        let yp = rk4(fp, [1.0, -1.0, 0.3], t_end);
        let perr = |n: usize| {
            let h = t_end / (n - 1) as f64;
            let twists: Vec<f64> = (0..n).flat_map(|k| ptw(k as f64 * h)).collect();
            let rates: Vec<f64> = (0..n).flat_map(|k| pdtw(k as f64 * h)).collect();
            let mut out = vec![0.0; 3 * n];
            integrate_planar_base_poses(Steps::Uniform(h), &twists, Some(&rates), &[1.0, -1.0, 0.3], &mut out).unwrap();
            let last = &out[3 * (n - 1)..];
            (last[0] - yp[0]).hypot(last[1] - yp[1]).max((last[2] - yp[2]).abs())
        };
        let order = (perr(21) / perr(41)).log2();
        assert!((order - 4.0).abs() < 0.2, "planar order {order}");
        // bad rates
        let mut out = vec![0.0; 7 * 3];
        let tw3 = [0.0; 18];
        assert!(integrate_base_poses(
            Steps::Uniform(0.1),
            &tw3,
            Some(&[0.0; 17]),
            &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
            &mut out
        )
        .is_err());
        assert!(integrate_base_poses(
            Steps::Uniform(0.1),
            &tw3,
            Some(&[f64::NAN; 18]),
            &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
            &mut out
        )
        .is_err());
    }

    /// Uneven times give the same result as the uniform step when they are the same grid.
    #[test]
    fn times_and_uniform_step_agree() {
        let n = 30;
        let h = 0.01;
        let twists: Vec<f64> = (0..n)
            .flat_map(|k| {
                let s = k as f64 * h;
                [s.sin(), 0.2, -s, 0.3 * s.cos(), 0.1, s * s]
            })
            .collect();
        let t: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
        let pose0 = [1.0, 2.0, 3.0, 0.0, 0.0, 0.6f64.sin(), 0.6f64.cos()];
        let (mut a, mut b) = (vec![0.0; 7 * n], vec![0.0; 7 * n]);
        integrate_base_poses(Steps::Uniform(h), &twists, None, &pose0, &mut a).unwrap();
        integrate_base_poses(Steps::Times(&t), &twists, None, &pose0, &mut b).unwrap();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-13);
        }
    }

    /// The planar rule equals the free-base rule for a motion in the plane.
    #[test]
    fn planar_matches_free_in_plane() {
        let n = 50;
        let h = 0.05;
        let rates: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                let s = k as f64 * h;
                [0.5 + s.sin(), -0.3 * s, 0.2 + 0.4 * s.cos()]
            })
            .collect();
        let planar: Vec<f64> = rates.iter().flatten().copied().collect();
        let free: Vec<f64> = rates.iter().flat_map(|r| [r[0], r[1], 0.0, 0.0, 0.0, r[2]]).collect();
        let yaw0 = 0.3f64;
        let (mut p, mut f) = (vec![0.0; 3 * n], vec![0.0; 7 * n]);
        integrate_planar_base_poses(Steps::Uniform(h), &planar, None, &[1.0, -1.0, yaw0], &mut p).unwrap();
        integrate_base_poses(
            Steps::Uniform(h),
            &free,
            None,
            &[1.0, -1.0, 0.0, 0.0, 0.0, (yaw0 / 2.0).sin(), (yaw0 / 2.0).cos()],
            &mut f,
        )
        .unwrap();
        for k in 0..n {
            let r: M3 = rot_from_quat(&f[7 * k + 3..7 * k + 7]);
            let yaw = r[(1, 0)].atan2(r[(0, 0)]);
            assert!((p[3 * k] - f[7 * k]).abs() < 1e-12 && (p[3 * k + 1] - f[7 * k + 1]).abs() < 1e-12);
            assert!(
                ((p[3 * k + 2] - yaw + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                    - std::f64::consts::PI)
                    .abs()
                    < 1e-12
            );
        }
    }

    #[test]
    fn bad_arguments_are_errors() {
        let tw = [0.0; 12];
        let mut out = [0.0; 14];
        let p0 = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        assert!(integrate_base_poses(Steps::Uniform(0.0), &tw, None, &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Times(&[0.0, 0.0]), &tw, None, &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Times(&[0.0]), &tw, None, &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Uniform(0.1), &tw[..11], None, &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Uniform(0.1), &tw, None, &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0], &mut out)
            .is_err());
        let mut nan = tw;
        nan[4] = f64::NAN;
        assert!(integrate_base_poses(Steps::Uniform(0.1), &nan, None, &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Uniform(0.1), &tw, None, &p0, &mut out[..13]).is_err());
    }
}
