//! `Data`: every work buffer the algorithms need, allocated once per model (Model/Data split).

use crate::dqdynamics::DqData;
use crate::error::{FfError, Result};
use crate::model::Model;
use crate::spatial::{Force, Inertia, Motion, Se3, M6};
use nalgebra::DMatrix;

/// Work buffers and outputs of the algorithms for one model (make it with `Data::new(&model)`).
#[derive(Clone, Debug)]
pub struct Data {
    /// Placement of body i in its parent (joint placement ∘ joint motion).
    pub li_mi: Vec<Se3>,
    /// Placement of body i in the inertial frame.
    pub o_mi: Vec<Se3>,
    /// Body twists, body frame (forward velocities, RNEA).
    pub v: Vec<Motion>,
    /// Body spatial accelerations, body frame (RNEA: gravity included as a fictitious base
    /// acceleration; `forward_accelerations`: without gravity).
    pub a: Vec<Motion>,
    /// RNEA: force transmitted by each joint to its child, body frame.
    pub f: Vec<Force>,
    /// Articulated-body inertias (ABA; inertial-frame coordinates).
    pub ia: Vec<M6>,
    /// ABA works in inertial-frame coordinates (twists and accelerations at the inertial origin):
    /// body twists, accelerations, velocity-product terms and bias forces there.
    pub ov: Vec<Motion>,
    /// ABA: body spatial accelerations at the inertial origin, inertial axes (gravity included).
    pub oa: Vec<Motion>,
    /// ABA: velocity-product accelerations `v × (oS q̇) + o(Ṡ q̇)`, inertial frame.
    pub oc: Vec<Motion>,
    /// ABA: bias forces (then articulated bias forces), inertial frame.
    pub of: Vec<Force>,
    /// Sine and cosine of each revolute joint's angle at the last kinematic sweep (`[0, 1]` for other joints),
    /// computed four joints at a time before the sweep (`spatial::trig`).
    pub joint_sc: Vec<[f64; 2]>,
    /// Motion subspace of each joint in its child frame at the last `forward_kinematics` call: a copy
    /// of `Model::subspaces`, whose universal-joint columns forward kinematics refreshes.
    pub s: Vec<M6>,
    /// Motion subspace of each joint in inertial coordinates (nv columns used; ABA, CRBA).
    pub os: Vec<M6>,
    /// By-products of ABA's first pass: total momentum (about the inertial origin, inertial frame)
    /// and kinetic energy at the state it was called with.
    pub aba_momentum: Force,
    /// ABA's by-product: kinetic energy (J) at the state it was called with.
    pub aba_kinetic_energy: f64,
    /// ABA's by-product: the power (W) of the external wrenches `fext` it was called with on the bodies' twists
    /// (zero without them); every call sets it.
    pub aba_fext_power: f64,
    /// `U = I^A S`, one 6×nv block per joint (unused columns zero).
    pub u: Vec<M6>,
    /// `D⁻¹ = (Sᵀ U)⁻¹`, top-left nv×nv block (for a multi-DoF root: D itself, solved in place).
    pub dinv: Vec<M6>,
    /// `u = τ - Sᵀ p^A`, first nv entries.
    pub uu: Vec<[f64; 6]>,
    /// Composite rigid-body inertias of subtrees, inertial frame (CRBA, centroidal momentum matrix).
    pub ic: Vec<Inertia>,
    /// Joint accelerations (ABA output).
    pub ddq: Vec<f64>,
    /// Joint forces (RNEA output; hybrid dynamics: the torques the prescribed joints needed).
    pub tau: Vec<f64>,
    /// Joint-space inertia matrix (CRBA output, full symmetric). The only nv × nv buffer: it is empty (0 × 0)
    /// until the first call that needs it (CRBA and what uses it), so loading a model with tens of thousands of
    /// bodies and running ABA or RNEA on it costs memory linear in the number of bodies.
    pub mass_matrix: DMatrix<f64>,
    /// 6×nv scratch for Jacobians and the centroidal momentum matrix.
    pub jac: DMatrix<f64>,
    /// Normalised copy of q when the caller's quaternions were off by round-off.
    pub qbuf: Vec<f64>,
    /// Workspace and outputs of the dual-quaternion dynamics (`dqdynamics::dq_dynamics`) and of the
    /// decoupled formulation.
    pub dq: DqData,
    /// Identity of the model this Data was made for (`Model::id`), checked by every entry point.
    model_id: u64,
}

impl Data {
    /// Every buffer sized for `m`, stamped with `m`'s identity.
    pub fn new(m: &Model) -> Data {
        let n = m.nbodies();
        Data {
            li_mi: vec![Se3::identity(); n],
            o_mi: vec![Se3::identity(); n],
            v: vec![Motion::ZERO; n],
            a: vec![Motion::ZERO; n],
            f: vec![Force::ZERO; n],
            ia: vec![M6::zeros(); n],
            ov: vec![Motion::ZERO; n],
            oa: vec![Motion::ZERO; n],
            oc: vec![Motion::ZERO; n],
            of: vec![Force::ZERO; n],
            joint_sc: vec![[0.0, 1.0]; n],
            s: m.subspaces.clone(),
            os: vec![M6::zeros(); n],
            aba_momentum: Force::ZERO,
            aba_kinetic_energy: 0.0,
            aba_fext_power: 0.0,
            u: vec![M6::zeros(); n],
            dinv: vec![M6::zeros(); n],
            uu: vec![[0.0; 6]; n],
            ic: vec![Inertia::zero(); n],
            ddq: vec![0.0; m.nv],
            tau: vec![0.0; m.nv],
            mass_matrix: DMatrix::zeros(0, 0),
            jac: DMatrix::zeros(6, m.nv),
            qbuf: Vec::with_capacity(m.nq),
            dq: DqData::new(m),
            model_id: m.id(),
        }
    }

    /// Every buffer sized for `m` as `Data::new` makes them, but with fallible reservation: a model too large for
    /// the memory at hand gives an error naming the size instead of aborting the process.
    pub fn try_new(m: &Model) -> Result<Data> {
        let n = m.nbodies();
        // The per-body buffers dominate (about 2 kB per body); reserve their total up front to fail cleanly.
        let per_body = 2 * std::mem::size_of::<Se3>()
            + 6 * std::mem::size_of::<Motion>()
            + 2 * std::mem::size_of::<Force>()
            + 5 * std::mem::size_of::<M6>()
            + std::mem::size_of::<[f64; 6]>()
            + std::mem::size_of::<[f64; 2]>()
            + std::mem::size_of::<Inertia>();
        let bytes = n.checked_mul(per_body).ok_or_else(|| too_big(m, usize::MAX))?;
        let mut probe: Vec<u8> = Vec::new();
        probe.try_reserve_exact(bytes).map_err(|_| too_big(m, bytes))?;
        drop(probe);
        Ok(Data::new(m))
    }

    /// Allocate the nv × nv mass matrix on first use (fallible reservation: a clear error, never an abort, when
    /// nv² numbers do not fit in memory). A no-op once allocated.
    pub fn ensure_mass_matrix(&mut self, m: &Model) -> Result<()> {
        if self.mass_matrix.shape() == (m.nv, m.nv) {
            return Ok(());
        }
        let len = m.nv.checked_mul(m.nv).ok_or_else(|| too_big_matrix(m))?;
        // Linux overcommits: a reservation larger than the free memory can succeed and the process is killed when
        // the zeros are written. Refuse up front when /proc/meminfo says it cannot fit.
        if let Some(avail) = available_memory_bytes() {
            if (len as u64).saturating_mul(8) > avail {
                return Err(too_big_matrix(m));
            }
        }
        let mut buf: Vec<f64> = Vec::new();
        buf.try_reserve_exact(len).map_err(|_| too_big_matrix(m))?;
        buf.resize(len, 0.0);
        self.mass_matrix = DMatrix::from_vec(m.nv, m.nv, buf);
        Ok(())
    }

    /// Identity of the model this Data was made for (see `check::check_data`).
    pub fn model_id(&self) -> u64 {
        self.model_id
    }

    /// Whether every buffer still has the size `Data::new(m)` gave it (the fields are public, so a
    /// caller may have replaced one). O(1): a few length comparisons.
    pub fn sized_for(&self, m: &Model) -> bool {
        let n = m.nbodies();
        let per_body = [
            self.li_mi.len(),
            self.o_mi.len(),
            self.v.len(),
            self.a.len(),
            self.f.len(),
            self.ia.len(),
            self.ov.len(),
            self.oa.len(),
            self.oc.len(),
            self.of.len(),
            self.joint_sc.len(),
            self.s.len(),
            self.os.len(),
            self.u.len(),
            self.dinv.len(),
            self.uu.len(),
            self.ic.len(),
        ];
        per_body.iter().all(|&l| l == n)
            && self.ddq.len() == m.nv
            && self.tau.len() == m.nv
            && (self.mass_matrix.shape() == (m.nv, m.nv) || self.mass_matrix.shape() == (0, 0))
            && self.jac.shape() == (6, m.nv)
    }
}

fn too_big(m: &Model, bytes: usize) -> FfError {
    FfError::Numerical(format!(
        "model '{}' has {} bodies: its work buffers need {:.1} GB, more than this machine can allocate",
        m.name,
        m.nbodies(),
        bytes as f64 / 1e9
    ))
}

fn too_big_matrix(m: &Model) -> FfError {
    let gb = (m.nv as f64).powi(2) * 8.0 / 1e9;
    FfError::Numerical(format!(
        "model '{}' has nv = {}: its {} x {} joint-space inertia matrix needs {gb:.1} GB, more than this machine can \
         allocate (ABA, RNEA and the kinematics do not need it)",
        m.name, m.nv, m.nv, m.nv
    ))
}

/// `MemAvailable` of /proc/meminfo in bytes, where the system has it (Linux).
fn available_memory_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb.saturating_mul(1024))
}
