//! Assembly and solution of the dual-quaternion Newton–Euler system (seed 003, §6.3, (6.17)–(6.27)).
//!
//! Unknowns: every body's CoM-frame twist rate `ẏ_i` and every joint's reduced reaction `W̃_j`. With
//! `G_ij` the map from joint j's reduced wrench to the wrench on body i at its CoM (6.20), the body rows are
//! `M_i (ẏ_i)^s = B1_i + Σ_j G_ij W̃_j` ((2.56) with (6.22)) and the joint rows (6.16) are
//! `Σ_i G_ijᵀ (ẏ_i)^s = B2_j`; we take the constraint selector `Λ_j = V_jᵀ P_swap` (the symmetric variant,
//! digest §2.5), which makes `S21 = G_physᵀ P_swap` because `Ad_inᵀ P_swap = P_swap Ad_out` (power is frame
//! invariant). Eliminating `ẏ` (Schur complement on S11, (6.24)–(6.27)) leaves
//!   `K W̃ = B2 − Σ_i G_iᵀ M_i⁻¹ B1_i`,  `K = Σ_i G_iᵀ M_i⁻¹ G_i = −S21 S11⁻¹ S12`,
//! K symmetric positive definite (the Delassus matrix), solved by Cholesky. K has a block for every pair of
//! joints sharing a body; eliminating joints from the leaves up creates no fill-in (the joint graph of a
//! tree is chordal), see `solve_tree`.

use super::joints::{alignment, motion_slots, slots, swapped};
use crate::dualquat::kinematics::joint_pose;
use crate::dualquat::pose::translation;
use crate::dualquat::{DualInertia, DualQuat};
use crate::error::{FfError, Result};
use crate::model::{JointType, Model};
use crate::spatial::{Force, V3, V6};
use nalgebra::{DMatrix, DVector, Matrix6};

type M6 = Matrix6<f64>;

/// Result of `dq_dynamics`.
#[derive(Clone, Debug, Default)]
pub struct DqDynamics {
    /// Generalized accelerations (nv), the engine's convention.
    pub ddq: Vec<f64>,
    /// Per body: the total wrench its joint transmits onto it (reaction + actuation), child body frame,
    /// about the body origin — the engine's RNEA `f_i`.
    pub joint_wrenches: Vec<Force>,
    /// Per body: the constraint (reaction) part alone, `V_j W̃_j` (for a locked joint: all but the actuated
    /// slots; for a free base: zero), same frame.
    pub reactions: Vec<Force>,
    /// Per body: for locked joints, the generalized force the joint must supply (zero elsewhere), nv.
    pub locked_forces: Vec<f64>,
    /// System dual momentum (2.53) about the inertial origin, inertial axes: [linear; angular].
    pub momentum: Force,
    /// System kinetic energy (2.54).
    pub kinetic_energy: f64,
}

/// The 6×6 restriction of an 8×8 sandwich matrix to the vector slots (1..4, 5..8) — exact for unit q,
/// which maps vector dual quaternions to vector dual quaternions. The thesis' form; kept as the reference
/// the closed forms below are tested against.
pub fn reduce(m: &crate::dualquat::M8) -> M6 {
    const IDX: [usize; 6] = [1, 2, 3, 5, 6, 7];
    M6::from_fn(|r, c| m[(IDX[r], IDX[c])])
}
/// `x ↦ q* x q` ((2.41)/(2.43)) on 6-vectors, in closed form: `[Rᵀ, 0; −Rᵀ[t]ˣ, Rᵀ]` with `R = C(q_r)`,
/// `t = 2 q_d q_r*` — the shifting law `s_r^Y + ε(s_d^Y + r^Y_{X/Y} × s_r^Y)` written as a matrix. It replaces
/// `[[q*]]_L [[q]]_R` (two 8×8 products) in the hot loop.
pub fn ad_in(q: &DualQuat) -> M6 {
    let rt = q.r.rotation_matrix().transpose();
    let t = q.translation();
    let mut m = M6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-rt * crate::spatial::skew(&t)));
    m
}
/// `x ↦ q x q*` ((2.42)/(2.44)) on 6-vectors: `[R, 0; [t]ˣ R, R]`.
pub fn ad_out(q: &DualQuat) -> M6 {
    let r = q.r.rotation_matrix();
    let t = q.translation();
    let mut m = M6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(crate::spatial::skew(&t) * r));
    m
}
/// The swap on 6-vectors: `[a; b] ↦ [b; a]`.
fn swap6(x: &V6) -> V6 {
    V6::new(x[3], x[4], x[5], x[0], x[1], x[2])
}
/// Dual-quaternion cross product (Table 2.4) of two vector dual quaternions as 6-vectors:
/// `(a_r × b_r) + ε(a_d × b_r + a_r × b_d)`.
fn cross6(a: &V6, b: &V6) -> V6 {
    let (ar, ad) = (a.fixed_rows::<3>(0).into_owned(), a.fixed_rows::<3>(3).into_owned());
    let (br, bd) = (b.fixed_rows::<3>(0).into_owned(), b.fixed_rows::<3>(3).into_owned());
    let r = ar.cross(&br);
    let d = ad.cross(&br) + ar.cross(&bd);
    V6::new(r.x, r.y, r.z, d.x, d.y, d.z)
}
/// `M⁻¹ [f; τ] = [f/m; Ī⁻¹τ]`, i.e. `(ẏ)^s` from a wrench (Lemma 3 without the swap).
fn minv(mi: &DualInertia, iinv: &nalgebra::Matrix3<f64>, w: &V6) -> V6 {
    let f = w.fixed_rows::<3>(0) / mi.mass();
    let t = iinv * w.fixed_rows::<3>(3);
    V6::new(f.x, f.y, f.z, t.x, t.y, t.z)
}

struct Joint {
    body: usize,
    parent: usize,
    /// offset of W̃_j in the unknown vector, and its slots
    off: usize,
    reaction: &'static [usize],
    locked: bool,
    /// q_{J/B} of the child body
    align: DualQuat,
    /// `G` of the distal (child) and proximal (parent) body, 6 × r (first r columns used)
    g_dist: M6,
    g_prox: M6,
    ad_out_oj: M6,
    ad_in_jo: M6,
    /// joint twist ω^j (6.13) and `x = q*_{j/o_k} ω_k q_{j/o_k}`
    twist: V6,
    parent_twist_in_j: V6,
    /// actuation wrench in J (zero if locked)
    act: V6,
    /// prescribed J-frame twist rate `ω̇_pres` of a locked joint (6.28); locking uses zero
    presc: V6,
}

/// Forward dynamics and joint wrenches by the dual-quaternion formulation for a tree with a free or fixed
/// base and revolute, prismatic, spherical and fixed joints. `locked[i]` (per body, optional) holds joint i
/// at zero joint acceleration (§6.4); its entry of `tau` is ignored and the force it needs is returned.
/// `fext`: nbodies × 6 body-frame wrenches [force; torque about the body origin], as in the engine.
pub fn dq_dynamics(
    m: &Model,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    locked: Option<&[bool]>,
) -> Result<DqDynamics> {
    dq_dynamics_with(m, q, v, tau, fext, locked, Solver::Tree)
}

/// How the Delassus system `K W̃ = rhs` is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// Assemble the R×R matrix and factor it densely (O(R³)): the thesis' (6.27) as written.
    Dense,
    /// Block elimination from the leaves up with no fill-in (O(number of bodies) for bounded fan-out).
    Tree,
}

/// `dq_dynamics` with a choice of solver (the two agree to round-off; `Dense` is the reference).
pub fn dq_dynamics_with(
    m: &Model,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    locked: Option<&[bool]>,
    solver: Solver,
) -> Result<DqDynamics> {
    solve_system(m, q, v, tau, fext, locked, None, solver, None)
}

/// Hybrid dynamics in the dual-quaternion formulation (§6.4 with the corrected recipe of digest §2.6): the
/// joints flagged in `prescribed` (per body) follow the accelerations `ddq` (their entries of the nv-vector),
/// the others respond to `tau`; `locked_forces` returns what the prescribed joints need. The engine's
/// `hybrid_aba` with the same arguments gives the same result.
pub fn dq_hybrid_dynamics(
    m: &Model,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    prescribed: &[bool],
    ddq: &[f64],
) -> Result<DqDynamics> {
    crate::error::check_vec("ddq", ddq, m.nv)?;
    solve_system(m, q, v, tau, fext, Some(prescribed), Some(ddq), Solver::Tree, None)
}

#[allow(clippy::too_many_arguments)]
fn solve_system(
    m: &Model,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    locked: Option<&[bool]>,
    presc_ddq: Option<&[f64]>,
    solver: Solver,
    cond_out: Option<&mut f64>,
) -> Result<DqDynamics> {
    let n = m.nbodies();
    let mut qbuf = Vec::new();
    let q = m.checked_q(q, &mut qbuf)?;
    crate::error::check_vec("v", v, m.nv)?;
    crate::error::check_vec("tau", tau, m.nv)?;
    if let Some(f) = fext {
        crate::error::check_vec("fext", f, 6 * n)?;
    }
    if let Some(l) = locked {
        if l.len() != n {
            return Err(FfError::arg("locked", format!("expected {n} flags (one per joint), got {}", l.len())));
        }
    }
    let is_locked = |i: usize| locked.map(|l| l[i]).unwrap_or(false);
    let root_fixed = match m.joint_types[0] {
        JointType::Free => false,
        JointType::FixedBase => true,
        other => {
            return Err(FfError::Model(format!(
                "dq_dynamics supports a free or fixed base, not a {} base",
                other.name()
            )))
        }
    };
    if is_locked(0) {
        return Err(FfError::arg("locked", "the base joint cannot be locked (lock the joints of the arm)"));
    }
    // Which bodies carry unknowns: all but a fixed root.
    let dynamic = |i: usize| !(i == 0 && root_fixed);

    // Mass properties in each body's CoM frame o_i (axes of the body frame B_i).
    let mut inert = Vec::with_capacity(n);
    let mut iinv = Vec::with_capacity(n);
    let mut com = Vec::with_capacity(n);
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
    let mut local = Vec::with_capacity(n); // q_{B_i/B_p}
    let mut pose = Vec::with_capacity(n); // q_{B_i/I}
    let mut tw_b: Vec<V6> = Vec::with_capacity(n);
    for i in 0..n {
        let qi = &q[m.idx_q[i]..m.idx_q[i] + m.nqs[i]];
        let l = DualQuat::from_se3(&m.placements[i]).mul(&joint_pose(m.joint_types[i], &m.axes[i], qi)?);
        // joint twist S q̇ in B_i as [ω; v]
        let mut sj = V6::zeros();
        let s = &m.subspaces[i];
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
    let to_com: Vec<DualQuat> = com.iter().map(translation).collect(); // q_{o_i/B_i}
    let tw_o: Vec<V6> = (0..n).map(|i| ad_in(&to_com[i]) * tw_b[i]).collect();

    // Body right-hand sides B1 (6.22): −ω × (M ω^s) + gravity + external + actuation.
    let mut b1 = vec![V6::zeros(); n];
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
    let mut joints: Vec<Joint> = Vec::with_capacity(n.saturating_sub(1));
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
        let align = alignment(kind, &m.axes[i]);
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
            act,
            presc,
        });
        r_total += sl.reaction.len();
    }

    if let Some(c) = cond_out {
        *c = full_system_condition(&joints, &inert, n, r_total);
    }

    // B2 (6.23): Λ_j ((q* ω_k q) × ω^j) + Λ_j ω̇_pres, with Λ_j = V_jᵀ P_swap.
    let mut rhs = DVector::zeros(r_total);
    for j in &joints {
        let c = cross6(&j.parent_twist_in_j, &j.twist) + j.presc;
        for (r, &s) in j.reaction.iter().enumerate() {
            rhs[j.off + r] = c[swapped(s)];
        }
    }
    // rhs −= Σ_i G_ijᵀ M_i⁻¹ B1_i
    let mb1: Vec<V6> = (0..n)
        .map(|i| match &inert[i] {
            Some(mi) => minv(mi, &iinv[i], &b1[i]),
            None => V6::zeros(),
        })
        .collect();
    for j in &joints {
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
    let mut inc: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (jj, j) in joints.iter().enumerate() {
        inc[j.body].push(jj);
        if dynamic(j.parent) {
            inc[j.parent].push(jj);
        }
    }
    let mut start = Vec::with_capacity(n);
    let mut blocks: Vec<M6> = Vec::new();
    let mut mg: Vec<M6> = Vec::new();
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
            for x in &mg {
                blocks.push(gt * x);
            }
        }
    }
    let mut rhs6: Vec<V6> = joints
        .iter()
        .map(|j| {
            let mut x = V6::zeros();
            for c in 0..j.reaction.len() {
                x[c] = rhs[j.off + c];
            }
            x
        })
        .collect();
    let sol = match solver {
        Solver::Dense => {
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
            solve_spd(kmat, rhs)?
        }
        Solver::Tree => {
            let x = solve_tree(&joints, &inc, &start, &mut blocks, &mut rhs6)?;
            let mut out = DVector::zeros(r_total);
            for (j, xj) in joints.iter().zip(&x) {
                for c in 0..j.reaction.len() {
                    out[j.off + c] = xj[c];
                }
            }
            out
        }
    };

    // Body accelerations: (ẏ_i)^s = M_i⁻¹ (B1_i + Σ G W̃).
    let mut net = b1.clone();
    for j in &joints {
        let w = DVector::from_iterator(j.reaction.len(), (0..j.reaction.len()).map(|c| sol[j.off + c]));
        for c in 0..j.reaction.len() {
            net[j.body] += j.g_dist.column(c) * w[c];
            net[j.parent] += j.g_prox.column(c) * w[c];
        }
    }
    let ydot: Vec<V6> = (0..n)
        .map(|i| match &inert[i] {
            Some(mi) => swap6(&minv(mi, &iinv[i], &net[i])),
            None => V6::zeros(),
        })
        .collect();

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
    let mut out = DqDynamics {
        ddq: vec![0.0; m.nv],
        joint_wrenches: vec![Force::ZERO; n],
        reactions: vec![Force::ZERO; n],
        locked_forces: vec![0.0; m.nv],
        momentum: Force::new(h.r.v, h.d.v),
        kinetic_energy: ke,
    };
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
    for j in &joints {
        let i = j.body;
        let k = j.parent;
        // (6.15): ω̇^j = q_{o_i/j} ẏ_i q*_{o_i/j} − q*_{j/o_k} ẏ_k q_{j/o_k} − (q* ω_k q) × ω^j
        let wdot = j.ad_out_oj * ydot[i] - j.ad_in_jo * ydot[k] - cross6(&j.parent_twist_in_j, &j.twist);
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
    Ok(out)
}

/// 2-norm condition number of the thesis' system matrix S (6.17) at configuration `q` (it does not depend
/// on velocities or forces): the quantity of Figs. 5.5 and 7.x. Assembled densely from the same blocks as
/// the solve: `S11 = blkdiag(H(M_i))`, `S12 = −G`, `S21 = Gᵀ P_swap` — the thesis' matrix up to a row
/// permutation of S21 (its E-selector order), which leaves singular values unchanged. The scalar slots the
/// 6-vectors drop are decoupled rows with singular value 1 (the ones of (2.45)), folded in at the end.
pub fn condition_number(m: &Model, q: &[f64]) -> Result<f64> {
    let (v, tau) = (vec![0.0; m.nv], vec![0.0; m.nv]);
    let mut c = f64::NAN;
    solve_system(m, q, &v, &tau, None, None, None, Solver::Tree, Some(&mut c))?;
    Ok(c)
}

fn full_system_condition(joints: &[Joint], inert: &[Option<DualInertia>], n: usize, r_total: usize) -> f64 {
    let mut boff = vec![usize::MAX; n];
    let mut nb = 0;
    for i in 0..n {
        if inert[i].is_some() {
            boff[i] = 6 * nb;
            nb += 1;
        }
    }
    let size = 6 * nb + r_total;
    let mut s = DMatrix::<f64>::zeros(size, size);
    for i in 0..n {
        if let Some(mi) = &inert[i] {
            // H(M) on [ω; v]: M (a)^s = [m v; Ī ω]
            let o = boff[i];
            for k in 0..3 {
                s[(o + k, o + 3 + k)] = mi.mass();
            }
            s.view_mut((o + 3, o), (3, 3)).copy_from(&mi.i_com());
        }
    }
    let p = |g: &M6| -> M6 { M6::from_fn(|r, c| g[((r + 3) % 6, c)]) }; // P_swap G
    for j in joints {
        let r = j.reaction.len();
        for (body, g) in [(j.body, &j.g_dist), (j.parent, &j.g_prox)] {
            if boff[body] == usize::MAX {
                continue;
            }
            let o = boff[body];
            s.view_mut((o, 6 * nb + j.off), (6, r)).copy_from(&(-g.columns(0, r)));
            let pg = p(g);
            s.view_mut((6 * nb + j.off, o), (r, 6)).copy_from(&pg.columns(0, r).transpose());
        }
    }
    let sv = s.singular_values();
    let (mx, mn) = (sv.max().max(1.0), sv.min().min(1.0));
    mx / mn
}

/// Tree-sparse block Cholesky of K. Joint j couples only to joints sharing its child body i (i's children)
/// or its parent body k (k's distal joint and k's other children). Eliminating joints in decreasing index
/// (children before parents) leaves, when j's turn comes, only body i's block of j (its children's Schur
/// updates already folded in) and neighbours that all share body k: their updates land in body k's blocks,
/// so there is no fill-in outside the per-body blocks. Every block is a stack 6×6 (padding dimensions get
/// a unit pivot and stay zero).
fn solve_tree(
    joints: &[Joint],
    inc: &[Vec<usize>],
    start: &[usize],
    blocks: &mut [M6],
    rhs: &mut [V6],
) -> Result<Vec<V6>> {
    let nj = joints.len();
    let singular = || {
        FfError::Numerical("the dual-quaternion constraint system (Delassus matrix) is singular or indefinite".into())
    };
    let mut eliminated = vec![false; nj];
    let mut pivots: Vec<Option<nalgebra::Cholesky<f64, nalgebra::U6>>> = vec![None; nj];
    // couplings C[a, j] of joint j to the joints solved before it: flat, joint j owns cstart[j]..cstart[j+1]
    let mut coupling: Vec<(usize, M6)> = Vec::with_capacity(2 * nj);
    let mut cstart = vec![0; nj + 1];
    let mut cend = vec![0; nj];
    let mut rest: Vec<(usize, usize)> = Vec::new(); // (joint, position in its parent body's list)
    for jj in (0..nj).rev() {
        let (i, k, rj) = (joints[jj].body, joints[jj].parent, joints[jj].reaction.len());
        let mut p = blocks[start[i]];
        rest.clear();
        let (lk, pos) = (inc[k].len(), inc[k].iter().position(|&x| x == jj));
        if let Some(pos) = pos {
            p += blocks[start[k] + pos * lk + pos];
            for (pa, &ja) in inc[k].iter().enumerate() {
                if ja != jj && !eliminated[ja] {
                    rest.push((ja, pa));
                }
            }
        }
        for d in rj..6 {
            p[(d, d)] = 1.0;
        }
        let ch = nalgebra::Cholesky::new(p).ok_or_else(singular)?;
        let y_rhs = ch.solve(&rhs[jj]);
        cstart[jj] = coupling.len();
        if let Some(pos) = pos {
            for &(ja, pa) in &rest {
                let c_a = blocks[start[k] + pa * lk + pos]; // C[a, j]
                let y_a = ch.solve(&c_a.transpose()); // P⁻¹ C[j, a]
                rhs[ja] -= c_a * y_rhs;
                for &(_, pb) in &rest {
                    let c_b = blocks[start[k] + pb * lk + pos];
                    blocks[start[k] + pb * lk + pa] -= c_b * y_a;
                }
                coupling.push((ja, c_a));
            }
        }
        cend[jj] = coupling.len();
        pivots[jj] = Some(ch);
        eliminated[jj] = true;
    }
    cstart[nj] = coupling.len();
    // back substitution, parents first: x_j = P⁻¹ (rhs_j − Σ_a C[a, j]ᵀ x_a)
    let mut x = vec![V6::zeros(); nj];
    for jj in 0..nj {
        let mut b = rhs[jj];
        for (ja, c) in &coupling[cstart[jj]..cend[jj]] {
            b -= c.transpose() * x[*ja];
        }
        x[jj] = pivots[jj].as_ref().ok_or_else(singular)?.solve(&b);
    }
    Ok(x)
}

/// Solve the symmetric positive-definite Delassus system by Cholesky; a failure means dependent constraint
/// rows (e.g. degenerate joint axes) or a non-physical body.
fn solve_spd(k: DMatrix<f64>, rhs: DVector<f64>) -> Result<DVector<f64>> {
    if k.nrows() == 0 {
        return Ok(rhs);
    }
    match k.cholesky() {
        Some(ch) => Ok(ch.solve(&rhs)),
        None => Err(FfError::Numerical(
            "the dual-quaternion constraint system (Delassus matrix) is singular or indefinite".into(),
        )),
    }
}
