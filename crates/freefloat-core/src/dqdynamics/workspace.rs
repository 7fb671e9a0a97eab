//! Types shared by the assembly (`system.rs`), the solvers (`tree_solve.rs`) and the condition number
//! (`condition.rs`) of the dual-quaternion dynamics, and the workspace that holds every per-call buffer
//! (`DqData`, owned by `Data::dq`, sized once per model). Keeping them here breaks the former
//! `system.rs` ↔ `tree_solve.rs` dependency cycle: both depend on this module only.

use super::sixvec::M6;
use crate::dualquat::{DualInertia, DualQuat};
use crate::model::Model;
use crate::spatial::{Force, M3, V3, V6};

/// Result of `dq_dynamics` (kept in `Data::dq` and returned by reference).
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
    /// System kinetic energy (2.54), J.
    pub kinetic_energy: f64,
}

impl DqDynamics {
    /// Zeroed outputs sized for `m`.
    pub fn new(m: &Model) -> Self {
        let n = m.nbodies();
        DqDynamics {
            ddq: vec![0.0; m.nv],
            joint_wrenches: vec![Force::ZERO; n],
            reactions: vec![Force::ZERO; n],
            locked_forces: vec![0.0; m.nv],
            momentum: Force::ZERO,
            kinetic_energy: 0.0,
        }
    }

    /// Zero every output, keeping the buffers (resized to `m` if they were not, which allocates only
    /// then).
    pub(crate) fn reset(&mut self, m: &Model) {
        let n = m.nbodies();
        for (x, len) in [(&mut self.ddq, m.nv), (&mut self.locked_forces, m.nv)] {
            x.clear();
            x.resize(len, 0.0);
        }
        for x in [&mut self.joint_wrenches, &mut self.reactions] {
            x.clear();
            x.resize(n, Force::ZERO);
        }
        self.momentum = Force::ZERO;
        self.kinetic_energy = 0.0;
    }
}

/// One joint's rows of the dual-quaternion system (Valverde 2018, (6.13)–(6.23)).
#[derive(Clone, Debug)]
pub(super) struct Joint {
    pub(super) body: usize,
    pub(super) parent: usize,
    /// offset of W̃_j in the unknown vector, and its slots
    pub(super) off: usize,
    pub(super) reaction: &'static [usize],
    pub(super) locked: bool,
    /// q_{J/B} of the child body
    pub(super) align: DualQuat,
    /// `G` of the distal (child) and proximal (parent) body, 6 × r (first r columns used)
    pub(super) g_dist: M6,
    pub(super) g_prox: M6,
    pub(super) ad_out_oj: M6,
    pub(super) ad_in_jo: M6,
    /// joint twist ω^j (6.13) and `x = q*_{j/o_k} ω_k q_{j/o_k}`
    pub(super) twist: V6,
    pub(super) parent_twist_in_j: V6,
    /// twist `[ρ; 0]` of J relative to the child body, in J: zero except for a universal joint, whose J turns
    /// with θ2. Differentiating `ω^j` in a turning J adds `ρ × ω^j` to (6.15)'s `(q* ω_k q) × ω^j` (the
    /// derivative of `Ad_{J←o}` is `−(twist of J relative to o) × Ad_{J←o}`, applied to both bodies' terms).
    pub(super) frame_rate: V6,
    /// actuation wrench in J (zero if locked)
    pub(super) act: V6,
    /// prescribed J-frame twist rate `ω̇_pres` of a locked joint (6.28); locking uses zero
    pub(super) presc: V6,
}

/// Buffers of the tree-sparse block Cholesky (`tree_solve::solve_tree`).
#[derive(Clone, Debug, Default)]
pub(super) struct TreeWork {
    pub(super) eliminated: Vec<bool>,
    pub(super) pivots: Vec<Option<nalgebra::Cholesky<f64, nalgebra::U6>>>,
    /// couplings C[a, j] of joint j to the joints solved before it: flat, joint j owns cstart[j]..cend[j]
    pub(super) coupling: Vec<(usize, M6)>,
    pub(super) cstart: Vec<usize>,
    pub(super) cend: Vec<usize>,
    /// (joint, position in its parent body's list)
    pub(super) rest: Vec<(usize, usize)>,
    /// the solution, one padded 6-vector per joint
    pub(super) x: Vec<V6>,
}

/// Every per-call buffer of `dq_dynamics` (and of the decoupled formulation's output), allocated once per
/// model by `Data::new`; a call after the first allocates nothing (tests/allocations.rs).
#[derive(Clone, Debug)]
pub struct DqData {
    /// Mass properties in each body's CoM frame (None: a fixed root).
    pub(super) inert: Vec<Option<DualInertia>>,
    pub(super) iinv: Vec<M3>,
    pub(super) com: Vec<V3>,
    /// q_{B_i/B_p}, q_{B_i/I}, body twists in B_i, q_{o_i/B_i}, CoM twists
    pub(super) local: Vec<DualQuat>,
    pub(super) pose: Vec<DualQuat>,
    pub(super) tw_b: Vec<V6>,
    pub(super) to_com: Vec<DualQuat>,
    pub(super) tw_o: Vec<V6>,
    /// body right-hand sides B1 (6.22), M⁻¹B1, net wrenches, twist rates
    pub(super) b1: Vec<V6>,
    pub(super) mb1: Vec<V6>,
    pub(super) net: Vec<V6>,
    pub(super) ydot: Vec<V6>,
    pub(super) joints: Vec<Joint>,
    /// reduced right-hand side and solution (R = Σ reaction sizes)
    pub(super) rhs: Vec<f64>,
    pub(super) sol: Vec<f64>,
    /// joints incident to each body (its distal joint first), block offsets, Delassus blocks, M⁻¹G
    pub(super) inc: Vec<Vec<usize>>,
    pub(super) start: Vec<usize>,
    pub(super) blocks: Vec<M6>,
    pub(super) mg: Vec<M6>,
    pub(super) rhs6: Vec<V6>,
    pub(super) tree: TreeWork,
    /// The outputs of the last call.
    pub out: DqDynamics,
}

impl DqData {
    /// Buffers sized for `m` (an upper bound of every length a call needs).
    pub fn new(m: &Model) -> Self {
        let n = m.nbodies();
        let nj = n.saturating_sub(1);
        // each joint is incident to its child and its parent: Σ L_i = 2 nj, Σ L_i² ≤ (1 + max children)·2nj
        let mut inc_len = vec![0usize; n];
        for i in 1..n {
            inc_len[i] += 1;
            if let Some(p) = m.parents[i] {
                inc_len[p] += 1;
            }
        }
        let nblocks: usize = inc_len.iter().map(|l| l * l).sum();
        let maxl = inc_len.iter().copied().max().unwrap_or(0);
        DqData {
            inert: Vec::with_capacity(n),
            iinv: Vec::with_capacity(n),
            com: Vec::with_capacity(n),
            local: Vec::with_capacity(n),
            pose: Vec::with_capacity(n),
            tw_b: Vec::with_capacity(n),
            to_com: Vec::with_capacity(n),
            tw_o: Vec::with_capacity(n),
            b1: Vec::with_capacity(n),
            mb1: Vec::with_capacity(n),
            net: Vec::with_capacity(n),
            ydot: Vec::with_capacity(n),
            joints: Vec::with_capacity(nj),
            rhs: Vec::with_capacity(6 * nj),
            sol: Vec::with_capacity(6 * nj),
            inc: inc_len.iter().map(|&l| Vec::with_capacity(l)).collect(),
            start: Vec::with_capacity(n),
            blocks: Vec::with_capacity(nblocks),
            mg: Vec::with_capacity(maxl),
            rhs6: Vec::with_capacity(nj),
            tree: TreeWork {
                eliminated: Vec::with_capacity(nj),
                pivots: Vec::with_capacity(nj),
                coupling: Vec::with_capacity(nblocks),
                cstart: Vec::with_capacity(nj + 1),
                cend: Vec::with_capacity(nj),
                rest: Vec::with_capacity(maxl),
                x: Vec::with_capacity(nj),
            },
            out: DqDynamics::new(m),
        }
    }
}
