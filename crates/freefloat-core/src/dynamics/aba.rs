use super::{fext_of, gravity_acceleration};
use crate::data::Data;
use crate::error::{FfError, Result};
use crate::kinematics::{forward_kinematics, joint_velocity};
use crate::model::Model;
use crate::spatial::{m6_mul_motion, transform_inertia_to_parent, Force, Motion, M6, V6};
use nalgebra::Matrix3;

/// Joints whose motion is imposed: `mask[i]` for body i's joint, with accelerations taken from
/// `ddq` (length nv) at that joint's velocity indices.
#[derive(Clone, Copy)]
pub struct Prescribed<'a> {
    pub mask: &'a [bool],
    pub ddq: &'a [f64],
}

/// Forward dynamics by the articulated-body algorithm: `d.ddq = M⁻¹(τ − h + Σ Jᵢᵀ fextᵢ)`.
pub fn aba(m: &Model, d: &mut Data, q: &[f64], v: &[f64], tau: &[f64], fext: Option<&[f64]>) -> Result<()> {
    hybrid_aba(m, d, q, v, tau, fext, None)
}

/// Hybrid dynamics: the prescribed joints follow the given accelerations while the base and the
/// other joints respond to `tau`. On return `d.ddq` holds all accelerations and `d.tau` all joint
/// forces: `tau` for the free joints, the force each prescribed joint needed for the others.
/// (Featherstone's hybrid ABA: a prescribed joint passes its whole articulated inertia to the parent,
/// together with the bias force of its known acceleration.)
pub fn hybrid_aba(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    presc: Option<Prescribed>,
) -> Result<()> {
    let n = m.nbodies();
    let is_presc = |i: usize| presc.map(|p| p.mask[i]).unwrap_or(false);
    forward_kinematics(m, d, q);

    // Pass 1: velocities, velocity-product accelerations, bias forces.
    for i in 0..n {
        let vj = joint_velocity(m, i, v);
        let vi = match m.parents[i] {
            Some(p) => d.li_mi[i].inv_act_motion(&d.v[p]) + vj,
            None => vj,
        };
        d.v[i] = vi;
        d.c[i] = vi.cross_motion(&vj);
        let inr = &m.inertias[i];
        d.ia[i] = inr.to_matrix();
        d.f[i] = vi.cross_force(&inr.mul_motion(&vi)) - fext_of(fext, i);
    }

    // Pass 2: articulated inertias and bias forces, leaves to root.
    for i in (0..n).rev() {
        let k = m.nvs[i];
        let s = &m.subspaces[i];
        let (ia_a, pa) = if k > 0 && !is_presc(i) {
            let ia = &d.ia[i];
            let mut u = M6::zeros();
            for c in 0..k {
                u.set_column(c, &(ia * s.column(c)));
            }
            let mut dm = M6::zeros();
            for r in 0..k {
                for c in 0..k {
                    dm[(r, c)] = s.column(r).dot(&u.column(c));
                }
            }
            let dinv = small_spd_inverse(&dm, k).ok_or_else(|| {
                FfError::Numerical(format!(
                    "joint '{}': its articulated inertia about the joint is singular (massless or degenerate subtree)",
                    m.joint_names[i]
                ))
            })?;
            let pa6 = d.f[i].to_v6();
            let mut uu = [0.0; 6];
            for c in 0..k {
                uu[c] = tau[m.idx_v[i] + c] - s.column(c).dot(&pa6);
            }
            d.u[i] = u;
            d.dinv[i] = dinv;
            d.uu[i] = uu;
            if m.parents[i].is_none() {
                continue;
            }
            // U D⁻¹ (6 × k), then I^a = I^A − U D⁻¹ Uᵀ and p^a = p^A + I^a c + U D⁻¹ u.
            let mut ud = M6::zeros();
            for r in 0..6 {
                for c in 0..k {
                    ud[(r, c)] = (0..k).map(|t| u[(r, t)] * dinv[(t, c)]).sum();
                }
            }
            let mut ia_a = *ia;
            for r in 0..6 {
                for c in 0..6 {
                    ia_a[(r, c)] -= (0..k).map(|t| ud[(r, t)] * u[(c, t)]).sum::<f64>();
                }
            }
            let mut udu = V6::zeros();
            for t in 0..k {
                udu += ud.column(t) * uu[t];
            }
            let pa = d.f[i] + m6_mul_motion(&ia_a, &d.c[i]) + Force::from_v6(&udu);
            (ia_a, pa)
        } else {
            if m.parents[i].is_none() {
                continue;
            }
            // Fixed or prescribed joint: the child moves with a known relative acceleration.
            let mut ac = d.c[i];
            if k > 0 {
                ac += joint_velocity(m, i, presc.unwrap().ddq);
            }
            (d.ia[i], d.f[i] + m6_mul_motion(&d.ia[i], &ac))
        };
        let p = m.parents[i].unwrap();
        let t = transform_inertia_to_parent(&d.li_mi[i], &ia_a);
        d.ia[p] += t;
        let fp = d.li_mi[i].act_force(&pa);
        d.f[p] += fp;
    }

    // Pass 3: accelerations, root to leaves.
    let ag = gravity_acceleration(m);
    for i in 0..n {
        let k = m.nvs[i];
        let s = &m.subspaces[i];
        let ap = match m.parents[i] {
            Some(p) => d.li_mi[i].inv_act_motion(&d.a[p]),
            None => d.li_mi[i].inv_act_motion(&ag),
        } + d.c[i];
        let iv = m.idx_v[i];
        if k == 0 {
            d.a[i] = ap;
        } else if is_presc(i) {
            let ddq = presc.unwrap().ddq;
            d.a[i] = ap + joint_velocity(m, i, ddq);
            let f = m6_mul_motion(&d.ia[i], &d.a[i]) + d.f[i];
            let f6 = f.to_v6();
            for c in 0..k {
                d.ddq[iv + c] = ddq[iv + c];
                d.tau[iv + c] = s.column(c).dot(&f6);
            }
        } else {
            let a6 = ap.to_v6();
            let mut rhs = [0.0; 6];
            for c in 0..k {
                rhs[c] = d.uu[i][c] - d.u[i].column(c).dot(&a6);
            }
            let mut acc = ap;
            for r in 0..k {
                let x: f64 = (0..k).map(|c| d.dinv[i][(r, c)] * rhs[c]).sum();
                d.ddq[iv + r] = x;
                d.tau[iv + r] = tau[iv + r];
                acc += Motion::from_v6(&(s.column(r) * x));
            }
            d.a[i] = acc;
        }
    }
    Ok(())
}

/// Inverse of the leading k×k block (k ∈ {1, 3, 6}) of a symmetric positive-definite matrix, by
/// Cholesky; `None` if it is not positive definite.
fn small_spd_inverse(dm: &M6, k: usize) -> Option<M6> {
    let mut out = M6::zeros();
    match k {
        1 => {
            if !(dm[(0, 0)] > 0.0) {
                return None;
            }
            out[(0, 0)] = 1.0 / dm[(0, 0)];
        }
        3 => {
            let m3: Matrix3<f64> = dm.fixed_view::<3, 3>(0, 0).into_owned();
            let inv = m3.cholesky()?.inverse();
            out.fixed_view_mut::<3, 3>(0, 0).copy_from(&inv);
        }
        6 => out = dm.cholesky()?.inverse(),
        _ => unreachable!("joints have 1, 3 or 6 velocity coordinates"),
    }
    if out.iter().all(|x| x.is_finite()) {
        Some(out)
    } else {
        None
    }
}

