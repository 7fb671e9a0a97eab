use super::*;
use crate::spatial::{quat_normalize, rot_from_quat};

fn xi(s: f64) -> V6 {
    V6::new(0.3 * s, -0.7 * s, 0.2 * s, 0.9 * s, -0.4 * s, 1.1 * s)
}

#[test]
fn exp_and_log_are_inverse() {
    for s in [1e-7, 1e-3, 0.5, 1.0, 2.0] {
        let x = xi(s);
        let back = log6(&exp6(&x));
        assert!((back - x).amax() < 1e-12, "s = {s}: {back:?}");
    }
}

#[test]
fn right_jacobian_inverse_matches_central_differences() {
    for s in [1e-5, 0.3, 1.0, 1.8] {
        let x = xi(s);
        let m = exp6(&x);
        let jac = se3_right_jacobian_inv(&x);
        let h = 1e-6;
        for c in 0..6 {
            let mut d = V6::zeros();
            d[c] = h;
            let p = log6(&m.compose(&exp6(&d)));
            d[c] = -h;
            let mm = log6(&m.compose(&exp6(&d)));
            let col = (p - mm) / (2.0 * h);
            let err = (col - jac.column(c)).amax();
            assert!(err < 1e-8, "s = {s}, column {c}: {err}");
        }
    }
}

#[test]
fn free_flyer_difference_inverts_integrate() {
    let q0 = {
        let mut q = [0.1, -0.2, 0.3, 0.2, -0.1, 0.4, 0.9];
        quat_normalize(&mut q[3..7]);
        q
    };
    let d = [0.4, -0.3, 0.8, 0.5, -0.6, 0.2];
    let mut q1 = [0.0; 7];
    ff_integrate(&q0, &d, &mut q1);
    let mut back = [0.0; 6];
    ff_difference(&q0, &q1, &mut back);
    for i in 0..6 {
        assert!((back[i] - d[i]).abs() < 1e-12);
    }
}

// ------------------------------------------------ independent references: power series of matrices

/// `Σₙ cₙ Aⁿ` with `cₙ = 1/(n + shift)!`, summed until the terms stop mattering (‖A‖ ≤ π here: at most 60 terms).
fn power_series<const N: usize>(a: &nalgebra::SMatrix<f64, N, N>, shift: usize) -> nalgebra::SMatrix<f64, N, N> {
    let mut fact = (1..=shift).map(|k| k as f64).product::<f64>();
    let mut pow = nalgebra::SMatrix::<f64, N, N>::identity();
    let mut sum = pow / fact;
    for n in 1..80 {
        pow = a * pow;
        fact *= (n + shift) as f64;
        let term = pow / fact;
        sum += term;
        if term.amax() < 1e-40 {
            break;
        }
    }
    sum
}

/// Directional derivative of `Σₙ Aⁿ/(n+1)!` along `U`: `Σₙ 1/(n+1)! Σᵢ Aⁱ U Aⁿ⁻¹⁻ⁱ`.
fn power_series_derivative(a: &M3, u: &M3) -> M3 {
    // dPₙ = A dPₙ₋₁ + U Aⁿ⁻¹ with Pₙ = Aⁿ
    let (mut pow, mut dpow) = (M3::identity(), M3::zeros());
    let (mut fact, mut sum) = (1.0, M3::zeros());
    for n in 1..80 {
        dpow = a * dpow + u * pow;
        pow = a * pow;
        fact *= (n + 1) as f64;
        let term = dpow / fact;
        sum += term;
        if term.amax() < 1e-40 && n > 4 {
            break;
        }
    }
    sum
}

fn ad6(x: &V6) -> M6 {
    let (r, p) = (skew(&V3::new(x[0], x[1], x[2])), skew(&V3::new(x[3], x[4], x[5])));
    let mut m = M6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&p);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&p);
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(&r);
    m
}

fn rel<const R: usize, const C: usize>(a: &nalgebra::SMatrix<f64, R, C>, b: &nalgebra::SMatrix<f64, R, C>) -> f64 {
    (a - b).amax() / b.amax().max(1.0)
}

/// Every Lie function against its power series, θ from 1e-9 to π − 1e-3 (log-spaced, so that both sides of
/// `SMALL_ANGLE_SQ` are dense), on three axes, relative to the larger of 1 and the reference's largest entry.
#[test]
fn sweep_matches_power_series() {
    let axes = [V3::new(1.0, 0.0, 0.0), V3::new(0.3, -0.5, 0.8).normalize(), V3::new(-0.6, 0.7, 0.2).normalize()];
    let (lo, hi) = (1e-9f64.ln(), (std::f64::consts::PI - 1e-3).ln());
    let n = 600;
    let mut worst: Vec<(&str, f64, f64)> = Vec::new();
    let mut note = |name: &'static str, th: f64, e: f64| match worst.iter_mut().find(|w| w.0 == name) {
        Some(w) if e > w.1 => *w = (name, e, th),
        Some(_) => {}
        None => worst.push((name, e, th)),
    };
    for (ai, axis) in axes.iter().enumerate() {
        for i in 0..=n {
            let th = (lo + (hi - lo) * i as f64 / n as f64).exp();
            let phi = axis * th;
            let k = skew(&phi);
            let w = V3::new(0.4, -1.3, 0.7);
            let exp_ref = power_series(&k, 0);
            let jr_ref = power_series(&(-k), 1);
            let jl_ref = power_series(&k, 1);
            let jr_inv_ref = jr_ref.try_inverse().unwrap();
            let jl_inv_ref = jl_ref.try_inverse().unwrap();
            note("so3_exp", th, rel(&so3_exp(&phi), &exp_ref));
            note("quat_exp", th, rel(&rot_from_quat(&quat_exp(&phi)), &exp_ref));
            note("so3_log", th, (so3_log(&exp_ref) - phi).amax() / th.max(1.0));
            note("quat_log", th, (quat_log(&quat_exp(&phi)) - phi).amax() / th.max(1.0));
            note("so3_right_jacobian", th, rel(&so3_right_jacobian(&phi), &jr_ref));
            note("so3_left_jacobian", th, rel(&so3_left_jacobian(&phi), &jl_ref));
            note("so3_right_jacobian_inv_matrix", th, rel(&so3_right_jacobian_inv_matrix(&phi), &jr_inv_ref));
            note("so3_left_jacobian_inv", th, rel(&so3_left_jacobian_inv(&phi), &jl_inv_ref));
            let v_ref = jr_inv_ref * w;
            note("so3_right_jacobian_inv", th, rel(&so3_right_jacobian_inv(&phi, &w), &v_ref));
            // ∂(Jr⁻¹ w)/∂θ column c = −Jr⁻¹ (∂Jr/∂θ_c) Jr⁻¹ w, with ∂Jr/∂θ_c the series' derivative along −[e_c]
            let dref = M3::from_fn(|r, c| {
                let dj = power_series_derivative(&(-k), &(-skew(&V3::ith(c, 1.0))));
                (-(jr_inv_ref * dj * v_ref))[r]
            });
            note("so3_right_jacobian_inv_dtheta", th, rel(&so3_right_jacobian_inv_dtheta(&phi, &w), &dref));
            // SE(3): ρ of unit size and of the size of φ
            for rho in [V3::new(0.5, 0.2, -0.8) * (1.0 + ai as f64), V3::new(-0.3, 0.9, 0.1) * th] {
                let x = V6::new(rho.x, rho.y, rho.z, phi.x, phi.y, phi.z);
                let mut hat = nalgebra::Matrix4::<f64>::zeros();
                hat.fixed_view_mut::<3, 3>(0, 0).copy_from(&k);
                hat.fixed_view_mut::<3, 1>(0, 3).copy_from(&rho);
                let e4 = power_series(&hat, 0);
                let m = exp6(&x);
                let mut e_ours = nalgebra::Matrix4::<f64>::identity();
                e_ours.fixed_view_mut::<3, 3>(0, 0).copy_from(&m.rot);
                e_ours.fixed_view_mut::<3, 1>(0, 3).copy_from(&m.trans);
                note("exp6", th, rel(&e_ours, &e4));
                let se = Se3::new(e4.fixed_view::<3, 3>(0, 0).into(), e4.fixed_view::<3, 1>(0, 3).into());
                note("log6", th, (log6(&se) - x).amax() / x.amax().max(1.0));
                let jr6_inv_ref = power_series(&(-ad6(&x)), 1).try_inverse().unwrap();
                note("se3_right_jacobian_inv", th, rel(&se3_right_jacobian_inv(&x), &jr6_inv_ref));
            }
        }
    }
    let mut bad = Vec::new();
    for (name, e, th) in &worst {
        eprintln!("{name:32} worst relative error {e:.2e} at theta = {th:.3e}");
        if *e > 1e-12 {
            bad.push(format!("{name}: {e:.2e} at theta = {th:.3e}"));
        }
    }
    assert!(bad.is_empty(), "beyond 1e-12: {bad:?}");
}

/// The Taylor coefficients are the general terms their comments state (factorials in f64: exact to 2⁻⁵³).
#[test]
fn series_coefficients_are_their_general_terms() {
    let f = |n: usize| (1..=n).map(|k| k as f64).product::<f64>();
    let close = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * b.abs();
    for n in 0..7 {
        let s = if n % 2 == 0 { 1.0 } else { -1.0 };
        assert!(close(HALF_SINC[n], s / (2f64.powi(2 * n as i32 + 1) * f(2 * n + 1))));
        assert!(close(HALF_COS[n], s / (2f64.powi(2 * n as i32) * f(2 * n))));
        assert!(close(ONE_MINUS_COS[n], s / f(2 * n + 2)));
        assert!(close(THETA_MINUS_SIN[n], s / f(2 * n + 3)));
        assert!(close(Q_C2[n], s / f(2 * n + 4)));
        assert!(close(Q_C3[n], s * (n + 1) as f64 / f(2 * n + 5)));
    }
    for n in 0..7 {
        assert!(close(JINV_DERIV[n], 2.0 * (n + 1) as f64 * JINV[n + 1]));
    }
    // the first term left out, at the cutoff, is below 2⁻⁵⁷ of the value there
    let c = SMALL_ANGLE_SQ;
    assert!(c.powi(7) / f(16) < 2f64.powi(-57) * 0.47); // (1 − cos θ)/θ²
    assert!(c.powi(7) / f(17) < 2f64.powi(-57) * 0.16); // (θ − sin θ)/θ³
    assert!(c.powi(7) / (2f64.powi(15) * f(15)) < 2f64.powi(-57) * 0.49); // sin(θ/2)/θ
    assert!(c.powi(7) / (2f64.powi(14) * f(14)) < 2f64.powi(-57) * 0.96); // cos(θ/2)
    assert!(c.powi(7) / f(18) < 2f64.powi(-57) * 0.04); // Q's c₂
    assert!(c.powi(7) * 8.0 / f(19) < 2f64.powi(-57) * 0.008); // Q's c₃
                                                               // D: |B₁₈|/18! = 2ζ(18)/(2π)¹⁸ ≤ 2.0001/(2π)¹⁸
    assert!(c.powi(8) * 2.0001 / (2.0 * std::f64::consts::PI).powi(18) < 2f64.powi(-57) / 12.0);
    assert!(c.powi(9) * 20.0 * 2.0001 / (2.0 * std::f64::consts::PI).powi(22) < 2f64.powi(-57) / 360.0);
}

/// The closed forms and the series agree to round-off on both sides of the cutoff.
#[test]
fn series_and_closed_forms_meet_at_the_cutoff() {
    for t2 in [SMALL_ANGLE_SQ * (1.0 - 1e-12), SMALL_ANGLE_SQ * (1.0 + 1e-12)] {
        let t = t2.sqrt();
        let (a, b) = jacobian_coeffs(t2);
        assert!((a - (1.0 - t.cos()) / t2).abs() < 1e-15);
        assert!((b - (t - t.sin()) / (t2 * t)).abs() < 1e-14);
        let (d, _) = jinv_coeffs(t2);
        assert!((d - (1.0 / t2 - (1.0 + t.cos()) / (2.0 * t * t.sin()))).abs() < 1e-14);
    }
}
