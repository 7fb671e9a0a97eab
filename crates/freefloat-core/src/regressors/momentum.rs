use super::{check_out, RegressorOut};
use crate::check::{check_args, check_data, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::kinematics::forward_velocities_unchecked;
use crate::model::Model;
use crate::spatial::V3;
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
/// and the body twist `d.v[i]`: the one copy of Naveen, Shah, Misra's eq. 10, shared by the regressor and by the
/// identification's block builder (which keeps only some columns and so writes them itself).
#[inline]
pub(crate) fn body_momentum_columns(d: &Data, i: usize) -> [[f64; 6]; 10] {
    let (rot, p) = (&d.o_mi[i].rot, d.o_mi[i].trans);
    let (vb, wb) = (d.v[i].lin, d.v[i].ang);
    let (vo, wo) = (rot * vb, rot * wb);
    let r = [rot.column(0).into_owned(), rot.column(1).into_owned(), rot.column(2).into_owned()];
    let col = |lin: V3, ang: V3| [lin.x, lin.y, lin.z, ang.x, ang.y, ang.z];
    let z = V3::zeros();
    let h = |k: usize| {
        let lin = wo.cross(&r[k]);
        col(lin, r[k].cross(&vo) + p.cross(&lin))
    };
    [
        col(vo, p.cross(&vo)),
        h(0),
        h(1),
        h(2),
        col(z, r[0] * wb.x),
        col(z, r[0] * wb.y + r[1] * wb.x),
        col(z, r[1] * wb.y),
        col(z, r[0] * wb.z + r[2] * wb.x),
        col(z, r[1] * wb.z + r[2] * wb.y),
        col(z, r[2] * wb.z),
    ]
}
