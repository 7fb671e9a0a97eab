//! `Model`: the immutable description of a rigid-body tree (topology, joint placements, inertial
//! parameters). Algorithms never change it; their work buffers live in `crate::Data`.

/// Built-in robots, embedded in the engine at build time.
pub mod builtin;
mod joint;
mod merge;
/// MJCF (MuJoCo) writer.
pub mod mjcf;
mod physics;
/// URDF reader and writer.
pub mod urdf;
/// The YAML model format (docs/model_format.md).
pub mod yaml;

pub use joint::{universal_bias, universal_first_axis, JointLimits, JointType};
pub use physics::{check_finite_nonnegative_mass, check_physical};

use crate::error::{FfError, Result};
use crate::spatial::{principal_axis, Inertia, Se3, M6, V3};

/// A named frame rigidly attached to a body (end effector, sensor point, thruster).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Frame name (unique among frames and bodies).
    pub name: String,
    /// Body the frame is attached to.
    pub body: usize,
    /// Placement of the frame in the body frame.
    pub placement: Se3,
}

/// Description of one body as given to `ModelBuilder::add_body`.
#[derive(Clone, Debug)]
pub struct BodySpec {
    /// Body name.
    pub name: String,
    /// Index of the parent body (already added).
    pub parent: usize,
    /// Name of the joint that attaches the body to its parent.
    pub joint_name: String,
    /// Type of that joint (not a base type).
    pub joint_type: JointType,
    /// Joint axis in the joint frame (normalised by the builder; revolute, prismatic, cylindrical, universal).
    pub axis: V3,
    /// Second axis of a universal joint (in the intermediate frame); ignored by other joints.
    pub axis2: V3,
    /// Rest placement of the joint frame in the parent body frame.
    pub placement: Se3,
    /// Inertial parameters about the body origin, body axes.
    pub inertia: Inertia,
    /// Joint limits (optional).
    pub limits: JointLimits,
    /// Free-form tags (e.g. `base`, `wheel`, `target`, `nonphysical`).
    pub tags: Vec<String>,
    /// Skip the physical-consistency check for this body (published data that is itself
    /// inconsistent, e.g. Naveen, Shah, Misra's Table 2). Finite values and mass ≥ 0 are still required.
    pub allow_nonphysical: bool,
}

/// Immutable description of a rigid-body tree in topological order (`parents[i] < i`); body 0 is
/// the base. Make it with `ModelBuilder` (or a reader); its work buffers are a `Data`.
#[derive(Clone, Debug)]
pub struct Model {
    /// Model name.
    pub name: String,
    /// Body names, in body order.
    pub body_names: Vec<String>,
    /// Joint names: joint i moves body i (joint 0 is the base joint, `root_joint`).
    pub joint_names: Vec<String>,
    /// Parent body of each body; `None` for the base (body 0). Always `parents[i] < i`.
    pub parents: Vec<Option<usize>>,
    /// Joint type of each body's joint.
    pub joint_types: Vec<JointType>,
    /// Joint axis in the joint frame (unit; meaningful for revolute/prismatic/cylindrical only).
    pub axes: Vec<V3>,
    /// Second axis of a universal joint (unit, not parallel to `axes[i]`); z elsewhere, unused.
    pub axes2: Vec<V3>,
    /// Rest placement of each joint frame in its parent body frame (the base: in the inertial frame).
    pub placements: Vec<Se3>,
    /// Inertial parameters of each body (about the body origin, body axes).
    pub inertias: Vec<Inertia>,
    /// Joint limits of each joint.
    pub limits: Vec<JointLimits>,
    /// Tags of each body.
    pub tags: Vec<Vec<String>>,
    /// Bodies exempted from the physical-consistency check (see `BodySpec::allow_nonphysical`).
    pub allow_nonphysical: Vec<bool>,
    /// Named frames fixed on bodies.
    pub frames: Vec<Frame>,
    /// Gravity in the inertial frame (zero for orbital robots).
    pub gravity: V3,
    // Derived layout, filled by `ModelBuilder::build`.
    /// Offset of each joint's coordinates in q.
    pub idx_q: Vec<usize>,
    /// Offset of each joint's coordinates in v.
    pub idx_v: Vec<usize>,
    /// Number of configuration coordinates of each joint.
    pub nqs: Vec<usize>,
    /// Number of velocity coordinates of each joint.
    pub nvs: Vec<usize>,
    /// Length of q.
    pub nq: usize,
    /// Length of v (degrees of freedom).
    pub nv: usize,
    /// Motion subspace of each joint in the child frame at q = 0 (constant for every joint but the
    /// universal one, whose current subspace is `Data::s`).
    pub subspaces: Vec<M6>,
    /// Children of each body, in increasing index order.
    pub children: Vec<Vec<usize>>,
    /// Layout identity stamped by `ModelBuilder::build`, kept by `clone`, `with_parameters` and
    /// `with_gravity` (which change neither the topology nor the joints, hence no buffer size);
    /// `Data::new` copies it so that `check::check_data` can tell a `Data` of another model.
    id: u64,
    /// (body, offset in q) of every quaternion in q, so that the argument check and the
    /// normalisation visit only those (filled by `finalize`).
    quaternions: Vec<(usize, usize)>,
    /// For each joint, `Some(k)` if it is revolute about the principal axis eₖ of its frame (filled by `finalize`;
    /// CRBA's specialised products key on it).
    principal_revolute: Vec<Option<usize>>,
}

/// A fresh model identity (process-wide counter; 0 is never handed out).
fn next_model_id() -> u64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Builds a `Model` body by body, validating each, then the whole tree in `build`.
pub struct ModelBuilder {
    model: Model,
}

impl ModelBuilder {
    /// Start a model whose base body is `base_name`, attached to the inertial frame by `base_joint`
    /// (free, planar or fixed).
    pub fn new(name: &str, base_name: &str, base_joint: JointType, base_inertia: Inertia) -> Result<Self> {
        if !base_joint.is_base() {
            return Err(FfError::Model(format!(
                "base joint must be free, planar or fixed, got '{}'",
                base_joint.name()
            )));
        }
        let model = Model {
            name: name.to_string(),
            body_names: vec![base_name.to_string()],
            joint_names: vec!["root_joint".to_string()],
            parents: vec![None],
            joint_types: vec![base_joint],
            axes: vec![V3::z()],
            axes2: vec![V3::z()],
            placements: vec![Se3::identity()],
            inertias: vec![base_inertia],
            limits: vec![JointLimits::default()],
            tags: vec![vec![]],
            allow_nonphysical: vec![false],
            frames: vec![],
            gravity: V3::zeros(),
            idx_q: vec![],
            idx_v: vec![],
            nqs: vec![],
            nvs: vec![],
            nq: 0,
            nv: 0,
            subspaces: vec![],
            children: vec![],
            id: 0,
            quaternions: vec![],
            principal_revolute: vec![],
        };
        Ok(ModelBuilder { model })
    }

    /// Tags of the base body.
    pub fn set_base_tags(&mut self, tags: Vec<String>) {
        self.model.tags[0] = tags;
    }
    /// Exempt the base from the physical-consistency check (see `BodySpec::allow_nonphysical`).
    pub fn set_base_allow_nonphysical(&mut self, allow: bool) {
        self.model.allow_nonphysical[0] = allow;
    }
    /// Gravity in the inertial frame (m/s²; zero for orbital robots).
    pub fn set_gravity(&mut self, g: V3) {
        self.model.gravity = g;
    }

    /// Index of the body named `name`, if added.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.model.body_names.iter().position(|n| n == name)
    }

    /// Add a body below an existing one; returns its index.
    pub fn add_body(&mut self, b: BodySpec) -> Result<usize> {
        let m = &mut self.model;
        let i = m.body_names.len();
        if b.parent >= i {
            return Err(FfError::Model(format!("body '{}': parent index {} does not exist yet", b.name, b.parent)));
        }
        if b.joint_type.is_base() {
            return Err(FfError::Model(format!(
                "body '{}': joint type '{}' is only allowed for the base",
                b.name,
                b.joint_type.name()
            )));
        }
        // Effort and velocity limits are magnitudes (the simulator enforces |tau| <= effort and stops
        // driving past |v| = velocity); a negative or non-finite one is a mistake in the file, and so
        // is a lower position limit above the upper one.
        for (key, x) in [("effort", b.limits.effort), ("velocity", b.limits.velocity)] {
            if let Some(x) = x {
                if !(x >= 0.0) || !x.is_finite() {
                    return Err(FfError::Model(format!(
                        "joint '{}': limits.{key} must be a finite number >= 0, got {x}",
                        b.joint_name
                    )));
                }
            }
        }
        if let (Some(lo), Some(hi)) = (b.limits.lower, b.limits.upper) {
            if lo > hi {
                return Err(FfError::Model(format!(
                    "joint '{}': limits.lower {lo} is above limits.upper {hi} (inverted limits)",
                    b.joint_name
                )));
            }
        }
        let mut axis = b.axis;
        if b.joint_type.has_axis() {
            let n = axis.norm();
            if !(n > 1e-12) || !n.is_finite() {
                return Err(FfError::Model(format!(
                    "joint '{}': axis {:?} has zero length",
                    b.joint_name,
                    axis.as_slice()
                )));
            }
            axis /= n;
        }
        let mut axis2 = V3::z();
        if b.joint_type == JointType::Universal {
            let n = b.axis2.norm();
            if !(n > 1e-12) || !n.is_finite() {
                return Err(FfError::Model(format!(
                    "joint '{}': second axis {:?} has zero length",
                    b.joint_name,
                    b.axis2.as_slice()
                )));
            }
            axis2 = b.axis2 / n;
            // A Cardan joint: orthogonal axes (parallel ones would leave S rank-deficient; the dual-quaternion
            // formulation's joint frame is built from the two axes and needs them orthogonal)
            if axis.dot(&axis2).abs() > 1e-9 {
                return Err(FfError::Model(format!(
                    "joint '{}': universal joint axes {:?} and {:?} must be orthogonal",
                    b.joint_name,
                    axis.as_slice(),
                    axis2.as_slice()
                )));
            }
        }
        m.body_names.push(b.name);
        m.joint_names.push(b.joint_name);
        m.parents.push(Some(b.parent));
        m.joint_types.push(b.joint_type);
        m.axes.push(axis);
        m.axes2.push(axis2);
        m.placements.push(b.placement);
        m.inertias.push(b.inertia);
        m.limits.push(b.limits);
        m.tags.push(b.tags);
        m.allow_nonphysical.push(b.allow_nonphysical);
        Ok(i)
    }

    /// Attach a named frame to a body.
    pub fn add_frame(&mut self, name: &str, body: usize, placement: Se3) -> Result<()> {
        if body >= self.model.body_names.len() {
            return Err(FfError::Model(format!("frame '{name}': body index {body} does not exist")));
        }
        self.model.frames.push(Frame { name: name.to_string(), body, placement });
        Ok(())
    }

    /// Validate everything and compute the derived layout.
    pub fn build(self) -> Result<Model> {
        let mut m = self.model;
        m.finalize()?;
        m.id = next_model_id();
        Ok(m)
    }
}

impl Model {
    /// Number of bodies (the base included).
    pub fn nbodies(&self) -> usize {
        self.body_names.len()
    }

    /// This model's layout identity (see `check::check_data`): shared by clones and by the models
    /// `with_parameters`/`with_gravity` derive from it, distinct for every model `ModelBuilder::build`
    /// makes (even from the same description).
    pub fn id(&self) -> u64 {
        self.id
    }

    /// For each joint, `Some(k)` if it is revolute about exactly eₖ of its own frame (k = 0, 1, 2), else `None`.
    pub fn principal_revolute(&self) -> &[Option<usize>] {
        &self.principal_revolute
    }

    /// (body, offset in q) of every unit quaternion in q (free base, spherical joints).
    pub fn quaternions(&self) -> &[(usize, usize)] {
        &self.quaternions
    }

    fn finalize(&mut self) -> Result<()> {
        /// Largest magnitude of a length [m] or an inertial parameter [kg, kg m, kg m^2] a model may hold.
        const MAX_MAGNITUDE: f64 = 1e50;
        let n = self.nbodies();
        check_unique("body", &self.body_names)?;
        check_unique("joint", &self.joint_names)?;
        let frame_names: Vec<String> = self.frames.iter().map(|f| f.name.clone()).collect();
        check_unique("frame", &frame_names)?;
        if let Some(f) = self.frames.iter().find(|f| self.body_names.contains(&f.name)) {
            return Err(FfError::Model(format!("frame name '{}' is also a body name", f.name)));
        }
        for (i, name) in self.body_names.iter().enumerate() {
            if name.is_empty() {
                return Err(FfError::Model(format!("body {i} has an empty name")));
            }
            let p = &self.placements[i];
            if p.rot.iter().chain(p.trans.iter()).any(|x| !x.is_finite()) {
                return Err(FfError::Model(format!("joint '{}': placement is not finite", self.joint_names[i])));
            }
            if self.allow_nonphysical[i] {
                check_finite_nonnegative_mass(name, &self.inertias[i])?;
            } else {
                check_physical(name, &self.inertias[i])?;
            }
            // Finite is not enough: the algorithms multiply masses by squared lengths and rates, so a mass of
            // 1e308 or a joint origin at 1e200 m overflows to inf/NaN inside them. Far above any spacecraft, far
            // below overflow for the products the dynamics form (a few factors of this size).
            if let Some(x) = p.trans.iter().copied().find(|x| x.abs() > MAX_MAGNITUDE) {
                return Err(FfError::Model(format!(
                    "joint '{}': origin coordinate {x:e} m is beyond {MAX_MAGNITUDE:e} (the dynamics would overflow \
                     double precision)",
                    self.joint_names[i]
                )));
            }
            let params = self.inertias[i].to_params();
            if let Some(x) = params.iter().copied().find(|x| x.abs() > MAX_MAGNITUDE) {
                return Err(FfError::Model(format!(
                    "body '{name}': inertial parameter {x:e} (mass, first or second moment) is beyond \
                     {MAX_MAGNITUDE:e} (the dynamics would overflow double precision)"
                )));
            }
        }
        if !self.gravity.iter().all(|g| g.is_finite()) {
            return Err(FfError::Model("gravity is not finite".into()));
        }
        self.idx_q.clear();
        self.idx_v.clear();
        self.nqs.clear();
        self.nvs.clear();
        self.subspaces.clear();
        let (mut nq, mut nv) = (0, 0);
        for i in 0..n {
            let jt = self.joint_types[i];
            self.idx_q.push(nq);
            self.idx_v.push(nv);
            self.nqs.push(jt.nq());
            self.nvs.push(jt.nv());
            self.subspaces.push(jt.subspace(&self.axes[i], &self.axes2[i]));
            nq += jt.nq();
            nv += jt.nv();
        }
        self.nq = nq;
        self.nv = nv;
        self.quaternions =
            (0..n).filter_map(|i| self.joint_types[i].quaternion_offset().map(|k| (i, self.idx_q[i] + k))).collect();
        self.principal_revolute = (0..n)
            .map(|i| if self.joint_types[i] == JointType::Revolute { principal_axis(&self.axes[i]) } else { None })
            .collect();
        self.children = vec![vec![]; n];
        for i in 1..n {
            self.children[self.parents[i].unwrap()].push(i);
        }
        self.check_no_massless_subtree()
    }

    /// A moving joint whose whole subtree has no inertia makes the mass matrix singular: say which.
    fn check_no_massless_subtree(&self) -> Result<()> {
        let n = self.nbodies();
        let mut weight: Vec<f64> = self.inertias.iter().map(|i| i.mass + i.i_o.trace()).collect();
        for i in (1..n).rev() {
            let p = self.parents[i].unwrap();
            weight[p] += weight[i];
        }
        for i in 0..n {
            if self.nvs[i] > 0 && weight[i] <= 0.0 {
                return Err(FfError::Model(format!(
                    "joint '{}' moves body '{}' whose subtree has no mass or inertia: the dynamics would be singular \
                     (give the bodies inertial parameters, or make the joint fixed)",
                    self.joint_names[i], self.body_names[i]
                )));
            }
        }
        Ok(())
    }

    /// Index of the body named `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.body_names.iter().position(|n| n == name)
    }

    /// Look up a body or a frame by name: returns (body, placement of the frame in that body).
    pub fn frame_or_body(&self, name: &str) -> Result<(usize, Se3)> {
        if let Some(b) = self.body_index(name) {
            return Ok((b, Se3::identity()));
        }
        if let Some(f) = self.frames.iter().find(|f| f.name == name) {
            return Ok((f.body, f.placement));
        }
        Err(FfError::arg(
            "name",
            format!(
                "'{name}' is neither a body nor a frame of model '{}' (bodies: {})",
                self.name,
                self.body_names.join(", ")
            ),
        ))
    }

    /// Standard parameters, one row of 10 per body.
    pub fn parameters(&self) -> Vec<[f64; 10]> {
        self.inertias.iter().map(|i| i.to_params()).collect()
    }

    /// A copy with other inertial parameters (validated for physical consistency).
    pub fn with_parameters(&self, params: &[f64]) -> Result<Model> {
        let n = self.nbodies();
        if params.len() != 10 * n {
            return Err(FfError::arg("parameters", format!("expected ({n}, 10) values, got {}", params.len())));
        }
        if let Some(k) = params.iter().position(|x| !x.is_finite()) {
            return Err(FfError::arg("parameters", format!("row {}, column {} is not finite", k / 10, k % 10)));
        }
        let mut m = self.clone();
        for i in 0..n {
            m.inertias[i] = Inertia::from_params(&params[10 * i..10 * i + 10]);
        }
        m.finalize()?;
        Ok(m)
    }

    /// A copy with another gravity vector (inertial frame, m/s²); keeps the layout identity.
    pub fn with_gravity(&self, g: V3) -> Result<Model> {
        let mut m = self.clone();
        m.gravity = g;
        m.finalize()?;
        Ok(m)
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.inertias.iter().map(|i| i.mass).sum()
    }

    /// The neutral configuration: zero coordinates, identity quaternions.
    pub fn neutral(&self) -> Vec<f64> {
        let mut q = vec![0.0; self.nq];
        for i in 0..self.nbodies() {
            self.joint_types[i].neutral(&mut q[self.idx_q[i]..self.idx_q[i] + self.nqs[i]]);
        }
        q
    }
}

fn check_unique(what: &str, names: &[String]) -> Result<()> {
    let mut seen = std::collections::HashSet::new();
    for n in names {
        if !seen.insert(n.as_str()) {
            return Err(FfError::Model(format!("{what} name '{n}' is used twice")));
        }
    }
    Ok(())
}
