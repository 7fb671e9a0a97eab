//! Assembly and solution of the dual-quaternion Newton–Euler system (Valverde 2018, §6.3, (6.17)–(6.27)).
//!
//! Unknowns: every body's CoM-frame twist rate `ẏ_i` and every joint's reduced reaction `W̃_j`. With
//! `G_ij` the map from joint j's reduced wrench to the wrench on body i at its CoM (6.20), the body rows are
//! `M_i (ẏ_i)^s = B1_i + Σ_j G_ij W̃_j` ((2.56) with (6.22)) and the joint rows (6.16) are
//! `Σ_i G_ijᵀ (ẏ_i)^s = B2_j`; we take the constraint selector `Λ_j = V_jᵀ P_swap` (the symmetric variant:
//! as assembled, (6.21)'s `S21 S11⁻¹ S12` is not symmetric), which makes `S21 = G_physᵀ P_swap` because
//! `Ad_inᵀ P_swap = P_swap Ad_out` (power is frame invariant). Eliminating `ẏ` (Schur complement on S11,
//! (6.24)–(6.27)) leaves
//!   `K W̃ = B2 − Σ_i G_iᵀ M_i⁻¹ B1_i`,  `K = Σ_i G_iᵀ M_i⁻¹ G_i = −S21 S11⁻¹ S12`,
//! K symmetric positive definite (the Delassus matrix), solved by Cholesky. K has a block for every pair of
//! joints sharing a body; eliminating joints from the leaves up creates no fill-in (the joint graph of a
//! tree is chordal), see `solve_tree`.

use super::joints::{alignment, motion_slots, slots, swapped, universal_alignment, universal_frame_rate};
use super::sixvec::{ad_in, ad_out, cross6, minv, swap6, M6};
use super::tree_solve::{solve_spd, solve_tree};
use super::workspace::{DqData, DqDynamics, Joint};
use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::dualquat::kinematics::joint_pose;
use crate::dualquat::pose::translation;
use crate::dualquat::{DualInertia, DualQuat};
use crate::error::{FfError, Result};
use crate::model::{universal_first_axis, JointType, Model};
use crate::spatial::{Force, V3, V6};
use nalgebra::{DMatrix, DVector};

/// Forward dynamics and joint wrenches by the dual-quaternion formulation for a tree with a free or fixed
/// base and revolute, prismatic, spherical and fixed joints. `locked[i]` (per body, optional) holds joint i
/// at zero joint acceleration (§6.4); its entry of `tau` is ignored and the force it needs is returned.
/// `fext`: nbodies × 6 body-frame wrenches [force; torque about the body origin], as in the engine.
/// Every buffer is `d.dq`'s and the result is `d.dq.out` (returned by reference): a call allocates nothing.
/// Checks every argument (sizes, finiteness, unit quaternions, `locked` one flag per body, `d` made for `m`).
pub fn dq_dynamics<'d>(
    m: &Model,
    d: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    locked: Option<&[bool]>,
) -> Result<&'d DqDynamics> {
    dq_dynamics_with(m, d, q, v, tau, fext, locked, Solver::Tree)
}

/// How the Delassus system `K W̃ = rhs` is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// Assemble the R×R matrix and factor it densely (O(R³)): the thesis' (6.27) as written.
    Dense,
    /// Block elimination from the leaves up with no fill-in (O(number of bodies) for bounded fan-out).
    Tree,
}

/// `dq_dynamics` with a choice of solver (the two agree to round-off; `Dense` is the reference and
/// allocates its R×R matrix).
#[allow(clippy::too_many_arguments)]
pub fn dq_dynamics_with<'d>(
    m: &Model,
    d: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    locked: Option<&[bool]>,
    solver: Solver,
) -> Result<&'d DqDynamics> {
    let mut args = Args::qv(q, v).nv("tau", tau).fext(fext);
    if let Some(l) = locked {
        args = args.mask("locked", l);
    }
    let fix = check_args(m, Some(d), &args)?;
    with_unit_q(m, d, q, fix, |d, q| solve_system(m, &mut d.dq, q, v, tau, fext, locked, None, solver, None))?;
    Ok(&d.dq.out)
}

/// Hybrid dynamics in the dual-quaternion formulation (§6.4, corrected: the printed
/// recipe deletes the prescribed joint's distal body from the unknowns without substituting its
/// acceleration (6.31), which drops that body's inertia and ignores the prescribed acceleration in the joint's
/// constraint rows; here a prescribed joint constrains all six slots, its prescribed acceleration enters B2,
/// and its actuation is the actuated part of that six-slot reaction, see docs/architecture.md): the
/// joints flagged in `prescribed` (per body) follow the accelerations `ddq` (their entries of the nv-vector),
/// the others respond to `tau`; `locked_forces` returns what the prescribed joints need. The engine's
/// `hybrid_aba` with the same arguments gives the same result. Checks every argument; allocates nothing.
#[allow(clippy::too_many_arguments)]
pub fn dq_hybrid_dynamics<'d>(
    m: &Model,
    d: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    prescribed: &[bool],
    ddq: &[f64],
) -> Result<&'d DqDynamics> {
    let args = Args::qv(q, v).nv("tau", tau).nv("ddq", ddq).fext(fext).mask("locked", prescribed);
    let fix = check_args(m, Some(d), &args)?;
    with_unit_q(m, d, q, fix, |d, q| {
        solve_system(m, &mut d.dq, q, v, tau, fext, Some(prescribed), Some(ddq), Solver::Tree, None)
    })?;
    Ok(&d.dq.out)
}

/// `dq_dynamics`/`dq_hybrid_dynamics` without the argument check, for the simulator's stages: `locked` is
/// the prescribed mask with `presc_ddq` its accelerations (or None).
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_system_unchecked(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    locked: Option<&[bool]>,
    presc_ddq: Option<&[f64]>,
) -> Result<()> {
    solve_system(m, &mut d.dq, q, v, tau, fext, locked, presc_ddq, Solver::Tree, None)
}

/// The system of (6.17) assembled and solved in `w` (arguments already checked, `q` normalised). The
/// result is `w.out`. `cond_out`: also the condition number of the full system (allocates; not a hot path).
#[allow(clippy::too_many_arguments)]
pub(super) fn solve_system(
    m: &Model,
    w: &mut DqData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    locked: Option<&[bool]>,
    presc_ddq: Option<&[f64]>,
    solver: Solver,
    cond_out: Option<&mut f64>,
) -> Result<()> {
    let n = m.nbodies();
    let DqData {
        inert,
        iinv,
        com,
        local,
        pose,
        tw_b,
        to_com,
        tw_o,
        b1,
        mb1,
        net,
        ydot,
        joints,
        rhs,
        sol,
        inc,
        start,
        blocks,
        mg,
        rhs6,
        tree,
        out,
    } = w;
    let is_locked = |i: usize| locked.and_then(|l| l.get(i).copied()).unwrap_or(false);
    let root_fixed = match m.joint_types.first() {
        Some(JointType::Free) => false,
        Some(JointType::FixedBase) => true,
        other => {
            return Err(FfError::Model(format!(
                "dq_dynamics supports a free or fixed base, not a {} base",
                other.map(|j| j.name()).unwrap_or("missing")
            )))
        }
    };
    if is_locked(0) {
        return Err(FfError::arg("locked", "the base joint cannot be locked (lock the joints of the arm)"));
    }
    // Which bodies carry unknowns: all but a fixed root.
    let dynamic = |i: usize| !(i == 0 && root_fixed);

    // Mass properties in each body's CoM frame o_i (axes of the body frame B_i).
    inert.clear();
    iinv.clear();
    com.clear();
    for i in 0..n {
        let inr = &m.inertias[i];
        com.push(if inr.mass > 0.0 { inr.com() } else { V3::zeros() });
        if !dynamic(i) {
            inert.push(None);
            iinv.push(nalgebra::Matrix3::zeros());
            continue;
        }
        let di = DualInertia::from_inertia(inr).map_err(|e| {
            FfError::Model(format!(
                "body '{}' cannot enter the dual-quaternion formulation, which needs H(M)⁻¹ for every moving body: {e}",
                m.body_names[i]
            ))
        })?;
        iinv.push(di.i_com_inverse());
        inert.push(Some(di));
    }

    // Kinematics in dual-quaternion form: poses (3.43), CoM twists via (2.43).
    local.clear(); // q_{B_i/B_p}
    pose.clear(); // q_{B_i/I}
    tw_b.clear();
    for i in 0..n {
        let qi = &q[m.idx_q[i]..m.idx_q[i] + m.nqs[i]];
        let l = DualQuat::from_se3(&m.placements[i]).mul(&joint_pose(m.joint_types[i], &m.axes[i], &m.axes2[i], qi)?);
        // joint twist S q̇ in B_i as [ω; v]
        let mut sj = V6::zeros();
        let mut s = m.subspaces[i];
        if m.joint_types[i] == JointType::Universal {
            // the first column turns with θ2 (the engine refreshes it in forward kinematics)
            s.fixed_view_mut::<3, 1>(3, 0).copy_from(&universal_first_axis(&m.axes[i], &m.axes2[i], qi[1]));
        }
        for c in 0..m.nvs[i] {
            let x = v[m.idx_v[i] + c];
            for r in 0..3 {
                sj[r] += s[(r + 3, c)] * x;
                sj[r + 3] += s[(r, c)] * x;
            }
        }
        let (p, t) = match m.parents[i] {
            Some(p) => (pose[p], ad_in(&l) * tw_b[p] + sj),
            None => (DualQuat::ONE, sj),
        };
        pose.push(p.mul(&l));
        tw_b.push(t);
        local.push(l);
    }
    to_com.clear();
    to_com.extend(com.iter().map(translation)); // q_{o_i/B_i}
    tw_o.clear();
    tw_o.extend((0..n).map(|i| ad_in(&to_com[i]) * tw_b[i]));

    // Body right-hand sides B1 (6.22): −ω × (M ω^s) + gravity + external + actuation.
    b1.clear();
    b1.resize(n, V6::zeros());
    for i in 0..n {
        let w = &tw_o[i];
        if let Some(mi) = &inert[i] {
            let h = mi.apply(&crate::dualquat::DualQuat::vector(
                &w.fixed_rows::<3>(3).into_owned(),
                &w.fixed_rows::<3>(0).into_owned(),
            ));
            b1[i] -= cross6(w, &V6::new(h.r.v.x, h.r.v.y, h.r.v.z, h.d.v.x, h.d.v.y, h.d.v.z));
        }
        // gravity m g at the CoM, o_i coordinates
        let g = pose[i].r.conj().rotate(&m.gravity) * m.inertias[i].mass;
        b1[i] += V6::new(g.x, g.y, g.z, 0.0, 0.0, 0.0);
        if let Some(f) = fext {
            let fe = &f[6 * i..6 * i + 6];
            b1[i] += ad_in(&to_com[i]) * V6::from_column_slice(fe);
        }
    }
    if !root_fixed {
        // free-base actuation: a wrench on the base at its origin, base axes
        b1[0] += ad_in(&to_com[0]) * V6::from_column_slice(&tau[0..6]);
    }

    // Joints.
    joints.clear();
    let mut r_total = 0;
    for i in 1..n {
        let Some(k) = m.parents[i] else {
            return Err(FfError::Model(format!(
                "body '{}' has no parent; dq_dynamics needs one root",
                m.body_names[i]
            )));
        };
        let kind = m.joint_types[i];
        let lk = is_locked(i);
        let sl = slots(kind, lk);
        let (align, frame_rate) = if kind == JointType::Universal {
            let iq = m.idx_q[i];
            (universal_alignment(&m.axes[i], &m.axes2[i], q[iq + 1]), universal_frame_rate(v[m.idx_v[i] + 1]))
        } else {
            (alignment(kind, &m.axes[i]), V6::zeros())
        };
        let q_jo = to_com[k].conj().mul(&local[i]).mul(&align); // q_{j/o_k}
        let q_oj = align.conj().mul(&to_com[i]); // q_{o_i/j}
        let (ad_out_oj, ad_in_oj) = (ad_out(&q_oj), ad_in(&q_oj));
        let (ad_in_jo, ad_out_jo) = (ad_in(&q_jo), ad_out(&q_jo));
        let mut g_dist = M6::zeros();
        let mut g_prox = M6::zeros();
        for (c, &s) in sl.reaction.iter().enumerate() {
            g_dist.set_column(c, &ad_in_oj.column(s));
            g_prox.set_column(c, &(-ad_out_jo.column(s)));
        }
        // joint twist (6.13) and the parent twist seen in J
        let parent_twist_in_j = ad_in_jo * tw_o[k];
        let twist = ad_out_oj * tw_o[i] - parent_twist_in_j;
        // actuation (Table 6.3): the swaps of the motion slots carry tau
        let mut act = V6::zeros();
        if !lk {
            for (c, &s) in motion_slots(kind).iter().enumerate() {
                act[swapped(s)] = tau[m.idx_v[i] + c];
            }
            b1[i] += ad_in_oj * act;
            b1[k] -= ad_out_jo * act;
        }
        // prescribed joint-frame twist rate ω̇_pres (6.28): the prescribed accelerations on the motion slots
        let mut presc = V6::zeros();
        if let (true, Some(a)) = (lk, presc_ddq) {
            for (c, &s) in motion_slots(kind).iter().enumerate() {
                presc[s] = a[m.idx_v[i] + c];
            }
        }
        joints.push(Joint {
            body: i,
            parent: k,
            off: r_total,
            reaction: sl.reaction,
            locked: lk,
            align,
            g_dist,
            g_prox,
            ad_out_oj,
            ad_in_jo,
            twist,
            parent_twist_in_j,
            frame_rate,
            act,
            presc,
        });
        r_total += sl.reaction.len();
    }

    if let Some(c) = cond_out {
        *c = super::condition::full_system_condition(joints, inert, n, r_total);
    }

    // B2 (6.23): Λ_j ((q* ω_k q) × ω^j) + Λ_j ω̇_pres, with Λ_j = V_jᵀ P_swap.
    rhs.clear();
    rhs.resize(r_total, 0.0);
    for j in joints.iter() {
        let c = cross6(&(j.parent_twist_in_j + j.frame_rate), &j.twist) + j.presc;
        for (r, &s) in j.reaction.iter().enumerate() {
            rhs[j.off + r] = c[swapped(s)];
        }
    }
    // rhs −= Σ_i G_ijᵀ M_i⁻¹ B1_i
    mb1.clear();
    mb1.extend((0..n).map(|i| match &inert[i] {
        Some(mi) => minv(mi, &iinv[i], &b1[i]),
        None => V6::zeros(),
    }));
    for j in joints.iter() {
        let r = j.reaction.len();
        for c in 0..r {
            let mut x = j.g_dist.column(c).dot(&mb1[j.body]);
            if dynamic(j.parent) {
                x += j.g_prox.column(c).dot(&mb1[j.parent]);
            }
            rhs[j.off + c] -= x;
        }
    }

    // Delassus matrix K = Σ_i G_iᵀ M_i⁻¹ G_i as 6×6 blocks (each reduced reaction padded to 6 by the zero
    // columns of its G), one set per body over the joints incident to it: its distal joint first, then its
    // children. Block (b, a) of body i is `blocks[start[i] + b·L_i + a]`.
    inc.resize_with(n, Vec::new);
    for x in inc.iter_mut() {
        x.clear();
    }
    for (jj, j) in joints.iter().enumerate() {
        inc[j.body].push(jj);
        if dynamic(j.parent) {
            inc[j.parent].push(jj);
        }
    }
    start.clear();
    blocks.clear();
    for i in 0..n {
        start.push(blocks.len());
        let Some(mi) = &inert[i] else { continue };
        let g_of = |jj: usize| if joints[jj].body == i { &joints[jj].g_dist } else { &joints[jj].g_prox };
        mg.clear();
        for &ja in &inc[i] {
            // M⁻¹ G = [G_top / m; Ī⁻¹ G_bottom]
            let g = g_of(ja);
            let mut x = *g / mi.mass();
            x.fixed_rows_mut::<3>(3).copy_from(&(iinv[i] * g.fixed_rows::<3>(3)));
            mg.push(x);
        }
        for &jb in &inc[i] {
            let gt = g_of(jb).transpose();
            for x in mg.iter() {
                blocks.push(gt * x);
            }
        }
    }
    sol.clear();
    sol.resize(r_total, 0.0);
    match solver {
        Solver::Dense => {
            // the reference: assembles the R×R matrix (allocates)
            let mut kmat = DMatrix::zeros(r_total, r_total);
            for i in 0..n {
                let l = inc[i].len();
                for (pb, &jb) in inc[i].iter().enumerate() {
                    for (pa, &ja) in inc[i].iter().enumerate() {
                        let (ra, rb) = (joints[ja].reaction.len(), joints[jb].reaction.len());
                        let blk = blocks[start[i] + pb * l + pa].view((0, 0), (rb, ra)).clone_owned();
                        let mut dst = kmat.view_mut((joints[jb].off, joints[ja].off), (rb, ra));
                        dst += blk;
                    }
                }
            }
            let x = solve_spd(kmat, DVector::from_column_slice(rhs))?;
            sol.copy_from_slice(x.as_slice());
        }
        Solver::Tree => {
            rhs6.clear();
            rhs6.extend(joints.iter().map(|j| {
                let mut x = V6::zeros();
                for c in 0..j.reaction.len() {
                    x[c] = rhs[j.off + c];
                }
                x
            }));
            solve_tree(joints, inc, start, blocks, rhs6, tree)?;
            for (j, xj) in joints.iter().zip(&tree.x) {
                for c in 0..j.reaction.len() {
                    sol[j.off + c] = xj[c];
                }
            }
        }
    }

    // Body accelerations: (ẏ_i)^s = M_i⁻¹ (B1_i + Σ G W̃).
    net.clear();
    net.extend_from_slice(b1);
    for j in joints.iter() {
        for c in 0..j.reaction.len() {
            let wc = sol[j.off + c];
            net[j.body] += j.g_dist.column(c) * wc;
            net[j.parent] += j.g_prox.column(c) * wc;
        }
    }
    ydot.clear();
    ydot.extend((0..n).map(|i| match &inert[i] {
        Some(mi) => swap6(&minv(mi, &iinv[i], &net[i])),
        None => V6::zeros(),
    }));

    // Generalized accelerations.
    // (2.53) and (2.54) from the CoM poses q_{o_i/I} and twists
    let mut h = DualQuat::ZERO;
    let mut ke = 0.0;
    for i in 0..n {
        if let Some(mi) = &inert[i] {
            let w =
                DualQuat::vector(&tw_o[i].fixed_rows::<3>(0).into_owned(), &tw_o[i].fixed_rows::<3>(3).into_owned());
            h = h + pose[i].mul(&to_com[i]).shift_out(&mi.momentum(&w));
            ke += mi.kinetic_energy(&w);
        }
    }
    out.reset(m);
    out.momentum = Force::new(h.r.v, h.d.v);
    out.kinetic_energy = ke;
    if !root_fixed {
        // base: ẏ_0 = [ω̇; v̇_o], v_o = v_b + ω × c ⇒ v̇_b = v̇_o − ω̇ × c (c constant in the body)
        let wd = ydot[0].fixed_rows::<3>(0).into_owned();
        let vd = ydot[0].fixed_rows::<3>(3).into_owned() - wd.cross(&com[0]);
        out.ddq[0..3].copy_from_slice(vd.as_slice());
        out.ddq[3..6].copy_from_slice(wd.as_slice());
        out.joint_wrenches[0] = Force::from_slice(&tau[0..6]);
    } else {
        // the ground's wrench on a fixed root: everything else on it, negated (its ẏ is zero)
        let w = -net[0];
        out.joint_wrenches[0] = Force::from_v6(&(ad_out(&to_com[0]) * w));
        out.reactions[0] = out.joint_wrenches[0];
    }
    for j in joints.iter() {
        let i = j.body;
        let k = j.parent;
        // (6.15): ω̇^j = q_{o_i/j} ẏ_i q*_{o_i/j} − q*_{j/o_k} ẏ_k q_{j/o_k} − (q* ω_k q) × ω^j
        let wdot =
            j.ad_out_oj * ydot[i] - j.ad_in_jo * ydot[k] - cross6(&(j.parent_twist_in_j + j.frame_rate), &j.twist);
        for (c, &s) in motion_slots(m.joint_types[i]).iter().enumerate() {
            out.ddq[m.idx_v[i] + c] = if j.locked { j.presc[s] } else { wdot[s] };
        }
        // wrenches in J, then in the child body frame (rotation only, same origin); our wrench 6-vector
        // [f; τ] is the engine's Force [force; moment]
        let mut react = V6::zeros();
        for (c, &s) in j.reaction.iter().enumerate() {
            react[s] = sol[j.off + c];
        }
        let total = react + j.act;
        let ad = ad_out(&j.align);
        out.joint_wrenches[i] = Force::from_v6(&(ad * total));
        let mut pure = react;
        if j.locked {
            for (c, &s) in motion_slots(m.joint_types[i]).iter().enumerate() {
                out.locked_forces[m.idx_v[i] + c] = react[swapped(s)];
                pure[swapped(s)] = 0.0;
            }
        }
        out.reactions[i] = Force::from_v6(&(ad * pure));
    }
    Ok(())
}

/// 2-norm condition number of the thesis' system matrix S (6.17) at configuration `q` (it does not depend
/// on velocities or forces): the quantity of Figs. 5.5 and 7.x. Assembled densely from the same blocks as
/// the solve: `S11 = blkdiag(H(M_i))`, `S12 = −G`, `S21 = Gᵀ P_swap` — the thesis' matrix up to a row
/// permutation of S21 (its E-selector order), which leaves singular values unchanged. The scalar slots the
/// 6-vectors drop are decoupled rows with singular value 1 (the ones of (2.45)), folded in at the end.
/// Checks `q`. Allocates its own workspace and the dense matrix (an analysis routine, not a hot path).
pub fn condition_number(m: &Model, q: &[f64]) -> Result<f64> {
    let mut qbuf = Vec::new();
    check_args(m, None, &Args::q(q))?;
    let q = m.checked_q(q, &mut qbuf)?;
    let (v, tau) = (vec![0.0; m.nv], vec![0.0; m.nv]);
    let mut c = f64::NAN;
    let mut w = DqData::new(m);
    solve_system(m, &mut w, q, &v, &tau, None, None, None, Solver::Tree, Some(&mut c))?;
    Ok(c)
}
