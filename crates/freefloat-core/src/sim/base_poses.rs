//! Base poses from sampled base twists: the trapezoidal rule on the group. The one copy of this formula:
//! the exciting-trajectory design (`excitation::response`, the base response along a joint path) and the
//! telemetry tools (pose reconstruction from measured rates, Python `telemetry.integrate_poses`) use it.
//!
//! Free base, twists `[v; ω]` in the base frame at samples k = 0, 1, …, step `h_k = t_{k+1} − t_k`:
//! - attitude `Q_{k+1} = normalise(Q_k ⊗ exp(h_k (ω_k + ω_{k+1}) / 2))` (body-frame ω, right product);
//! - position `r_{k+1} = r_k + h_k (R_k v_k + R_{k+1} v_{k+1}) / 2`, `R_k` the rotation of `Q_k`.
//!
//! Planar base, `[vx, vy, ω_z]` in the base frame: `ψ_{k+1} = ψ_k + h_k (ω_k + ω_{k+1}) / 2` and the
//! position as above with `R(ψ)`.
//!
//! Second order; it uses both samples of a step, which is what a sampled measurement gives. (Naveen, Shah,
//! Misra's Appendix C, eqs. 44-47, integrates Euler angles by explicit Euler; we keep the attitude on the group.)

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
    crate::error::check_vec("pose0", pose0, nq)?;
    let n = twists.len() / width;
    if out.len() != n * nq {
        return Err(FfError::arg("out", format!("expected {} numbers ({n} × {nq}), got {}", n * nq, out.len())));
    }
    Ok(n)
}

/// Free-base poses `out` (samples × 7: position, quaternion x y z w) from base-frame twists `twists`
/// (samples × 6: `[v; ω]`) starting at `pose0` (7: position, quaternion; its norm must be within 1e-6 of 1).
pub fn integrate_base_poses(steps: Steps, twists: &[f64], pose0: &[f64], out: &mut [f64]) -> Result<()> {
    let n = check_samples(twists, 6, pose0, 7, out)?;
    steps.check(n)?;
    let mut quat = [pose0[3], pose0[4], pose0[5], pose0[6]];
    let norm = quat.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > 1e-6 {
        return Err(FfError::arg(
            "pose0",
            format!("the quaternion (x y z w) has norm {norm:.6}; it must be a unit quaternion"),
        ));
    }
    quat_normalize(&mut quat);
    let tw = |k: usize| &twists[6 * k..6 * k + 6];
    let mut pos = V3::new(pose0[0], pose0[1], pose0[2]);
    let mut vel0 = rot_from_quat(&quat) * V3::new(tw(0)[0], tw(0)[1], tw(0)[2]);
    out[..3].copy_from_slice(pos.as_slice());
    out[3..7].copy_from_slice(&quat);
    for k in 1..n {
        let h = steps.step(k);
        let (a, b) = (tw(k - 1), tw(k));
        let w = (V3::new(a[3], a[4], a[5]) + V3::new(b[3], b[4], b[5])) * (0.5 * h);
        quat = quat_mul(&quat, &quat_exp(&w));
        quat_normalize(&mut quat);
        let vel = rot_from_quat(&quat) * V3::new(b[0], b[1], b[2]);
        pos += (vel0 + vel) * (0.5 * h);
        vel0 = vel;
        out[7 * k..7 * k + 3].copy_from_slice(pos.as_slice());
        out[7 * k + 3..7 * k + 7].copy_from_slice(&quat);
    }
    Ok(())
}

/// Planar-base poses `out` (samples × 3: x, y, yaw) from base-frame rates `twists` (samples × 3:
/// vx, vy, yaw rate) starting at `pose0` (3).
pub fn integrate_planar_base_poses(steps: Steps, twists: &[f64], pose0: &[f64], out: &mut [f64]) -> Result<()> {
    let n = check_samples(twists, 3, pose0, 3, out)?;
    steps.check(n)?;
    let world = |yaw: f64, t: &[f64]| {
        let (s, c) = yaw.sin_cos();
        [c * t[0] - s * t[1], s * t[0] + c * t[1]]
    };
    let (mut x, mut y, mut yaw) = (pose0[0], pose0[1], pose0[2]);
    let mut vel0 = world(yaw, &twists[0..3]);
    out[..3].copy_from_slice(&[x, y, yaw]);
    for k in 1..n {
        let h = steps.step(k);
        let (a, b) = (&twists[3 * k - 3..3 * k], &twists[3 * k..3 * k + 3]);
        yaw += (a[2] + b[2]) * (0.5 * h);
        let vel = world(yaw, b);
        x += (vel0[0] + vel[0]) * (0.5 * h);
        y += (vel0[1] + vel[1]) * (0.5 * h);
        vel0 = vel;
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
        integrate_base_poses(Steps::Uniform(h), &twists, &pose0, &mut a).unwrap();
        integrate_base_poses(Steps::Times(&t), &twists, &pose0, &mut b).unwrap();
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
        integrate_planar_base_poses(Steps::Uniform(h), &planar, &[1.0, -1.0, yaw0], &mut p).unwrap();
        integrate_base_poses(
            Steps::Uniform(h),
            &free,
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
        assert!(integrate_base_poses(Steps::Uniform(0.0), &tw, &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Times(&[0.0, 0.0]), &tw, &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Times(&[0.0]), &tw, &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Uniform(0.1), &tw[..11], &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Uniform(0.1), &tw, &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0], &mut out).is_err());
        let mut nan = tw;
        nan[4] = f64::NAN;
        assert!(integrate_base_poses(Steps::Uniform(0.1), &nan, &p0, &mut out).is_err());
        assert!(integrate_base_poses(Steps::Uniform(0.1), &tw, &p0, &mut out[..13]).is_err());
    }
}
