use super::{check_out, RegressorOut};
use crate::check::{check_args, check_data, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::kinematics::forward_velocities_unchecked;
use crate::model::Model;
use crate::spatial::lanes::{add, cross, mat_vec, scale, Real, Vec3};
use nalgebra::{Dyn, StorageMut};

/// Momentum regressor `K` (6 × 10·nbodies): `momentum(q, v) == K · vec(P)`, momentum being
/// `[p; L]` about the inertial origin in the inertial frame.
///
/// This is the link kinematic matrix `K_i` of Naveen, Shah, Misra (Eq. 10) with the columns in our
/// parameter order. Body i's momentum in its own frame is
/// `Iᵢ vᵢ = [m v − h × ω; I_o ω + h × v]`, linear in its ten parameters; carried to the inertial
/// origin and written in inertial-frame quantities (`v_o = R v`, `ω_o = R ω`, `r_k` = column k of
/// R, `p` the body origin, ω in the body frame) the columns are:
/// - mass: `[v_o; p × v_o]`
/// - first moment `h_k`: `[ω_o × r_k; r_k × v_o + p × (ω_o × r_k)]`
/// - inertia `I_jk`: `[0; r_j ω_k + r_k ω_j]` (`[0; r_k ω_k]` on the diagonal).
///
/// This expanded form costs about half of rotating every body-frame column (it is the hot loop of
/// identification); tests check it against `Inertia::mul_motion_columns` carried by `act_force`.
pub fn momentum_regressor<S: StorageMut<f64, Dyn, Dyn>>(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
    out: &mut RegressorOut<S>,
) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::qv(q, v))?;
    check_out(m, out, 6)?;
    with_unit_q(m, d, q, fix, |d, q| forward_velocities_unchecked(m, d, q, v));
    momentum_regressor_from_data_unchecked(m, d, out);
    Ok(())
}

/// The momentum regressor from placements `d.o_mi` and body twists `d.v` already in `d` (e.g. placements
/// moved rigidly with the base, as the excitation design does, without a second kinematics pass).
pub fn momentum_regressor_from_data<S: StorageMut<f64, Dyn, Dyn>>(
    m: &Model,
    d: &Data,
    out: &mut RegressorOut<S>,
) -> Result<()> {
    check_data(m, d)?;
    check_out(m, out, 6)?;
    momentum_regressor_from_data_unchecked(m, d, out);
    Ok(())
}

pub(crate) fn momentum_regressor_from_data_unchecked<S: StorageMut<f64, Dyn, Dyn>>(
    m: &Model,
    d: &Data,
    out: &mut RegressorOut<S>,
) {
    for i in 0..m.nbodies() {
        for (k, col) in body_momentum_columns(d, i).iter().enumerate() {
            for r in 0..6 {
                out[(r, 10 * i + k)] = col[r];
            }
        }
    }
}

/// Body i's ten columns of the momentum regressor, `[p; L]` each (see [`momentum_regressor`]), from `d.o_mi[i]`
/// and the body twist `d.v[i]`: [`momentum_columns`] for one sample, shared by the regressor and the excitation
/// design.
#[inline]
pub(crate) fn body_momentum_columns(d: &Data, i: usize) -> [[f64; 6]; 10] {
    let (rot, p) = (&d.o_mi[i].rot, d.o_mi[i].trans);
    let r = [0, 1, 2].map(|k| [rot[(0, k)], rot[(1, k)], rot[(2, k)]]);
    let (vb, wb) = (d.v[i].lin, d.v[i].ang);
    momentum_columns(&r, &[p.x, p.y, p.z], &[vb.x, vb.y, vb.z], &[wb.x, wb.y, wb.z])
}

/// The ten momentum-regressor columns of a body with rotation R (columns `r`), origin `p` and body-frame twist
/// `(vb, wb)`, all inertial-frame but the twist: the one copy of Naveen, Shah, Misra's eq. 10, for one sample
/// (`f64`) or four or eight side by side (`Lanes<L>`, the identification's stream), with the same operations in the same order
/// (nalgebra's, which this replaced: the results did not change by a bit).
#[inline(always)]
pub(crate) fn momentum_columns<T: Real>(r: &[Vec3<T>; 3], p: &Vec3<T>, vb: &Vec3<T>, wb: &Vec3<T>) -> [[T; 6]; 10] {
    let mut out = [[T::splat(0.0); 6]; 10];
    momentum_columns_into(&mut out, r, p, vb, wb, ALL_COLUMNS);
    out
}

/// Every column of [`momentum_columns_into`].
pub(crate) const ALL_COLUMNS: u16 = (1 << 10) - 1;

/// [`momentum_columns`] into `out`, only the columns k with bit k of `need` set (the others are not touched): the
/// identification's stream asks for the columns it keeps or moves to the right-hand side (on the dual-arm robot,
/// no first moments of the wheels, no mass, h_z, I_yy of the links), into one buffer for all bodies. (Returning a
/// fresh, zeroed array per body instead cost a 1.9 kB memset per body and four samples: 5 % of the identification.)
#[inline(always)]
pub(crate) fn momentum_columns_into<T: Real>(
    out: &mut [[T; 6]; 10],
    r: &[Vec3<T>; 3],
    p: &Vec3<T>,
    vb: &Vec3<T>,
    wb: &Vec3<T>,
    need: u16,
) {
    let on = |k: usize| need & (1 << k) != 0;
    let col = |lin: Vec3<T>, ang: Vec3<T>| [lin[0], lin[1], lin[2], ang[0], ang[1], ang[2]];
    let z = [T::splat(0.0); 3];
    if need & 0b1111 != 0 {
        let vo = mat_vec(r, vb);
        if on(0) {
            out[0] = col(vo, cross(p, &vo));
        }
        if need & 0b1110 != 0 {
            let wo = mat_vec(r, wb);
            for k in 0..3 {
                if on(k + 1) {
                    out[k + 1] = first_moment_column(&r[k], p, &vo, &wo);
                }
            }
        }
    }
    // the inertia columns: [0; r_j ω_k + r_k ω_j]
    let inertia = [(0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)];
    for (c, &(j, k)) in inertia.iter().enumerate() {
        if on(4 + c) {
            out[4 + c] =
                col(z, if j == k { scale(&r[j], wb[j]) } else { add(&scale(&r[j], wb[k]), &scale(&r[k], wb[j])) });
        }
    }
}

/// The column of the first moment along `r_k`: `[ω_o × r_k; r_k × v_o + p × (ω_o × r_k)]` (a function, not a
/// closure, so that it is inlined: as a closure it stayed a call that returned its column through memory).
#[inline(always)]
fn first_moment_column<T: Real>(rk: &Vec3<T>, p: &Vec3<T>, vo: &Vec3<T>, wo: &Vec3<T>) -> [T; 6] {
    let lin = cross(wo, rk);
    let ang = add(&cross(rk, vo), &cross(p, &lin));
    [lin[0], lin[1], lin[2], ang[0], ang[1], ang[2]]
}
