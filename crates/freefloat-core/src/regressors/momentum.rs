use super::{check_out, write_column, RegressorOut};
use crate::check::{check_args, check_data, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::kinematics::forward_velocities_unchecked;
use crate::model::Model;
use crate::spatial::{Force, V3};
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
    let z = V3::zeros();
    for i in 0..m.nbodies() {
        let (rot, p) = (&d.o_mi[i].rot, d.o_mi[i].trans);
        let (vb, wb) = (d.v[i].lin, d.v[i].ang);
        let (vo, wo) = (rot * vb, rot * wb);
        let r = [rot.column(0).into_owned(), rot.column(1).into_owned(), rot.column(2).into_owned()];
        let c = 10 * i;
        write_column(out, c, &Force::new(vo, p.cross(&vo)));
        for k in 0..3 {
            let lin = wo.cross(&r[k]);
            write_column(out, c + 1 + k, &Force::new(lin, r[k].cross(&vo) + p.cross(&lin)));
        }
        write_column(out, c + 4, &Force::new(z, r[0] * wb.x));
        write_column(out, c + 5, &Force::new(z, r[0] * wb.y + r[1] * wb.x));
        write_column(out, c + 6, &Force::new(z, r[1] * wb.y));
        write_column(out, c + 7, &Force::new(z, r[0] * wb.z + r[2] * wb.x));
        write_column(out, c + 8, &Force::new(z, r[1] * wb.z + r[2] * wb.y));
        write_column(out, c + 9, &Force::new(z, r[2] * wb.z));
    }
}
