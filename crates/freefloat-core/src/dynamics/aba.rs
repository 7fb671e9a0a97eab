use super::gravity_acceleration;
use crate::data::Data;
use crate::error::{FfError, Result};
use crate::kinematics::forward_kinematics;
use crate::model::Model;
use crate::spatial::{Force, Motion, M6, V6};
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
///
/// Featherstone's articulated-body algorithm, in inertial-frame coordinates (all twists at the
/// inertial origin): inertias are expressed there once per body, so passing an articulated inertia
/// to the parent is an addition instead of a 6×6 change of frame. A prescribed joint passes its
/// whole articulated inertia to the parent together with the bias of its known acceleration.
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

    // Pass 1: subspaces, twists, velocity-product accelerations and bias forces, inertial frame.
    for i in 0..n {
        let omi = d.o_mi[i];
        let k = m.nvs[i];
        let iv = m.idx_v[i];
        let mut vj = Motion::ZERO;
        for c in 0..k {
            let s = omi.act_motion(&Motion::from_v6(&m.subspaces[i].column(c).into_owned()));
            d.os[i].set_column(c, &s.to_v6());
            vj += s * v[iv + c];
        }
        let vi = match m.parents[i] {
            Some(p) => d.ov[p] + vj,
            None => vj,
        };
        d.ov[i] = vi;
        // d/dt(oS q̇) with S fixed in the body: v × (oS q̇).
        d.oc[i] = vi.cross_motion(&vj);
        let oi = m.inertias[i].transformed(&omi);
        d.ia[i] = oi.to_matrix();
        let mut f = vi.cross_force(&oi.mul_motion(&vi));
        if let Some(fe) = fext {
            f -= omi.act_force(&Force::from_slice(&fe[6 * i..6 * i + 6]));
        }
        d.of[i] = f;
    }

    // Pass 2: articulated inertias and bias forces, leaves to root.
    for i in (0..n).rev() {
        let k = m.nvs[i];
        let iv = m.idx_v[i];
        let parent = m.parents[i];
        if k > 0 && !is_presc(i) {
            let s = &d.os[i];
            let ia = d.ia[i];
            let pa6 = d.of[i].to_v6();
            if k == 1 {
                // Single-DoF joint: rank-one update.
                let s0 = s.column(0).into_owned();
                let u = ia * s0;
                let dd = s0.dot(&u);
                if !(dd > 0.0) || !dd.is_finite() {
                    return Err(singular(m, i));
                }
                let uu = tau[iv] - s0.dot(&pa6);
                d.u[i].set_column(0, &u);
                d.dinv[i][(0, 0)] = 1.0 / dd;
                d.uu[i][0] = uu;
                if let Some(p) = parent {
                    let ia_a = ia - u * (u.transpose() / dd);
                    let pa = pa6 + ia_a * d.oc[i].to_v6() + u * (uu / dd);
                    d.ia[p] += ia_a;
                    d.of[p] += Force::from_v6(&pa);
                }
                continue;
            }
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
            let dinv = small_spd_inverse(&dm, k).ok_or_else(|| singular(m, i))?;
            let mut uu = [0.0; 6];
            for c in 0..k {
                uu[c] = tau[iv + c] - s.column(c).dot(&pa6);
            }
            d.u[i] = u;
            d.dinv[i] = dinv;
            d.uu[i] = uu;
            let Some(p) = parent else { continue };
            // U D⁻¹ (6 × k), then I^a = I^A − U D⁻¹ Uᵀ and p^a = p^A + I^a c + U D⁻¹ u.
            let mut ud = M6::zeros();
            for r in 0..6 {
                for c in 0..k {
                    ud[(r, c)] = (0..k).map(|t| u[(r, t)] * dinv[(t, c)]).sum();
                }
            }
            let mut ia_a = ia;
            for r in 0..6 {
                for c in 0..6 {
                    ia_a[(r, c)] -= (0..k).map(|t| ud[(r, t)] * u[(c, t)]).sum::<f64>();
                }
            }
            let mut pa = pa6 + ia_a * d.oc[i].to_v6();
            for t in 0..k {
                pa += ud.column(t) * uu[t];
            }
            d.ia[p] += ia_a;
            d.of[p] += Force::from_v6(&pa);
        } else if let Some(p) = parent {
            // Fixed or prescribed joint: the child moves with a known relative acceleration.
            let mut ac = d.oc[i].to_v6();
            if k > 0 {
                let ddq = presc.unwrap().ddq;
                for c in 0..k {
                    ac += d.os[i].column(c) * ddq[iv + c];
                }
            }
            let pa = d.of[i].to_v6() + d.ia[i] * ac;
            let ia = d.ia[i];
            d.ia[p] += ia;
            d.of[p] += Force::from_v6(&pa);
        }
    }

    // Pass 3: accelerations, root to leaves.
    let ag = gravity_acceleration(m).to_v6();
    for i in 0..n {
        let k = m.nvs[i];
        let iv = m.idx_v[i];
        let s = &d.os[i];
        let mut a = match m.parents[i] {
            Some(p) => d.oa[p].to_v6(),
            None => ag,
        } + d.oc[i].to_v6();
        if k == 0 {
        } else if is_presc(i) {
            let ddq = presc.unwrap().ddq;
            for c in 0..k {
                a += s.column(c) * ddq[iv + c];
            }
            let f: V6 = d.ia[i] * a + d.of[i].to_v6();
            for c in 0..k {
                d.ddq[iv + c] = ddq[iv + c];
                d.tau[iv + c] = s.column(c).dot(&f);
            }
        } else {
            let mut rhs = [0.0; 6];
            for c in 0..k {
                rhs[c] = d.uu[i][c] - d.u[i].column(c).dot(&a);
            }
            for r in 0..k {
                let x: f64 = (0..k).map(|c| d.dinv[i][(r, c)] * rhs[c]).sum();
                d.ddq[iv + r] = x;
                d.tau[iv + r] = tau[iv + r];
                a += s.column(r) * x;
            }
        }
        d.oa[i] = Motion::from_v6(&a);
    }
    Ok(())
}

fn singular(m: &Model, i: usize) -> FfError {
    FfError::Numerical(format!(
        "joint '{}': its articulated inertia about the joint is singular (massless or degenerate subtree)",
        m.joint_names[i]
    ))
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
