//! Body placements and twists of L samples at once (one sample per lane of [`Lanes<L>`]; four, or eight in code
//! compiled for AVX-512), for passes over many independent samples: the identification's regressor stream.
//! Written for the robots identification is about,
//! a base joint at the root (free, planar or fixed) and, elsewhere, revolute joints about a principal axis of
//! their frame and fixed joints (a captured target); [`Kin::for_model`] says `None` for any other model, whose
//! callers take the one-sample path.
//!
//! Every lane's result is, bit for bit, what `forward_velocities_unchecked` gives for that sample: the same
//! operations in the same order (the root itself goes through the one-sample code, lane by lane). The test below
//! holds the two to equality.

use super::fk::{joint_placement_at, joint_velocity};
use crate::data::Data;
use crate::model::{JointType, Model};
use crate::spatial::lanes::{cross, mat_t_vec, Lanes, Real, Vec3, LANES};
use crate::spatial::so3::quat_rotation_rows;
use crate::spatial::trig::sin_cos_lanes;
use crate::spatial::M6;

/// A joint away from the root, as the L-sample sweep uses it.
struct Joint {
    body: usize,
    parent: usize,
    /// index of the joint angle in q and of its rate in v
    iq: usize,
    iv: usize,
    /// revolute about eₖ: the two columns that turn with the angle, (a, b) = the two others than k, cyclic;
    /// `None`: a fixed joint
    turns: Option<(usize, usize)>,
    /// the joint frame in the parent (a fixed joint: the child frame), rotation by columns, translation
    rot: [[f64; 3]; 3],
    trans: [f64; 3],
    /// the child-frame rotation axis (the angular part of the joint's motion subspace)
    axis: [f64; 3],
}

/// Placements (inertial frame) and body-frame twists of every body for L samples.
pub(crate) struct Kin<const L: usize> {
    /// per body: the columns of its rotation, its origin, its body-frame linear and angular velocity
    pub rot: Vec<[Vec3<Lanes<L>>; 3]>,
    pub pos: Vec<Vec3<Lanes<L>>>,
    pub lin: Vec<Vec3<Lanes<L>>>,
    pub ang: Vec<Vec3<Lanes<L>>>,
    joints: Vec<Joint>,
    /// a free root, in L lanes too; `None`: another base joint, placed by the one-sample code lane by lane
    free_root: Option<FreeRoot>,
}

/// A free root: its q and v offsets, its frame's placement (rotation by columns, translation) and its motion
/// subspace (the columns of `Data::s`).
struct FreeRoot {
    iq: usize,
    iv: usize,
    rot: [[f64; 3]; 3],
    trans: [f64; 3],
    s: [[f64; 6]; 6],
}

/// The four-sample sweep (the x86-64-v3 width).
pub(crate) type Kin4 = Kin<LANES>;

impl<const L: usize> Kin<L> {
    /// The sweep for `m`, or `None` if `m` is not of the kind it handles (see the module's text). `d`: a `Data`
    /// of `m`, whose fixed joint subspaces give the revolute axes.
    pub fn for_model(m: &Model, d: &Data) -> Option<Self> {
        let n = m.nbodies();
        if n == 0 || m.parents[0].is_some() || !m.joint_types[0].is_base() {
            return None;
        }
        let mut joints = Vec::with_capacity(n - 1);
        for i in 1..n {
            let parent = m.parents[i].filter(|&p| p < i)?;
            let (x, turns) = match (m.joint_types[i], m.principal_revolute()[i]) {
                (JointType::Revolute, Some(k)) => (m.placements[i], Some(((k + 1) % 3, (k + 2) % 3))),
                // the child frame in the parent, as the one-sample sweep forms it (it does not depend on q)
                (JointType::Fixed, _) => (joint_placement_at(m, &mut M6::zeros(), i, &m.neutral(), [0.0, 1.0]), None),
                _ => return None,
            };
            let s = &d.s[i];
            joints.push(Joint {
                body: i,
                parent,
                iq: m.idx_q[i],
                iv: m.idx_v[i],
                turns,
                rot: [0, 1, 2].map(|c| [x.rot[(0, c)], x.rot[(1, c)], x.rot[(2, c)]]),
                trans: [x.trans.x, x.trans.y, x.trans.z],
                axis: [s[(3, 0)], s[(4, 0)], s[(5, 0)]],
            });
        }
        let free_root = (m.joint_types[0] == JointType::Free).then(|| {
            let x = &m.placements[0];
            FreeRoot {
                iq: m.idx_q[0],
                iv: m.idx_v[0],
                rot: [0, 1, 2].map(|c| [x.rot[(0, c)], x.rot[(1, c)], x.rot[(2, c)]]),
                trans: [x.trans.x, x.trans.y, x.trans.z],
                s: std::array::from_fn(|c| std::array::from_fn(|r| d.s[0][(r, c)])),
            }
        });
        let z = [Lanes::splat(0.0); 3];
        Some(Kin { rot: vec![[z; 3]; n], pos: vec![z; n], lin: vec![z; n], ang: vec![z; n], joints, free_root })
    }

    /// The placements and twists of the L samples `(q[l], v[l])` (checked: sizes, finite, unit quaternions).
    /// `d` is the model's `Data`, used for the root lane by lane (its placements and twists are left changed).
    /// Inlined into its caller, so that the eight-lane sweep is compiled with the AVX-512 caller's registers.
    #[inline(always)]
    pub fn run(&mut self, m: &Model, d: &mut Data, q: [&[f64]; L], v: [&[f64]; L]) {
        let zero = Lanes::splat(0.0);
        if let Some(r) = &self.free_root {
            // a free root: its joint transform (`JointType::transform`: the quaternion's rotation, the position)
            // placed by the root frame (`Se3::compose`), its twist S v (`joint_velocity`'s sums, from zero)
            let qq = |k: usize| Lanes::from_fn(|l| q[l][r.iq + k]);
            let rq = quat_rotation_rows(qq(3), qq(4), qq(5), qq(6));
            let pr = splat33(&r.rot);
            let col = |c: usize| [rq[0][c], rq[1][c], rq[2][c]];
            self.rot[0] = [
                rotate_add(&pr, &col(0), [zero; 3]),
                rotate_add(&pr, &col(1), [zero; 3]),
                rotate_add(&pr, &col(2), [zero; 3]),
            ];
            self.pos[0] = rotate_add(&pr, &[qq(0), qq(1), qq(2)], splat3(&r.trans));
            let vv = [0, 1, 2, 3, 4, 5].map(|c| Lanes::<L>::from_fn(|l| v[l][r.iv + c]));
            let mut tw = [zero; 6];
            for c in 0..6 {
                for (row, t) in tw.iter_mut().enumerate() {
                    *t = *t + Lanes::splat(r.s[c][row]) * vv[c];
                }
            }
            self.lin[0] = [tw[0], tw[1], tw[2]];
            self.ang[0] = [tw[3], tw[4], tw[5]];
        }
        if self.free_root.is_none() {
            // another base joint: the one-sample code, lane by lane (it is one body of many)
            for l in 0..L {
                let x = joint_placement_at(m, &mut d.s[0], 0, q[l], [0.0, 1.0]);
                let vj = joint_velocity(m, d, 0, v[l]);
                for a in 0..3 {
                    for c in 0..3 {
                        self.rot[0][c][a].0[l] = x.rot[(a, c)];
                    }
                    self.pos[0][a].0[l] = x.trans[a];
                    self.lin[0][a].0[l] = vj.lin[a];
                    self.ang[0][a].0[l] = vj.ang[a];
                }
            }
        }
        for j in &self.joints {
            // the joint in its parent: a revolute one turns the placement's columns a, b by the angle about eₖ
            // (`rotate_about_principal_axis`: a c + b s and b c − a s, one fused multiply-add each)
            let mut lr = splat33(&j.rot);
            let mut qd = Lanes::splat(0.0);
            if let Some((ca, cb)) = j.turns {
                let (s, c) = sin_cos_lanes(Lanes::<L>::from_fn(|l| q[l][j.iq]).0);
                let (s, c) = (Lanes(s), Lanes(c));
                for row in 0..3 {
                    let (a, b) = (Lanes::splat(j.rot[ca][row]), Lanes::splat(j.rot[cb][row]));
                    lr[ca][row] = a.mul_add(c, b * s);
                    lr[cb][row] = b.mul_add(c, -(a * s));
                }
                qd = Lanes::from_fn(|l| v[l][j.iv]);
            }
            // placement in the inertial frame: the parent's composed with the joint's (`Se3::compose`)
            let (rp, tp) = (self.rot[j.parent], self.pos[j.parent]);
            self.rot[j.body] = [
                rotate_add(&rp, &lr[0], [zero; 3]),
                rotate_add(&rp, &lr[1], [zero; 3]),
                rotate_add(&rp, &lr[2], [zero; 3]),
            ];
            self.pos[j.body] = rotate_add(&rp, &splat3(&j.trans), tp);
            // body twist: the parent's carried into the joint frame (`Se3::inv_act_motion`), plus the joint's
            // [0; axis q̇] (`joint_velocity`; a fixed joint's is zero, added as 0 · 0 here and as a zero twist there)
            let (vp, wp) = (self.lin[j.parent], self.ang[j.parent]);
            let t = splat3(&j.trans);
            let tw = cross(&t, &wp);
            let lin = mat_t_vec(&lr, &[vp[0] - tw[0], vp[1] - tw[1], vp[2] - tw[2]]);
            let ang = mat_t_vec(&lr, &wp);
            self.lin[j.body] = [lin[0] + zero, lin[1] + zero, lin[2] + zero];
            let joint = |a: usize| ang[a] + Lanes::splat(j.axis[a]) * qd;
            self.ang[j.body] = [joint(0), joint(1), joint(2)];
        }
    }
}

/// `R x + b` for R by its columns, as `Se3::compose` sums it: `r₂ x₂ + (r₁ x₁ + (r₀ x₀ + b))`, fused.
#[inline(always)]
fn rotate_add<T: Real>(r: &[Vec3<T>; 3], x: &Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    // written out, not `std::array::from_fn` (as `lanes::mat_vec`): with eight lanes that stayed a call
    let row = |a: usize| r[2][a].mul_add(x[2], r[1][a].mul_add(x[1], r[0][a].mul_add(x[0], b[a])));
    [row(0), row(1), row(2)]
}

/// `x` in every lane, entry by entry (written out for the reason of `rotate_add`).
#[inline(always)]
fn splat3<T: Real>(x: &[f64; 3]) -> Vec3<T> {
    [T::splat(x[0]), T::splat(x[1]), T::splat(x[2])]
}

/// [`splat3`] of every column.
#[inline(always)]
fn splat33<T: Real>(x: &[[f64; 3]; 3]) -> [Vec3<T>; 3] {
    [splat3(&x[0]), splat3(&x[1]), splat3(&x[2])]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::forward_velocities_unchecked;
    use crate::model::builtin;

    fn mix(i: usize, j: usize) -> f64 {
        ((i * 37 + j * 101) % 97) as f64 / 97.0 - 0.5
    }

    #[test]
    fn every_lane_is_the_one_sample_sweep_bit_for_bit() {
        // four lanes (the x86-64-v3 width) and eight (the AVX-512 width, here compiled for the baseline: the same
        // operations, so the same bits; the identification's test runs the AVX-512-compiled sweep)
        every_lane::<4>();
        every_lane::<8>();
    }

    fn every_lane<const L: usize>() {
        let (mut handled, mut declined) = (Vec::new(), Vec::new());
        for name in builtin::names() {
            let m = builtin::load(name).unwrap();
            let mut d = Data::new(&m);
            let Some(mut kin) = Kin::<L>::for_model(&m, &d) else {
                // declined only for a joint other than a principal-axis revolute one away from the root
                let other = |i: usize| match m.joint_types[i] {
                    JointType::Revolute => m.principal_revolute()[i].is_none(),
                    t => t != JointType::Fixed,
                };
                assert!((1..m.nbodies()).any(other), "{name} declined");
                declined.push(name);
                continue;
            };
            handled.push(name);
            for round in 0..50 {
                let qs: Vec<Vec<f64>> = (0..L)
                    .map(|l| {
                        let mut q = m.neutral();
                        q.iter_mut().enumerate().for_each(|(k, x)| *x += 4.0 * mix(round * L + l, k));
                        for &(_, o) in m.quaternions() {
                            let nrm = q[o..o + 4].iter().map(|x| x * x).sum::<f64>().sqrt();
                            q[o..o + 4].iter_mut().for_each(|x| *x /= nrm);
                        }
                        q
                    })
                    .collect();
                let vs: Vec<Vec<f64>> =
                    (0..L).map(|l| (0..m.nv).map(|k| 3.0 * mix(round * L + l + 7, k)).collect()).collect();
                kin.run(&m, &mut d, std::array::from_fn(|l| &qs[l][..]), std::array::from_fn(|l| &vs[l][..]));
                for l in 0..L {
                    forward_velocities_unchecked(&m, &mut d, &qs[l], &vs[l]);
                    for b in 0..m.nbodies() {
                        for a in 0..3 {
                            for c in 0..3 {
                                assert_eq!(kin.rot[b][c][a].0[l].to_bits(), d.o_mi[b].rot[(a, c)].to_bits());
                            }
                            assert_eq!(kin.pos[b][a].0[l].to_bits(), d.o_mi[b].trans[a].to_bits(), "{name} {b}");
                            assert_eq!(kin.lin[b][a].0[l].to_bits(), d.v[b].lin[a].to_bits(), "{name} {b}");
                            assert_eq!(kin.ang[b][a].0[l].to_bits(), d.v[b].ang[a].to_bits(), "{name} {b}");
                        }
                    }
                }
            }
        }
        // the identification robots take the four-sample path; the arms with a spherical wrist or a prismatic
        // joint do not
        for name in ["naveen_dual_arm", "naveen_dual_arm_consistent", "zhang2020_3d", "zhang2020_2d_small"] {
            assert!(handled.contains(&name), "{name} is not handled (handled: {handled:?})");
        }
        assert!(!declined.is_empty());
    }
}
