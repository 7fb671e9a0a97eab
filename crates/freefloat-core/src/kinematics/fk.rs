use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::model::{universal_bias, universal_first_axis, JointType, Model};
use crate::spatial::trig::{sin_cos4, LANES};
use crate::spatial::{cross_fma, rotate_about_principal_axis, rotation_about_axis_sc, Motion, Se3, M6, V3};

/// Placements of every body: `li_mi` (in the parent) and `o_mi` (in the inertial frame).
/// Also refreshes the configuration-dependent subspace columns (`d.s`) of universal joints.
/// Checks `q` (size, finiteness, unit quaternions) and that `d` belongs to `m`.
pub fn forward_kinematics(m: &Model, d: &mut Data, q: &[f64]) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::q(q))?;
    with_unit_q(m, d, q, fix, |d, q| forward_kinematics_unchecked(m, d, q));
    Ok(())
}

/// `forward_kinematics` without the argument check (`q` checked and normalised by the caller).
pub(crate) fn forward_kinematics_unchecked(m: &Model, d: &mut Data, q: &[f64]) {
    let n = m.nbodies();
    // The model's per-body vectors have n entries (the builder makes them so); said once, it lets the compiler
    // drop the bounds checks of the loop below. The Data buffers as n-entry slices: their lengths stay in
    // registers instead of being re-read after every store.
    assert!(
        m.parents.len() == n
            && m.idx_q.len() == n
            && m.nqs.len() == n
            && m.joint_types.len() == n
            && m.placements.len() == n
            && m.axes.len() == n
            && m.axes2.len() == n
            && m.principal_revolute().len() == n
    );
    let (li_mi, o_mi, s, sc) = (&mut d.li_mi[..n], &mut d.o_mi[..n], &mut d.s[..n], &mut d.joint_sc[..n]);
    joint_sin_cos(m, q, sc);
    for i in 0..n {
        let li = joint_placement_at(m, &mut s[i], i, q, sc[i]);
        li_mi[i] = li;
        o_mi[i] = match m.parents[i] {
            Some(p) => o_mi[p].compose(&li),
            None => li,
        };
    }
}

/// Sine and cosine of every revolute joint's angle (`[0, 1]` for the other bodies), four bodies per
/// `trig::sin_cos4` call: `sc` must have one entry per body. Run before a kinematic sweep, whose
/// `joint_placement_at` takes body i's entry.
#[inline]
pub(crate) fn joint_sin_cos(m: &Model, q: &[f64], sc: &mut [[f64; 2]]) {
    let n = m.nbodies();
    assert!(sc.len() == n && m.joint_types.len() == n && m.idx_q.len() == n);
    for (b0, chunk) in sc.chunks_mut(LANES).enumerate() {
        let mut x = [0.0; LANES];
        for (l, xl) in x.iter_mut().enumerate().take(chunk.len()) {
            let i = b0 * LANES + l;
            if m.joint_types[i] == JointType::Revolute {
                *xl = q[m.idx_q[i]];
            }
        }
        let (s, c) = sin_cos4(x);
        for (l, out) in chunk.iter_mut().enumerate() {
            *out = [s[l], c[l]];
        }
    }
}

/// Placement of body i in its parent at `q` (the whole configuration), also refreshing body i's subspace buffer
/// `s` (`d.s[i]`) for a universal joint: one step of `forward_kinematics` (and of the CRBA's forward sweep).
/// `sc` is body i's entry of `joint_sin_cos` at this `q` (used by revolute joints).
#[inline(always)]
pub(crate) fn joint_placement_at(m: &Model, s: &mut M6, i: usize, q: &[f64], sc: [f64; 2]) -> Se3 {
    let qi = &q[m.idx_q[i]..m.idx_q[i] + m.nqs[i]];
    let jt = m.joint_types[i];
    if jt == JointType::Universal {
        let s1 = universal_first_axis(&m.axes[i], &m.axes2[i], qi[1]);
        s.fixed_view_mut::<3, 1>(3, 0).copy_from(&s1);
    }
    match jt {
        // a rotation about the joint origin leaves the placement's translation as it is: one 3×3 product
        // about a principal axis eₖ of the joint frame, `P R(eₖ, q)` only mixes two columns of P: 12 products
        // instead of Rodrigues' formula and a dense 3×3 product (what CRBA does too)
        JointType::Revolute => {
            let p = &m.placements[i];
            match m.principal_revolute()[i] {
                Some(k) => Se3::new(rotate_about_principal_axis(&p.rot, k, sc[0], sc[1]), p.trans),
                None => Se3::new(p.rot * rotation_about_axis_sc(&m.axes[i], sc[0], sc[1]), p.trans),
            }
        }
        _ => m.placements[i].compose(&jt.transform(&m.axes[i], &m.axes2[i], qi)),
    }
}

/// Joint twist `S q̇` of body i, child frame (the subspace of the last `forward_kinematics`).
#[inline]
pub(crate) fn joint_velocity(m: &Model, d: &Data, i: usize, qd: &[f64]) -> Motion {
    let s = &d.s[i];
    let k0 = m.idx_v[i];
    // revolute [0; a] and prismatic [a; 0]: one 3-vector scaled, not a 6 × nv product
    match m.joint_types[i] {
        JointType::Revolute => return Motion::new(V3::zeros(), V3::new(s[(3, 0)], s[(4, 0)], s[(5, 0)]) * qd[k0]),
        JointType::Prismatic => return Motion::new(V3::new(s[(0, 0)], s[(1, 0)], s[(2, 0)]) * qd[k0], V3::zeros()),
        _ => {}
    }
    let mut out = [0.0; 6];
    for c in 0..m.nvs[i] {
        let x = qd[k0 + c];
        for r in 0..6 {
            out[r] += s[(r, c)] * x;
        }
    }
    Motion::from_slice(&out)
}

/// Column `c` of joint i's motion subspace in inertial coordinates (about the inertial origin), after
/// `forward_kinematics`. A revolute joint's child-frame column is [0; a], so it is `[p × R a; R a]`, and a
/// prismatic one's [a; 0] gives `[R a; 0]`: one 3×3 product instead of the general motion transform.
#[inline(always)]
pub(crate) fn world_subspace_column(m: &Model, d: &Data, i: usize, c: usize) -> Motion {
    subspace_column_at(m, &d.o_mi[i], &d.s[i], i, c)
}

/// `world_subspace_column` from body i's placement `o` and child-frame subspace `s` (for callers that hold
/// other fields of `Data` borrowed).
#[inline(always)]
pub(crate) fn subspace_column_at(m: &Model, o: &Se3, s: &M6, i: usize, c: usize) -> Motion {
    match m.joint_types[i] {
        JointType::Revolute => {
            // about a principal axis eₖ, R a is column k of R (no product)
            let w = match m.principal_revolute()[i] {
                Some(k) => o.rot.column(k).into_owned(),
                None => o.rot * V3::new(s[(3, 0)], s[(4, 0)], s[(5, 0)]),
            };
            Motion::new(cross_fma(&o.trans, &w), w)
        }
        JointType::Prismatic => Motion::new(o.rot * V3::new(s[(0, 0)], s[(1, 0)], s[(2, 0)]), V3::zeros()),
        _ => o.act_motion(&Motion::from_v6(&s.column(c).into_owned())),
    }
}

/// Joint bias acceleration `Ṡ q̇` of body i, child frame: zero but for a universal joint (RBDA
/// eq. 3.41 `c_J`), after `forward_kinematics`.
#[inline]
pub(crate) fn joint_bias(m: &Model, d: &Data, i: usize, qd: &[f64]) -> Motion {
    joint_bias_at(m, &d.s[i], i, qd)
}

/// `joint_bias` from body i's current child-frame subspace `s` (`d.s[i]`).
#[inline]
pub(crate) fn joint_bias_at(m: &Model, s: &M6, i: usize, qd: &[f64]) -> Motion {
    if m.joint_types[i] != JointType::Universal {
        return Motion::ZERO;
    }
    let k = m.idx_v[i];
    let s1 = V3::new(s[(3, 0)], s[(4, 0)], s[(5, 0)]);
    Motion::new(V3::zeros(), universal_bias(&s1, &m.axes2[i], qd[k], qd[k + 1]))
}

/// Placements and body twists (body frame).
pub fn forward_velocities(m: &Model, d: &mut Data, q: &[f64], v: &[f64]) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::qv(q, v))?;
    with_unit_q(m, d, q, fix, |d, q| forward_velocities_unchecked(m, d, q, v));
    Ok(())
}

/// `forward_velocities` without the argument check.
pub(crate) fn forward_velocities_unchecked(m: &Model, d: &mut Data, q: &[f64], v: &[f64]) {
    forward_kinematics_unchecked(m, d, q);
    for i in 0..m.nbodies() {
        let vj = joint_velocity(m, d, i, v);
        d.v[i] = match m.parents[i] {
            Some(p) => d.li_mi[i].inv_act_motion(&d.v[p]) + vj,
            None => vj,
        };
    }
}

/// Placements, body twists and body spatial accelerations (body frame; gravity NOT included, unlike
/// the accelerations RNEA uses internally). The classical acceleration of a body origin in body
/// axes is given by `classical_acceleration`.
pub fn forward_accelerations(m: &Model, d: &mut Data, q: &[f64], v: &[f64], a: &[f64]) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::qv(q, v).nv("a", a))?;
    with_unit_q(m, d, q, fix, |d, q| forward_accelerations_unchecked(m, d, q, v, a));
    Ok(())
}

/// `forward_accelerations` without the argument check.
pub(crate) fn forward_accelerations_unchecked(m: &Model, d: &mut Data, q: &[f64], v: &[f64], a: &[f64]) {
    forward_kinematics_unchecked(m, d, q);
    for i in 0..m.nbodies() {
        let vj = joint_velocity(m, d, i, v);
        let aj = joint_velocity(m, d, i, a) + joint_bias(m, d, i, v);
        let (vp, ap) = match m.parents[i] {
            Some(p) => (d.li_mi[i].inv_act_motion(&d.v[p]), d.li_mi[i].inv_act_motion(&d.a[p])),
            None => (Motion::ZERO, Motion::ZERO),
        };
        d.v[i] = vp + vj;
        d.a[i] = ap + aj + d.v[i].cross_motion(&vj);
    }
}

/// Classical acceleration of a frame origin from its spatial acceleration and twist (same axes):
/// `a_lin + ω × v_lin`.
pub fn classical_acceleration(a: &Motion, v: &Motion) -> Motion {
    Motion::new(a.lin + v.ang.cross(&v.lin), a.ang)
}
