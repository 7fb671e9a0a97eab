use super::{check_shape, write_column, RegressorOut};
use crate::data::Data;
use crate::kinematics::forward_velocities;
use crate::model::Model;
use crate::spatial::Inertia;
use nalgebra::{Dyn, StorageMut};

/// Momentum regressor `K` (6 × 10·nbodies): `momentum(q, v) == K · vec(P)`, momentum being
/// `[p; L]` about the inertial origin in the inertial frame.
///
/// Body i's momentum in its own frame is `Iᵢ vᵢ = [m v − h × ω; I_o ω + h × v]`, linear in its
/// ten parameters (`Inertia::mul_motion_columns`); `o_M_i.act_force` carries each column to the
/// inertial origin. This is seed 001's link kinematic matrix `K_i` (Eq. 10; digest
/// `seed001_minimal_params.md` §A.2–A.5) with the columns in our parameter order.
pub fn momentum_regressor<S: StorageMut<f64, Dyn, Dyn>>(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
    out: &mut RegressorOut<S>,
) {
    check_shape(m, out, 6, "momentum_regressor");
    forward_velocities(m, d, q, v);
    for i in 0..m.nbodies() {
        for (k, f) in Inertia::mul_motion_columns(&d.v[i]).iter().enumerate() {
            write_column(out, 10 * i + k, &d.o_mi[i].act_force(f));
        }
    }
}
