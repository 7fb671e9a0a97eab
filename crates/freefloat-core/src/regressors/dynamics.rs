use super::{check_out, RegressorOut};
use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::dynamics::gravity_acceleration;
use crate::error::Result;
use crate::kinematics::{forward_accelerations_unchecked, world_motion_subspaces_unchecked};
use crate::model::Model;
use crate::spatial::Inertia;
use nalgebra::{Dyn, StorageMut};

/// Inverse-dynamics regressor `Y` (nv × 10·nbodies): `rnea(q, v, a) == Y · vec(P)`, gravity
/// included (no external forces).
///
/// Body i's Newton-Euler force `fᵢ = Iᵢ aᵢ + vᵢ ×* (Iᵢ vᵢ)` is linear in its parameters (a 6×10
/// block in the body frame, `aᵢ` including the fictitious base acceleration `−g` as in RNEA). Carried
/// to the inertial frame, it loads every joint j on the path to the root: rows of j get
/// `oSⱼᵀ (oX*ᵢ Yᵢ)`. Fixed bodies own their columns through their ancestors' rows. The per-body
/// block `Y(aᵢ) + vᵢ ×* Y(vᵢ)` is Valverde 2018's per-body regressor `R = r(ω̇ˢ) + [ω]× r(ωˢ)` (Eqs. 4.3
/// and 9.7; (4.3) written with the body's inertial twist and its rate) in spatial vectors, i.e. the time
/// derivative of the link kinematic matrix of Naveen, Shah, Misra (Eq. 10), in our ten-parameter order;
/// Naveen et al. (Sec. VI.D) use such a regressor for torque prediction.
pub fn dynamics_regressor<S: StorageMut<f64, Dyn, Dyn>>(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    out: &mut RegressorOut<S>,
) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::qv(q, v).nv("a", a))?;
    check_out(m, out, m.nv)?;
    with_unit_q(m, d, q, fix, |d, q| forward_accelerations_unchecked(m, d, q, v, a));
    world_motion_subspaces_unchecked(m, d);
    let ag = gravity_acceleration(m);
    out.fill(0.0);
    for i in 0..m.nbodies() {
        let (x, vi) = (d.o_mi[i], d.v[i]);
        // Gravity enters every body's acceleration rigidly: X_{i←0} (−g).
        let ai = d.a[i] + x.inv_act_motion(&ag);
        let ya = Inertia::mul_motion_columns(&ai);
        let yv = Inertia::mul_motion_columns(&vi);
        for k in 0..10 {
            let f = x.act_force(&(ya[k] + vi.cross_force(&yv[k]))).to_v6();
            let col = 10 * i + k;
            let mut j = Some(i);
            while let Some(jj) = j {
                for c in 0..m.nvs[jj] {
                    out[(m.idx_v[jj] + c, col)] = d.os[jj].column(c).dot(&f);
                }
                j = m.parents[jj];
            }
        }
    }
    Ok(())
}
