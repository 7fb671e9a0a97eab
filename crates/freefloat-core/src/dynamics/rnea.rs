use super::{fext_of, gravity_acceleration};
use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::kinematics::{forward_kinematics_unchecked, joint_bias, joint_velocity};
use crate::model::Model;
use crate::spatial::Motion;

/// Inverse dynamics: generalized forces `τ = M(q) a + h(q, v) − Σ Jᵢᵀ fextᵢ`, into `d.tau`.
/// For a free base the first six entries are the base-frame wrench [force; torque] on the base.
/// `fext` holds nbodies × 6 body-frame wrenches [force; torque about the body origin].
/// Checks every argument (sizes, finiteness, unit quaternions, `d` made for `m`).
pub fn rnea(m: &Model, d: &mut Data, q: &[f64], v: &[f64], a: &[f64], fext: Option<&[f64]>) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::qv(q, v).nv("a", a).fext(fext))?;
    with_unit_q(m, d, q, fix, |d, q| rnea_unchecked(m, d, q, v, a, fext));
    Ok(())
}

/// `rnea` without the argument check.
pub(crate) fn rnea_unchecked(m: &Model, d: &mut Data, q: &[f64], v: &[f64], a: &[f64], fext: Option<&[f64]>) {
    forward_kinematics_unchecked(m, d, q);
    let ag = gravity_acceleration(m);
    for i in 0..m.nbodies() {
        let vj = joint_velocity(m, d, i, v);
        let aj = joint_velocity(m, d, i, a) + joint_bias(m, d, i, v);
        let (vp, ap) = match m.parents[i] {
            Some(p) => (d.li_mi[i].inv_act_motion(&d.v[p]), d.li_mi[i].inv_act_motion(&d.a[p])),
            None => (Motion::ZERO, d.li_mi[i].inv_act_motion(&ag)),
        };
        let vi = vp + vj;
        d.v[i] = vi;
        d.a[i] = ap + aj + vi.cross_motion(&vj);
        let inr = &m.inertias[i];
        d.f[i] = inr.mul_motion(&d.a[i]) + vi.cross_force(&inr.mul_motion(&vi)) - fext_of(fext, i);
    }
    for i in (0..m.nbodies()).rev() {
        let s = &d.s[i];
        let f6 = d.f[i].to_v6();
        for c in 0..m.nvs[i] {
            d.tau[m.idx_v[i] + c] = s.column(c).dot(&f6);
        }
        if let Some(p) = m.parents[i] {
            let fp = d.li_mi[i].act_force(&d.f[i]);
            d.f[p] += fp;
        }
    }
}
