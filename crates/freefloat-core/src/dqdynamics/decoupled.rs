//! The decoupled Newton–Euler formulation of Valverde 2018, §5.1 (after Stoneking [94]), generalised
//! from the chapter-5 chain to trees: per body the CoM-frame Newton and Euler equations (5.1)–(5.8) with the
//! rotations the thesis leaves implicit made explicit; per joint the "joint-point accelerations are equal"
//! linear constraint (5.20) and the angular constraint (5.29)/(5.33) projected off the joint axis. Plain
//! 3-vectors and rotation matrices, no dual quaternions: it is the independent formulation the thesis compares
//! the dual-quaternion one with. Unknowns `[v̇_i, ω̇_i]` (CoM velocity and angular velocity, body axes,
//! component derivatives) and the reaction components; solved by the Schur complement of the block-diagonal
//! mass rows and a dense LU of the R×R remainder (5.138)–(5.139).
//!
//! Joints: revolute (reaction: force + torque ⊥ axis), spherical (force), prismatic (force ⊥ axis + torque;
//! the linear constraint carries the Coriolis term `2 ω_k × ṡ a`), fixed (force + torque); free or fixed base.

use super::workspace::DqDynamics;
use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::error::{FfError, Result};
use crate::kinematics::forward_velocities_unchecked;
use crate::model::{JointType, Model};
use crate::spatial::{skew, Force, M3, V3};
use nalgebra::{DMatrix, DVector};

/// `x[o..o+3] += v`.
fn add3(x: &mut DVector<f64>, o: usize, v: &V3) {
    for k in 0..3 {
        x[o + k] += v[k];
    }
}

/// Two unit vectors spanning the plane ⊥ `a` (rows of the thesis' E₂₃ for a z axis).
fn perp(a: &V3) -> [V3; 2] {
    let t = if a.x.abs() < 0.9 { V3::x() } else { V3::y() };
    let e1 = a.cross(&t).normalize();
    [e1, a.cross(&e1)]
}

struct J {
    d: usize,
    k: usize,
    kind: JointType,
    /// R_j = R_{d/k}: k coordinates → d coordinates
    r: M3,
    /// joint point from each CoM: distal (d axes), proximal (k axes)
    rd: V3,
    rk: V3,
    /// axis in d axes (unit)
    a: V3,
    /// reaction bases (d axes): f = bf λ_f, τ = bt λ_t
    bf: Vec<V3>,
    bt: Vec<V3>,
    off: usize,
}

/// Forward dynamics and joint wrenches by the decoupled formulation; same conventions and output as
/// `dq_dynamics` (`reactions` holds the constraint parts; `locked_forces`, `momentum` and `kinetic_energy`
/// are not computed here and stay zero). The result is `d.dq.out`, returned by reference. Checks every
/// argument. The dense reference solve allocates its matrices (this formulation is a cross-check, not a
/// hot path).
pub fn decoupled_dynamics<'d>(
    m: &Model,
    d: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
) -> Result<&'d DqDynamics> {
    let fix = check_args(m, Some(d), &Args::qv(q, v).nv("tau", tau).fext(fext))?;
    let out = with_unit_q(m, d, q, fix, |d, q| decoupled_unchecked(m, d, q, v, tau, fext))?;
    d.dq.out = out;
    Ok(&d.dq.out)
}

fn decoupled_unchecked(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
) -> Result<DqDynamics> {
    let n = m.nbodies();
    let root_fixed = match m.joint_types[0] {
        JointType::Free => false,
        JointType::FixedBase => true,
        other => {
            return Err(FfError::Model(format!(
                "the decoupled formulation supports a free or fixed base, not {}",
                other.name()
            )))
        }
    };
    forward_velocities_unchecked(m, d, q, v);
    // body unknown offsets (a fixed root has none)
    let mut boff = vec![usize::MAX; n];
    let mut nb = 0;
    for i in 0..n {
        if !(i == 0 && root_fixed) {
            boff[i] = 6 * nb;
            nb += 1;
        }
    }
    let com: Vec<V3> = m.inertias.iter().map(|x| if x.mass > 0.0 { x.com() } else { V3::zeros() }).collect();
    let mut mass = vec![0.0; n];
    let mut ic = vec![M3::zeros(); n];
    let mut icinv = vec![M3::zeros(); n];
    for i in 0..n {
        if boff[i] == usize::MAX {
            continue;
        }
        let inr = &m.inertias[i];
        mass[i] = inr.mass;
        ic[i] = inr.i_com();
        let inv = if inr.mass > 0.0 { ic[i].cholesky().map(|c| c.inverse()) } else { None };
        icinv[i] = inv.ok_or_else(|| {
            FfError::Model(format!(
                "body '{}' needs a positive mass and inertia in the decoupled formulation",
                m.body_names[i]
            ))
        })?;
    }
    // CoM twists (body axes)
    let w: Vec<V3> = (0..n).map(|i| d.v[i].ang).collect();
    let vo: Vec<V3> = (0..n).map(|i| d.v[i].lin + d.v[i].ang.cross(&com[i])).collect();

    // joints
    let mut joints = Vec::new();
    let mut rr = 0;
    for i in 1..n {
        let k = m.parents[i].ok_or_else(|| FfError::Model("one root expected".into()))?;
        let x = &d.li_mi[i]; // B_i in B_k
        let kind = m.joint_types[i];
        let a = m.axes[i].normalize();
        let e = perp(&a);
        let all = vec![V3::x(), V3::y(), V3::z()];
        let (bf, bt) = match kind {
            JointType::Revolute => (all.clone(), e.to_vec()),
            JointType::Spherical => (all.clone(), vec![]),
            JointType::Prismatic => (e.to_vec(), all.clone()),
            // free rotation about and translation along a: both constraints projected off the axis
            JointType::Cylindrical => (e.to_vec(), e.to_vec()),
            JointType::Fixed => (all.clone(), all.clone()),
            // its blocked rotation direction turns with θ2: not derived for this formulation
            JointType::Universal => {
                return Err(FfError::Model(format!(
                    "joint '{}': the decoupled formulation does not support universal joints; use the \
                     dual-quaternion formulation (formulation=\"dq\")",
                    m.joint_names[i]
                )))
            }
            other => return Err(FfError::Model(format!("joint type {} is not supported", other.name()))),
        };
        let len = bf.len() + bt.len();
        joints.push(J { d: i, k, kind, r: x.rot.transpose(), rd: -com[i], rk: x.trans - com[k], a, bf, bt, off: rr });
        rr += len;
    }
    let size_y = 6 * nb;
    // S11 is block diagonal: diag(m I, Ī); S12 (6nb × R), S21 (R × 6nb), b1, b2
    let mut s12 = DMatrix::zeros(size_y, rr);
    let mut s21 = DMatrix::zeros(rr, size_y);
    let mut b1 = DVector::zeros(size_y);
    let mut b2 = DVector::zeros(rr);
    let grav = |i: usize| d.o_mi[i].rot.transpose() * m.gravity;
    for i in 0..n {
        if boff[i] == usize::MAX {
            continue;
        }
        let o = boff[i];
        // −ω×mv + m g + fext (shifted to the CoM); −ω×Īω
        let mut f = -w[i].cross(&(vo[i] * mass[i])) + grav(i) * mass[i];
        let mut t = -w[i].cross(&(ic[i] * w[i]));
        if let Some(fe) = fext {
            let (ff, tt) = (
                V3::new(fe[6 * i], fe[6 * i + 1], fe[6 * i + 2]),
                V3::new(fe[6 * i + 3], fe[6 * i + 4], fe[6 * i + 5]),
            );
            f += ff;
            t += tt - com[i].cross(&ff);
        }
        if i == 0 && !root_fixed {
            let (ff, tt) = (V3::new(tau[0], tau[1], tau[2]), V3::new(tau[3], tau[4], tau[5]));
            f += ff;
            t += tt - com[0].cross(&ff);
        }
        add3(&mut b1, o, &f);
        add3(&mut b1, o + 3, &t);
    }
    for j in &joints {
        let (od, ok) = (boff[j.d], boff[j.k]);
        let rt = j.r.transpose();
        // reaction columns: body rows (moved to the left-hand side: S12 = −contribution)
        let mut c = j.off;
        for e in &j.bf {
            let f_d = *e;
            let (fd, td) = (f_d, j.rd.cross(&f_d));
            s12.fixed_view_mut::<3, 1>(od, c).copy_from(&(-fd));
            s12.fixed_view_mut::<3, 1>(od + 3, c).copy_from(&(-td));
            if ok != usize::MAX {
                let fk = rt * f_d;
                s12.fixed_view_mut::<3, 1>(ok, c).copy_from(&fk);
                s12.fixed_view_mut::<3, 1>(ok + 3, c).copy_from(&j.rk.cross(&fk));
            }
            c += 1;
        }
        for e in &j.bt {
            s12.fixed_view_mut::<3, 1>(od + 3, c).copy_from(&(-*e));
            if ok != usize::MAX {
                s12.fixed_view_mut::<3, 1>(ok + 3, c).copy_from(&(rt * e));
            }
            c += 1;
        }
        // actuation: a torque about the axis (R), a torque vector (S), a force along the axis (P)
        let iv = m.idx_v[j.d];
        let (fa, ta) = match j.kind {
            JointType::Revolute => (V3::zeros(), j.a * tau[iv]),
            JointType::Spherical => (V3::zeros(), V3::new(tau[iv], tau[iv + 1], tau[iv + 2])),
            JointType::Prismatic => (j.a * tau[iv], V3::zeros()),
            JointType::Cylindrical => (j.a * tau[iv + 1], j.a * tau[iv]),
            _ => (V3::zeros(), V3::zeros()),
        };
        add3(&mut b1, od, &fa);
        add3(&mut b1, od + 3, &(ta + j.rd.cross(&fa)));
        if ok != usize::MAX {
            let (fk, tk) = (rt * fa, rt * ta);
            add3(&mut b1, ok, &(-fk));
            add3(&mut b1, ok + 3, &(-(tk + j.rk.cross(&fk))));
        }
        // constraint rows, k axes for the linear one (5.20), d axes for the angular one (5.29)/(5.33)
        let (wk, wd, vk, vd) = (w[j.k], w[j.d], vo[j.k], vo[j.d]);
        let ak = rt * j.a;
        let lin_rows: Vec<V3> = match j.kind {
            JointType::Prismatic | JointType::Cylindrical => perp(&ak).to_vec(),
            _ => vec![V3::x(), V3::y(), V3::z()],
        };
        // sliding rate along a (its Coriolis term 2 ω_k × ṡ a enters the linear constraint)
        let sdot = match j.kind {
            JointType::Prismatic => v[iv],
            JointType::Cylindrical => v[iv + 1],
            _ => 0.0,
        };
        let lin_rhs = wk.cross(&vk) + wk.cross(&wk.cross(&j.rk)) + wk.cross(&(ak * (2.0 * sdot)))
            - rt * (wd.cross(&vd) + wd.cross(&wd.cross(&j.rd)));
        let mut row = j.off;
        for e in &lin_rows {
            // eᵀ[Rᵀ(v̇_d + ω̇_d × r_d) − v̇_k − ω̇_k × r_k]
            let et_rt = (j.r * e).transpose(); // eᵀ Rᵀ
            s21.fixed_view_mut::<1, 3>(row, od).copy_from(&et_rt);
            s21.fixed_view_mut::<1, 3>(row, od + 3).copy_from(&(-et_rt * skew(&j.rd)));
            if ok != usize::MAX {
                s21.fixed_view_mut::<1, 3>(row, ok).copy_from(&(-e.transpose()));
                s21.fixed_view_mut::<1, 3>(row, ok + 3).copy_from(&(e.transpose() * skew(&j.rk)));
            }
            b2[row] = e.dot(&lin_rhs);
            row += 1;
        }
        let ang_rows: Vec<V3> = match j.kind {
            JointType::Revolute | JointType::Cylindrical => perp(&j.a).to_vec(),
            JointType::Spherical => vec![],
            _ => vec![V3::x(), V3::y(), V3::z()],
        };
        let w_rel_k = rt * wd - wk;
        let ang_rhs = j.r * wk.cross(&w_rel_k);
        for e in &ang_rows {
            // eᵀ[ω̇_d − R ω̇_k] = eᵀ R(ω_k × ω_rel)
            s21.fixed_view_mut::<1, 3>(row, od + 3).copy_from(&e.transpose());
            if ok != usize::MAX {
                s21.fixed_view_mut::<1, 3>(row, ok + 3).copy_from(&(-e.transpose() * j.r));
            }
            b2[row] = e.dot(&ang_rhs);
            row += 1;
        }
        debug_assert_eq!(row, j.off + j.bf.len() + j.bt.len());
    }
    // S11⁻¹ applied blockwise
    let s11_inv = |x: &DVector<f64>| -> DVector<f64> {
        let mut y = x.clone();
        for i in 0..n {
            if boff[i] == usize::MAX {
                continue;
            }
            let o = boff[i];
            let f = x.fixed_rows::<3>(o) / mass[i];
            let t = icinv[i] * x.fixed_rows::<3>(o + 3);
            y.fixed_rows_mut::<3>(o).copy_from(&f);
            y.fixed_rows_mut::<3>(o + 3).copy_from(&t);
        }
        y
    };
    let mut s11i_s12 = DMatrix::zeros(size_y, rr);
    for c in 0..rr {
        s11i_s12.set_column(c, &s11_inv(&s12.column(c).into_owned()));
    }
    let a = &s21 * &s11i_s12;
    let rhs = &s21 * s11_inv(&b1) - &b2;
    let lam =
        a.lu().solve(&rhs).ok_or_else(|| FfError::Numerical("the decoupled constraint system is singular".into()))?;
    let y = s11_inv(&(&b1 - &s12 * &lam));

    let mut out = DqDynamics {
        ddq: vec![0.0; m.nv],
        joint_wrenches: vec![Force::ZERO; n],
        reactions: vec![Force::ZERO; n],
        locked_forces: vec![0.0; m.nv],
        momentum: Force::ZERO,
        kinetic_energy: 0.0,
    };
    let yb = |i: usize| -> (V3, V3) {
        if boff[i] == usize::MAX {
            (V3::zeros(), V3::zeros())
        } else {
            (y.fixed_rows::<3>(boff[i]).into_owned(), y.fixed_rows::<3>(boff[i] + 3).into_owned())
        }
    };
    if !root_fixed {
        let (vdot, wdot) = yb(0);
        let vb = vdot - wdot.cross(&com[0]);
        out.ddq[0..3].copy_from_slice(vb.as_slice());
        out.ddq[3..6].copy_from_slice(wdot.as_slice());
        out.joint_wrenches[0] = Force::from_slice(&tau[0..6]);
    }
    for j in &joints {
        let ((vdk, wdk), (vdd, wdd)) = (yb(j.k), yb(j.d));
        let iv = m.idx_v[j.d];
        let rt = j.r.transpose();
        let w_rel_k = rt * w[j.d] - w[j.k];
        let ang = wdd - j.r * (wdk + w[j.k].cross(&w_rel_k)); // (5.29): the joint's angular acceleration, d axes
        match j.kind {
            JointType::Revolute => out.ddq[iv] = j.a.dot(&ang),
            JointType::Spherical => out.ddq[iv..iv + 3].copy_from_slice(ang.as_slice()),
            JointType::Prismatic | JointType::Cylindrical => {
                // s̈ a = Rᵀ a_point_d − a_point_k − 2 ω_k × ṡ a  (k axes)
                let (wk, wd) = (w[j.k], w[j.d]);
                let apd = vdd + wd.cross(&vo[j.d]) + wdd.cross(&j.rd) + wd.cross(&wd.cross(&j.rd));
                let apk = vdk + wk.cross(&vo[j.k]) + wdk.cross(&j.rk) + wk.cross(&wk.cross(&j.rk));
                let ak = rt * j.a;
                let is = if j.kind == JointType::Cylindrical { iv + 1 } else { iv };
                out.ddq[is] = ak.dot(&(rt * apd - apk - wk.cross(&(ak * (2.0 * v[is])))));
                if j.kind == JointType::Cylindrical {
                    out.ddq[iv] = j.a.dot(&ang);
                }
            }
            _ => {}
        }
        let mut f = V3::zeros();
        let mut t = V3::zeros();
        for (c, e) in j.bf.iter().enumerate() {
            f += e * lam[j.off + c];
        }
        for (c, e) in j.bt.iter().enumerate() {
            t += e * lam[j.off + j.bf.len() + c];
        }
        out.reactions[j.d] = Force::new(f, t);
        let (fa, ta) = match j.kind {
            JointType::Revolute => (V3::zeros(), j.a * tau[iv]),
            JointType::Spherical => (V3::zeros(), V3::new(tau[iv], tau[iv + 1], tau[iv + 2])),
            JointType::Prismatic => (j.a * tau[iv], V3::zeros()),
            JointType::Cylindrical => (j.a * tau[iv + 1], j.a * tau[iv]),
            _ => (V3::zeros(), V3::zeros()),
        };
        out.joint_wrenches[j.d] = Force::new(f + fa, t + ta);
    }
    if root_fixed {
        // the ground's wrench on the root at its origin: minus everything else acting on it (it does not move)
        let (mut f, mut t) = (V3::zeros(), V3::zeros());
        let r0 = d.o_mi[0].rot.transpose() * m.gravity * m.inertias[0].mass;
        f -= r0;
        t -= com[0].cross(&r0);
        if let Some(fe) = fext {
            f -= V3::new(fe[0], fe[1], fe[2]);
            t -= V3::new(fe[3], fe[4], fe[5]);
        }
        for j in joints.iter().filter(|j| j.k == 0) {
            let w = out.joint_wrenches[j.d];
            let x = &d.li_mi[j.d];
            let fk = x.rot * w.lin;
            f += fk;
            t += x.rot * w.ang + x.trans.cross(&fk);
        }
        out.joint_wrenches[0] = Force::new(f, t);
        out.reactions[0] = out.joint_wrenches[0];
    }
    Ok(out)
}
