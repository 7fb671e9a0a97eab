"""Random kinematic trees for oracle tests against Pinocchio.

A `TreeDescription` is plain data (numpy arrays, no freefloat, no Pinocchio).  It renders to

* our YAML model text (`to_yaml`), which freefloat loads,
* URDF text (`to_urdf`, for trees without spherical joints), which both freefloat and Pinocchio parse, and
* a Pinocchio model built *directly from the description* (`build_pinocchio`), never from a freefloat
  object, so that Pinocchio is an independent oracle.

Conventions follow docs/model_format.md: body 0 is the base, `parents[i] < i`, the body frame is the joint
frame, q/v concatenate the joints body by body.  Pinocchio has no fixed joint inside the tree, so a body on a
fixed joint is merged into its nearest moving ancestor (its inertia appended with `appendBodyToJoint`) and
represented by a BODY frame so its placement and Jacobians can still be compared.  For a fixed base that
ancestor is Pinocchio's "universe" (joint 0).  Our format allows any topological body order, Pinocchio's CRBA
needs depth-first order: `PinTree` adds the joints depth-first and permutes q/v (see `depth_first_order`).

The description also carries its own small numpy forward kinematics (`body_placements`): the self-check tests
compare it with the Pinocchio model, which catches mistakes in how the Pinocchio model is built.

Pinocchio is imported lazily so the YAML side can be used without it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: seeds of the trees used by the oracle and self-check tests (one tree per seed)
TREE_SEEDS = tuple(range(60))

BASE_TYPES = ("free", "planar", "fixed")
JOINT_TYPES = ("revolute", "prismatic", "spherical", "cylindrical", "universal", "fixed")
JOINT_NQ = {
    "free": 7,
    "planar": 3,
    "fixed": 0,
    "revolute": 1,
    "prismatic": 1,
    "spherical": 4,
    "cylindrical": 2,
    "universal": 2,
}
JOINT_NV = {
    "free": 6,
    "planar": 3,
    "fixed": 0,
    "revolute": 1,
    "prismatic": 1,
    "spherical": 3,
    "cylindrical": 2,
    "universal": 2,
}
INERTIAL_FORMS = ("com", "origin", "params")


# --------------------------------------------------------------------------------------------------------------
# small numpy geometry, independent of Pinocchio
# --------------------------------------------------------------------------------------------------------------


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_to_matrix(rpy):
    """URDF convention: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    return rot_z(y) @ rot_y(p) @ rot_x(r)


def matrix_to_rpy(R):
    """Inverse of `rpy_to_matrix`, pitch in [-pi/2, pi/2] (fine away from gimbal lock, as for random rotations)."""
    pitch = math.asin(max(-1.0, min(1.0, -R[2, 0])))
    roll = math.atan2(R[2, 1], R[2, 2])
    yaw = math.atan2(R[1, 0], R[0, 0])
    return np.array([roll, pitch, yaw])


def axis_angle_matrix(axis, angle):
    """Rodrigues' formula; `axis` must be a unit vector."""
    k = np.asarray(axis, float)
    kx = skew(k)
    return np.eye(3) + math.sin(angle) * kx + (1.0 - math.cos(angle)) * kx @ kx


def quat_to_matrix(qxyzw):
    """Rotation matrix of a quaternion in x, y, z, w order (normalised first)."""
    x, y, z, w = np.asarray(qxyzw, float) / np.linalg.norm(qxyzw)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def skew(v):
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def homogeneous(R=None, p=None):
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    if p is not None:
        T[:3, 3] = p
    return T


def random_unit_quaternion(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def random_rotation(rng):
    return quat_to_matrix(random_unit_quaternion(rng))


def inertia_about_origin(mass, com, inertia_com):
    """Parallel-axis theorem: inertia about the body-frame origin from the one about the CoM."""
    c = np.asarray(com, float)
    return inertia_com + mass * (c @ c * np.eye(3) - np.outer(c, c))


def standard_parameters(mass, com, inertia_com):
    """[m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz], inertia about the body origin (Pinocchio order)."""
    Io = inertia_about_origin(mass, com, inertia_com)
    return np.array(
        [mass, *(mass * np.asarray(com, float)), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]]
    )


def yaml_float(x) -> str:
    """A float literal that round-trips exactly through PyYAML *and* YAML 1.2 parsers.

    repr() is the shortest exact representation, but PyYAML (YAML 1.1) reads `1e-05` as a *string*: its float
    pattern needs a dot in the mantissa.  So `1e-05` becomes `1.0e-05`.
    """
    if not np.isfinite(x):
        raise ValueError(f"non-finite value {x!r} in a model description")
    s = repr(float(x))
    if "e" in s:
        mant, exp = s.split("e")
        if "." not in mant:
            mant += ".0"
        if exp[0] not in "+-":
            exp = "+" + exp
        s = f"{mant}e{exp}"
    return s


def yaml_list(values) -> str:
    return "[" + ", ".join(yaml_float(v) for v in values) + "]"


# --------------------------------------------------------------------------------------------------------------
# description
# --------------------------------------------------------------------------------------------------------------


@dataclass
class Body:
    name: str
    parent: int  # -1 for the base
    joint_type: str  # base: free|planar|fixed; others: revolute|prismatic|spherical|cylindrical|universal|fixed
    mass: float
    com: np.ndarray  # (3,) body frame
    inertia_com: np.ndarray  # (3,3) about the CoM, body axes
    inertial_form: str = "com"  # which YAML form renders the inertia (all three must load the same)
    joint_name: str | None = None  # None: rely on the documented default "<body>_joint"
    axis: np.ndarray | None = None  # unit axis (revolute/prismatic/cylindrical; universal: the first)
    axis2: np.ndarray | None = None  # universal: second axis (intermediate frame), orthogonal to `axis`
    axis_scale: float = 1.0  # the YAML file holds axis * scale; the loader must normalise it
    omit_axis: bool = False  # render without `axis:` (documented default z; used with mdh rows)
    origin_xyz: np.ndarray | None = None  # None: no `origin` key (identity)
    origin_rpy: np.ndarray | None = None
    mdh: dict | None = None  # {alpha, a, d, theta}, applied after `origin`
    limits: dict | None = None  # rendered only; no effect on dynamics

    @property
    def effective_joint_name(self) -> str:
        return self.joint_name if self.joint_name is not None else f"{self.name}_joint"

    def rest_placement(self) -> np.ndarray:
        """4x4 placement of this body's frame in its parent's frame at joint coordinate zero."""
        T = np.eye(4)
        if self.origin_xyz is not None:
            T = homogeneous(rpy_to_matrix(self.origin_rpy), self.origin_xyz)
        if self.mdh is not None:
            m = self.mdh
            T = (
                T
                @ homogeneous(rot_x(m["alpha"]))
                @ homogeneous(p=[m["a"], 0.0, 0.0])
                @ homogeneous(rot_z(m["theta"]))
                @ homogeneous(p=[0.0, 0.0, m["d"]])
            )
        return T

    def parameters(self) -> np.ndarray:
        return standard_parameters(self.mass, self.com, self.inertia_com)


@dataclass
class Frame:
    name: str
    body: int
    xyz: np.ndarray
    rpy: np.ndarray

    def placement(self) -> np.ndarray:
        return homogeneous(rpy_to_matrix(self.rpy), self.xyz)


@dataclass
class TreeDescription:
    name: str
    base: str
    gravity: np.ndarray
    bodies: list[Body]
    frames: list[Frame] = field(default_factory=list)
    angles: str = "rad"  # unit used when rendering angles to YAML
    omit_base_key: bool = False  # render without `base:` (default free) to exercise the default
    omit_gravity_key: bool = False  # render without `gravity:` (default zero)

    # ---- sizes and layout --------------------------------------------------------------------------------
    @property
    def nbodies(self) -> int:
        return len(self.bodies)

    @property
    def nq(self) -> int:
        return sum(JOINT_NQ[b.joint_type] for b in self.bodies)

    @property
    def nv(self) -> int:
        return sum(JOINT_NV[b.joint_type] for b in self.bodies)

    @property
    def parents(self) -> list[int]:
        return [b.parent for b in self.bodies]

    def q_slices(self) -> list[slice]:
        out, k = [], 0
        for b in self.bodies:
            n = JOINT_NQ[b.joint_type]
            out.append(slice(k, k + n))
            k += n
        return out

    def v_slices(self) -> list[slice]:
        out, k = [], 0
        for b in self.bodies:
            n = JOINT_NV[b.joint_type]
            out.append(slice(k, k + n))
            k += n
        return out

    def parameters(self) -> np.ndarray:
        return np.array([b.parameters() for b in self.bodies])

    def joint_rows(self):
        """(joint name, joint type, q slice, v slice) per body, our layout; the base's name is None."""
        return [
            (None if b.parent < 0 else b.effective_joint_name, b.joint_type, qs, vs)
            for b, qs, vs in zip(self.bodies, self.q_slices(), self.v_slices())
        ]

    def total_mass(self) -> float:
        return float(sum(b.mass for b in self.bodies))

    # ---- random states (our q/v layout) --------------------------------------------------------------------
    def random_q(self, rng) -> np.ndarray:
        parts = []
        for b in self.bodies:
            t = b.joint_type
            if t == "free":
                parts += [rng.uniform(-2, 2, 3), random_unit_quaternion(rng)]
            elif t == "planar":
                # yaw beyond +-pi on purpose: the mapping to cos/sin must not assume a wrapped angle
                parts += [rng.uniform(-2, 2, 2), [rng.uniform(-4.0, 4.0)]]
            elif t == "revolute":
                parts.append([rng.uniform(-math.pi, math.pi)])
            elif t == "prismatic":
                parts.append([rng.uniform(-1.0, 1.0)])
            elif t == "spherical":
                parts.append(random_unit_quaternion(rng))
            elif t == "cylindrical":
                parts.append([rng.uniform(-math.pi, math.pi), rng.uniform(-1.0, 1.0)])
            elif t == "universal":
                parts.append(rng.uniform(-math.pi, math.pi, 2))
        return np.concatenate(parts) if parts else np.zeros(0)

    def random_v(self, rng, scale=1.0) -> np.ndarray:
        return scale * rng.normal(size=self.nv)

    def random_fext(self, rng, scale=1.0) -> np.ndarray:
        return scale * rng.normal(size=(self.nbodies, 6))

    # ---- independent numpy forward kinematics --------------------------------------------------------------
    def joint_motion(self, i: int, qi: np.ndarray) -> np.ndarray:
        """4x4 transform produced by body i's joint at coordinates qi (identity at zero)."""
        b = self.bodies[i]
        t = b.joint_type
        if t == "free":
            return homogeneous(quat_to_matrix(qi[3:7]), qi[0:3])
        if t == "planar":
            return homogeneous(rot_z(qi[2]), [qi[0], qi[1], 0.0])
        if t == "revolute":
            return homogeneous(axis_angle_matrix(b.axis, qi[0]))
        if t == "prismatic":
            return homogeneous(p=b.axis * qi[0])
        if t == "spherical":
            return homogeneous(quat_to_matrix(qi))
        if t == "cylindrical":  # q = [angle about the axis, slide along it]
            return homogeneous(axis_angle_matrix(b.axis, qi[0]), b.axis * qi[1])
        if t == "universal":  # first about axis, then about axis2 of the intermediate frame
            return homogeneous(axis_angle_matrix(b.axis, qi[0]) @ axis_angle_matrix(b.axis2, qi[1]))
        return np.eye(4)  # fixed

    def body_placements(self, q) -> list[np.ndarray]:
        """World placement (4x4) of every body frame, computed without Pinocchio."""
        q = np.asarray(q, float)
        out = []
        for i, (b, sl) in enumerate(zip(self.bodies, self.q_slices())):
            J = self.joint_motion(i, q[sl])
            if b.parent < 0:
                out.append(J)
            else:
                out.append(out[b.parent] @ b.rest_placement() @ J)
        return out

    def frame_placements(self, q) -> dict[str, np.ndarray]:
        X = self.body_placements(q)
        return {f.name: X[f.body] @ f.placement() for f in self.frames}

    def center_of_mass(self, q) -> np.ndarray:
        X = self.body_placements(q)
        s = sum(b.mass * (T[:3, :3] @ b.com + T[:3, 3]) for b, T in zip(self.bodies, X))
        return s / self.total_mass()

    # ---- YAML --------------------------------------------------------------------------------------------
    def _angle(self, a: float) -> str:
        return yaml_float(math.degrees(a) if self.angles == "deg" else a)

    def _angles(self, values) -> str:
        return "[" + ", ".join(self._angle(v) for v in values) + "]"

    def _inertial_yaml(self, b: Body) -> str:
        if b.inertial_form == "params":
            return "{params: " + yaml_list(b.parameters()) + "}"
        if b.inertial_form == "origin":
            key, I = "inertia_origin", inertia_about_origin(b.mass, b.com, b.inertia_com)
        else:
            key, I = "inertia", b.inertia_com
        # products are tensor entries (Ixy = I[0,1] = -int x y dm), exactly as stored in the matrix
        tensor = ", ".join(
            f"{k}: {yaml_float(I[r, c])}"
            for k, (r, c) in (
                ("xx", (0, 0)),
                ("yy", (1, 1)),
                ("zz", (2, 2)),
                ("xy", (0, 1)),
                ("xz", (0, 2)),
                ("yz", (1, 2)),
            )
        )
        return f"{{mass: {yaml_float(b.mass)}, com: {yaml_list(b.com)}, {key}: {{{tensor}}}}}"

    def to_yaml(self) -> str:
        lines = [f"name: {self.name}", "description: random tree generated by tests/random_trees.py"]
        if not self.omit_base_key:
            lines.append(f"base: {self.base}")
        if not self.omit_gravity_key:
            lines.append(f"gravity: {yaml_list(self.gravity)}")
        lines += [f"angles: {self.angles}", "", "bodies:"]
        for b in self.bodies:
            lines.append(f"  - name: {b.name}")
            if b.parent >= 0:
                lines.append(f"    parent: {self.bodies[b.parent].name}")
                lines.append("    joint:")
                if b.joint_name is not None:
                    lines.append(f"      name: {b.joint_name}")
                lines.append(f"      type: {b.joint_type}")
                if b.axis is not None and not b.omit_axis:
                    lines.append(f"      axis: {yaml_list(b.axis * b.axis_scale)}")
                if b.axis2 is not None:
                    lines.append(f"      axis2: {yaml_list(b.axis2 * b.axis_scale)}")
                if b.limits is not None:
                    lim = b.limits
                    conv = self._angle if b.joint_type == "revolute" else yaml_float
                    lines.append(
                        f"      limits: {{lower: {conv(lim['lower'])}, upper: {conv(lim['upper'])}, "
                        f"velocity: {yaml_float(lim['velocity'])}, effort: {yaml_float(lim['effort'])}}}"
                    )
                if b.origin_xyz is not None:
                    lines.append(f"    origin: {{xyz: {yaml_list(b.origin_xyz)}, rpy: {self._angles(b.origin_rpy)}}}")
                if b.mdh is not None:
                    m = b.mdh
                    lines.append(
                        f"    mdh: {{alpha: {self._angle(m['alpha'])}, a: {yaml_float(m['a'])}, "
                        f"d: {yaml_float(m['d'])}, theta: {self._angle(m['theta'])}}}"
                    )
            lines.append(f"    inertial: {self._inertial_yaml(b)}")
        if self.frames:
            lines += ["", "frames:"]
            for f in self.frames:
                lines.append(
                    f"  - {{name: {f.name}, body: {self.bodies[f.body].name}, "
                    f"origin: {{xyz: {yaml_list(f.xyz)}, rpy: {self._angles(f.rpy)}}}}}"
                )
        return "\n".join(lines) + "\n"

    def to_urdf(self, render_seed: int = 0) -> str:
        """URDF text of this tree (the base is the root link; its joint type is chosen at load time).

        Rendering choices come from `render_seed`: links and joints are written in shuffled document order
        (so depth-first-in-document order differs from file order and from alphabetical order), some revolute
        joints are written as `continuous`, inertial frames get a random rpy (the inertia tensor is rotated to
        match), and +x axes are left out (URDF's default).  Spherical joints and extra frames have no URDF form.
        """
        rng = np.random.default_rng(render_seed)
        f = yaml_float

        def vec(v):
            return " ".join(f(x) for x in v)

        links, joints = [], []
        for b in self.bodies:
            r = rng.uniform(-math.pi, math.pi, 3) * np.array([1.0, 0.5, 1.0])
            R = rpy_to_matrix(r)
            Ir = R.T @ b.inertia_com @ R  # tensor in the rotated inertial frame: R Ir R^T = inertia_com
            links.append(
                f'  <link name="{b.name}">\n    <inertial>\n      <origin xyz="{vec(b.com)}" rpy="{vec(r)}"/>\n'
                f'      <mass value="{f(b.mass)}"/>\n      <inertia ixx="{f(Ir[0, 0])}" ixy="{f(Ir[0, 1])}" '
                f'ixz="{f(Ir[0, 2])}" iyy="{f(Ir[1, 1])}" iyz="{f(Ir[1, 2])}" izz="{f(Ir[2, 2])}"/>\n'
                f"    </inertial>\n  </link>"
            )
            if b.parent < 0:
                continue
            if b.joint_type in ("spherical", "cylindrical", "universal"):
                raise ValueError(f"URDF has no {b.joint_type} joint")
            T = b.rest_placement()
            jtype = b.joint_type
            if jtype == "revolute" and b.limits is None and rng.random() < 0.5:
                jtype = "continuous"
            body = [
                f'    <parent link="{self.bodies[b.parent].name}"/>',
                f'    <child link="{b.name}"/>',
                f'    <origin xyz="{vec(T[:3, 3])}" rpy="{vec(matrix_to_rpy(T[:3, :3]))}"/>',
            ]
            if b.joint_type in ("revolute", "prismatic"):
                if not np.array_equal(b.axis, [1.0, 0.0, 0.0]):
                    # unit axis: URDF asks for one, and Pinocchio's parser does not normalise it
                    body.append(f'    <axis xyz="{vec(b.axis)}"/>')
                if jtype != "continuous":
                    lim = b.limits or {"lower": -3.0, "upper": 3.0, "velocity": 2.0, "effort": 50.0}
                    body.append(
                        f'    <limit lower="{f(lim["lower"])}" upper="{f(lim["upper"])}" '
                        f'effort="{f(lim["effort"])}" velocity="{f(lim["velocity"])}"/>'
                    )
            joints.append(
                f'  <joint name="{b.effective_joint_name}" type="{jtype}">\n' + "\n".join(body) + "\n  </joint>"
            )
        elements = links + joints
        order = rng.permutation(len(elements))
        return (
            f'<?xml version="1.0"?>\n<robot name="{self.name}">\n'
            + "\n".join(elements[k] for k in order)
            + "\n</robot>\n"
        )


# --------------------------------------------------------------------------------------------------------------
# random generation
# --------------------------------------------------------------------------------------------------------------


def random_inertia(rng, mass_range=(0.1, 50.0)):
    """(mass, com, inertia about the CoM) of a physically consistent rigid body.

    Principal moments are built from positive second moments a, b, c of the mass distribution
    (I1 = b + c, ...), which satisfies the triangle inequalities with a margin, then rotated randomly.
    """
    m = float(math.exp(rng.uniform(math.log(mass_range[0]), math.log(mass_range[1]))))
    second = m * rng.uniform(0.03, 0.5, 3) ** 2
    a, b, c = second
    R = random_rotation(rng)
    I = R @ np.diag([b + c, a + c, a + b]) @ R.T
    I = 0.5 * (I + I.T)
    com = rng.uniform(-0.5, 0.5, 3)
    return m, com, I


def random_axis(rng):
    # a quarter of the axes are signed coordinate axes: an engine may special-case them
    if rng.random() < 0.25:
        ax = np.zeros(3)
        ax[rng.integers(3)] = rng.choice([-1.0, 1.0])
        return ax
    ax = rng.normal(size=3)
    return ax / np.linalg.norm(ax)


def random_tree(
    rng,
    name="random_tree",
    n_children=None,
    base=None,
    gravity=None,
    joint_types=JOINT_TYPES,
    joint_p=(0.3, 0.15, 0.1, 0.1, 0.15, 0.2),
) -> TreeDescription:
    """A random tree: random base type, 1-20 child joints, random placements, inertias and parents."""
    base = base or str(rng.choice(BASE_TYPES, p=[0.5, 0.25, 0.25]))
    n = int(n_children if n_children is not None else rng.integers(1, 21))
    if gravity is None:
        gravity = rng.normal(size=3) * rng.uniform(1.0, 10.0) if rng.random() < 0.5 else np.zeros(3)
    gravity = np.asarray(gravity, float)

    bm, bc, bI = random_inertia(rng, mass_range=(1.0, 500.0))
    bodies = [
        Body(
            name="base",
            parent=-1,
            joint_type=base,
            mass=bm,
            com=bc,
            inertia_com=bI,
            inertial_form=str(rng.choice(INERTIAL_FORMS)),
        )
    ]
    for i in range(1, n + 1):
        # half chains, half arbitrary branching
        parent = i - 1 if rng.random() < 0.5 else int(rng.integers(0, i))
        jt = str(rng.choice(joint_types, p=joint_p))
        m, c, I = random_inertia(rng)
        b = Body(
            name=f"b{i}",
            parent=parent,
            joint_type=jt,
            mass=m,
            com=c,
            inertia_com=I,
            inertial_form=str(rng.choice(INERTIAL_FORMS)),
            joint_name=f"j{i}" if rng.random() < 0.5 else None,
        )
        if jt in ("cylindrical", "universal"):
            b.axis = random_axis(rng)
            if jt == "universal":
                # orthogonal second axis (a Cardan joint); often a coordinate axis with a coordinate first axis
                other = random_axis(rng)
                while abs(other @ b.axis) > 0.95:
                    other = random_axis(rng)
                b.axis2 = np.cross(b.axis, other)
                b.axis2 /= np.linalg.norm(b.axis2)
            if rng.random() < 0.2:
                b.axis_scale = float(rng.uniform(0.3, 3.0))
        if jt in ("revolute", "prismatic"):
            b.axis = random_axis(rng)
            if rng.random() < 0.2:
                b.axis_scale = float(rng.uniform(0.3, 3.0))
            if rng.random() < 0.3:
                lo = float(rng.uniform(-3.0, -0.1))
                b.limits = {
                    "lower": lo,
                    "upper": float(rng.uniform(0.1, 3.0)),
                    "velocity": float(rng.uniform(0.5, 5)),
                    "effort": float(rng.uniform(1, 100)),
                }
        use_mdh = jt in ("revolute", "prismatic") and rng.random() < 0.3
        if use_mdh:
            # MDH rows fix the joint axis to z; omit it half the time to exercise the default
            b.axis = np.array([0.0, 0.0, 1.0])
            b.axis_scale = 1.0
            b.omit_axis = bool(rng.random() < 0.5)
            b.mdh = {
                "alpha": float(rng.uniform(-math.pi, math.pi)),
                "a": float(rng.uniform(-1, 1)),
                "d": float(rng.uniform(-1, 1)),
                "theta": float(rng.uniform(-math.pi, math.pi)),
            }
        if not use_mdh or rng.random() < 0.5:
            b.origin_xyz = rng.uniform(-1.0, 1.0, 3)
            b.origin_rpy = np.array(
                [rng.uniform(-math.pi, math.pi), rng.uniform(-math.pi / 2, math.pi / 2), rng.uniform(-math.pi, math.pi)]
            )
        bodies.append(b)

    # a tree whose every joint is fixed on a fixed base has nv = 0; make sure something moves
    if sum(JOINT_NV[b.joint_type] for b in bodies) == 0:
        bodies[-1].joint_type = "revolute"
        bodies[-1].axis = random_axis(rng)
        bodies[-1].omit_axis = False
        bodies[-1].mdh = None
        if bodies[-1].origin_xyz is None:
            bodies[-1].origin_xyz, bodies[-1].origin_rpy = np.zeros(3), np.zeros(3)

    frames = []
    for k in range(int(rng.integers(0, 4))):
        frames.append(
            Frame(
                name=f"f{k}",
                body=int(rng.integers(0, len(bodies))),
                xyz=rng.uniform(-1, 1, 3),
                rpy=rng.uniform(-1.5, 1.5, 3),
            )
        )

    return TreeDescription(
        name=name,
        base=base,
        gravity=gravity,
        bodies=bodies,
        frames=frames,
        angles="deg" if rng.random() < 0.2 else "rad",
        omit_base_key=(base == "free" and rng.random() < 0.3),
        omit_gravity_key=(not np.any(gravity) and rng.random() < 0.5),
    )


def tree_from_seed(seed: int) -> TreeDescription:
    return random_tree(np.random.default_rng(seed), name=f"random_tree_{seed}")


#: seeds of the trees rendered to URDF (no spherical joints, no extra frames, zero gravity: URDF has none)
URDF_TREE_SEEDS = tuple(range(100, 120))


def urdf_tree_from_seed(seed: int, base: str = "free") -> TreeDescription:
    """A tree for URDF rendering; `base` is how it will be loaded (it does not change the URDF text)."""
    rng = np.random.default_rng(seed)
    d = random_tree(
        rng,
        name=f"random_urdf_{seed}",
        base="free",
        gravity=np.zeros(3),
        joint_types=("revolute", "prismatic", "fixed"),
        joint_p=(0.55, 0.2, 0.25),
    )
    d.base = d.bodies[0].joint_type = base
    d.frames = []
    for b in d.bodies[1:]:
        # URDF's default axis is +x; give it to some joints so `to_urdf` can leave the axis out
        if b.joint_type in ("revolute", "prismatic") and b.mdh is None and rng.random() < 0.2:
            b.axis = np.array([1.0, 0.0, 0.0])
    return d


# --------------------------------------------------------------------------------------------------------------
# Pinocchio model built from the description
# --------------------------------------------------------------------------------------------------------------


def _se3(T):
    import pinocchio as pin

    return pin.SE3(np.array(T[:3, :3]), np.array(T[:3, 3]))


def depth_first_order(parents) -> list[int]:
    """Bodies in depth-first order, children visited in file order.

    Our format only asks for parents[i] < i, but Pinocchio's CRBA (and everything built on the sparsity of M)
    assumes each joint's subtree occupies a contiguous block of v.  Adding the joints in depth-first order and
    permuting q/v makes the oracle valid for any topological order.
    """
    children = [[] for _ in parents]
    for i, p in enumerate(parents):
        if p >= 0:
            children[p].append(i)
    order, stack = [], [0]
    while stack:
        i = stack.pop()
        order.append(i)
        stack.extend(reversed(children[i]))
    return order


@dataclass
class PinTree:
    """A Pinocchio model of a `TreeDescription` plus the maps between the two layouts.

    Our layout: joints body by body in file order.  Pinocchio's: joints in depth-first order (see
    `depth_first_order`), planar base as x, y, cos, sin.  Every method below takes and returns our layout.
    """

    desc: TreeDescription
    model: object
    data: object
    joint_of_body: list[int]  # Pinocchio joint carrying each body (0 = universe for fixed-base welds)
    body_in_joint: list[object]  # pin.SE3 placement of each body frame in that joint's frame
    frame_id: dict[str, int]  # body name or frame name -> Pinocchio frame id
    pin_q_slice: list[slice | None]  # per body: its joint's slice of Pinocchio's q (None: no joint of its own)
    v_perm: np.ndarray  # v_pin = v_ours[v_perm]

    # ---- layout maps -------------------------------------------------------------------------------------
    def q_to_pin(self, q) -> np.ndarray:
        """Our q -> Pinocchio q (reordered; planar yaw -> cos, sin)."""
        q = np.asarray(q, float)
        qp = np.zeros(self.model.nq)
        for b, ours, theirs in zip(self.desc.bodies, self.desc.q_slices(), self.pin_q_slice):
            if theirs is None:
                continue
            if b.joint_type == "planar":
                x, y, yaw = q[ours]
                qp[theirs] = [x, y, math.cos(yaw), math.sin(yaw)]
            else:
                qp[theirs] = q[ours]
        return qp

    def q_from_pin(self, qp) -> np.ndarray:
        qp = np.asarray(qp, float)
        q = np.zeros(self.desc.nq)
        for b, ours, theirs in zip(self.desc.bodies, self.desc.q_slices(), self.pin_q_slice):
            if theirs is None:
                continue
            if b.joint_type == "planar":
                x, y, c, s_ = qp[theirs]
                q[ours] = [x, y, math.atan2(s_, c)]
            else:
                q[ours] = qp[theirs]
        return q

    def v_to_pin(self, v) -> np.ndarray:
        """Our v (or tau, a) -> Pinocchio's; velocity coordinates of each joint are the same, only reordered."""
        return np.asarray(v, float)[self.v_perm].copy()

    def v_from_pin(self, vp) -> np.ndarray:
        vp = np.asarray(vp, float)
        out = np.zeros_like(vp)
        out[self.v_perm] = vp
        return out

    def cols_from_pin(self, J) -> np.ndarray:
        """Reorder the columns (v-indexed) of a Pinocchio matrix into our layout."""
        # eigenpy hands an n x 1 matrix back as a 1-D array, so restore the column dimension first
        J = np.asarray(J, float).reshape(-1, len(self.v_perm))
        out = np.zeros_like(J)
        out[:, self.v_perm] = J
        return out

    def fext_to_pin(self, fext):
        """Per-body [force; torque] in body frames -> Pinocchio per-joint forces in joint frames.

        A force on a merged (fixed) body is moved to its carrying joint's frame; forces on bodies welded to
        the universe (fixed base) do nothing, in Pinocchio as in reality.
        """
        import pinocchio as pin

        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        if fext is None:
            return out
        fext = np.asarray(fext, float)
        for i, f in enumerate(fext):
            j = self.joint_of_body[i]
            out[j] = out[j] + self.body_in_joint[i].act(pin.Force(f[:3], f[3:]))
        return out

    # ---- oracle quantities, all in our layout --------------------------------------------------------------
    def aba(self, q, v, tau, fext=None):
        import pinocchio as pin

        args = [self.model, self.data, self.q_to_pin(q), self.v_to_pin(v), self.v_to_pin(tau)]
        if fext is not None:
            args.append(self.fext_to_pin(fext))
        return self.v_from_pin(pin.aba(*args))

    def rnea(self, q, v, a, fext=None):
        import pinocchio as pin

        args = [self.model, self.data, self.q_to_pin(q), self.v_to_pin(v), self.v_to_pin(a)]
        if fext is not None:
            args.append(self.fext_to_pin(fext))
        return self.v_from_pin(pin.rnea(*args))

    def crba(self, q):
        import pinocchio as pin

        M = np.array(pin.crba(self.model, self.data, self.q_to_pin(q)), float).reshape(self.model.nv, self.model.nv)
        # pin 4 returns the full matrix; symmetrise anyway in case a version fills only the upper triangle
        M = np.triu(M) + np.triu(M, 1).T
        return self.cols_from_pin(self.cols_from_pin(M).T).T

    def nonlinear_effects(self, q, v):
        import pinocchio as pin

        return self.v_from_pin(pin.nonLinearEffects(self.model, self.data, self.q_to_pin(q), self.v_to_pin(v)))

    def center_of_mass(self, q):
        return pin_center_of_mass(self.model, self.data, self.q_to_pin(q))

    def momentum(self, q, v):
        return pin_momentum_at_origin(self.model, self.data, self.q_to_pin(q), self.v_to_pin(v))

    def centroidal_momentum_matrix(self, q):
        return self.cols_from_pin(pin_momentum_matrix_at_origin(self.model, self.data, self.q_to_pin(q)))

    def forward_kinematics(self, q):
        """(nbodies, 7): position and quaternion xyzw of each body frame in the world."""
        import pinocchio as pin

        pin.framesForwardKinematics(self.model, self.data, self.q_to_pin(q))
        out = np.zeros((self.desc.nbodies, 7))
        for i, b in enumerate(self.desc.bodies):
            M = self.data.oMf[self.frame_id[b.name]]
            out[i, :3] = M.translation
            out[i, 3:] = pin.Quaternion(M.rotation).coeffs()
        return out

    def placement(self, q, name) -> np.ndarray:
        import pinocchio as pin

        pin.framesForwardKinematics(self.model, self.data, self.q_to_pin(q))
        return self.data.oMf[self.frame_id[name]].homogeneous.copy()

    def frame_jacobian(self, q, name, reference="local"):
        import pinocchio as pin

        rf = {"local": pin.LOCAL, "world": pin.LOCAL_WORLD_ALIGNED}[reference]
        J = pin.computeFrameJacobian(self.model, self.data, self.q_to_pin(q), self.frame_id[name], rf)
        return self.cols_from_pin(J)

    def frame_velocity_local(self, q, v, name):
        """Twist [linear; angular] of a frame, in its own axes (used by the self-checks)."""
        import pinocchio as pin

        pin.forwardKinematics(self.model, self.data, self.q_to_pin(q), self.v_to_pin(v))
        pin.updateFramePlacements(self.model, self.data)
        return pin.getFrameVelocity(self.model, self.data, self.frame_id[name], pin.LOCAL).vector.copy()


def build_pinocchio(desc: TreeDescription) -> PinTree:
    """Build the Pinocchio model of `desc` directly from the description."""
    import pinocchio as pin

    model = pin.Model()
    model.name = desc.name
    model.gravity = pin.Motion(np.asarray(desc.gravity, float), np.zeros(3))
    n = desc.nbodies
    joint_of_body, body_in_joint = [0] * n, [None] * n
    frame_id: dict[str, int] = {}

    for i in depth_first_order(desc.parents):
        b = desc.bodies[i]
        if b.parent < 0:
            if b.joint_type == "free":
                # "root_joint" is the name crocoddyl's floating-base actuation expects
                jid = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
            elif b.joint_type == "planar":
                jid = model.addJoint(0, pin.JointModelPlanar(), pin.SE3.Identity(), "root_joint")
            else:
                jid = 0  # fixed base: the base body is welded to the universe at the world origin
            X = pin.SE3.Identity()
        else:
            pj = joint_of_body[b.parent]
            X_parent = body_in_joint[b.parent] * _se3(b.rest_placement())  # rest frame in the carrying joint
            t = b.joint_type
            if t == "fixed":
                jid, X = pj, X_parent
            else:
                if t == "revolute":
                    jm = pin.JointModelRevoluteUnaligned(np.array(b.axis, float))
                elif t == "prismatic":
                    jm = pin.JointModelPrismaticUnaligned(np.array(b.axis, float))
                elif t == "spherical":
                    jm = pin.JointModelSpherical()
                elif t == "cylindrical":
                    # Pinocchio has no cylindrical joint: a composite of a revolute and a prismatic joint on
                    # the same axis (they commute), q = [angle, slide] as ours, subspace in the child frame
                    a = np.array(b.axis, float)
                    jm = pin.JointModelComposite(pin.JointModelRevoluteUnaligned(a))
                    jm.addJoint(pin.JointModelPrismaticUnaligned(a))
                elif t == "universal":
                    # Pinocchio's universal joint: R = R(axis1, q1) R(axis2, q2), q and v as ours
                    jm = pin.JointModelUniversal(np.array(b.axis, float), np.array(b.axis2, float))
                else:
                    raise ValueError(f"unknown joint type {t!r}")
                jid = model.addJoint(pj, jm, X_parent, b.effective_joint_name)
                X = pin.SE3.Identity()
        model.appendBodyToJoint(jid, pin.Inertia(b.mass, np.array(b.com, float), np.array(b.inertia_com, float)), X)
        parent_frame = 0 if b.parent < 0 else frame_id[desc.bodies[b.parent].name]
        frame_id[b.name] = model.addFrame(pin.Frame(b.name, jid, parent_frame, X, pin.FrameType.BODY), False)
        joint_of_body[i], body_in_joint[i] = jid, X

    for f in desc.frames:
        j = joint_of_body[f.body]
        X = body_in_joint[f.body] * _se3(f.placement())
        frame_id[f.name] = model.addFrame(
            pin.Frame(f.name, j, frame_id[desc.bodies[f.body].name], X, pin.FrameType.OP_FRAME), False
        )

    # layout maps: a body owns a Pinocchio joint iff its own joint moves
    pin_q_slice: list[slice | None] = []
    v_perm = np.zeros(desc.nv, dtype=int)
    for b, vs, jid in zip(desc.bodies, desc.v_slices(), joint_of_body):
        if JOINT_NV[b.joint_type] == 0:
            pin_q_slice.append(None)
            continue
        jm = model.joints[jid]
        pin_q_slice.append(slice(jm.idx_q, jm.idx_q + jm.nq))
        v_perm[jm.idx_v : jm.idx_v + jm.nv] = np.arange(vs.start, vs.stop)

    return PinTree(
        desc=desc,
        model=model,
        data=model.createData(),
        joint_of_body=joint_of_body,
        body_in_joint=body_in_joint,
        frame_id=frame_id,
        pin_q_slice=pin_q_slice,
        v_perm=v_perm,
    )


def ff_joint_rows(m):
    """`TreeDescription.joint_rows()` for a freefloat model: (joint name, type, q slice, v slice) per body."""
    types = list(m.joint_types)
    names = list(m.joint_names)
    names = [None] + names[len(names) - (len(types) - 1) :]  # with or without a base entry
    rows, q0, v0 = [], 0, 0
    for name, t in zip(names, types):
        qs, vs = slice(q0, q0 + JOINT_NQ[t]), slice(v0, v0 + JOINT_NV[t])
        q0, v0 = qs.stop, vs.stop
        rows.append((name, t, qs, vs))
    return rows


class NamedLayout:
    """q/v maps between a body-ordered layout (ours) and a Pinocchio model whose joints are matched *by name*.

    Used for models Pinocchio builds itself (URDF), whose joint order and joint kinds we do not control:
    siblings come in urdfdom's (alphabetical) order, and URDF `continuous` joints become Pinocchio's unbounded
    revolute joints, stored as cos, sin.  `rows` is `joint_rows()`-shaped: the base first (name ignored).
    """

    def __init__(self, model, rows):
        self.model = model
        (_, self.base, self.base_q, self.base_v), self.rows = rows[0], rows[1:]
        first = 1 if self.base == "fixed" else 2  # Pinocchio joint 1 is the root joint when there is one
        self.pin_joint = {model.names[j]: j for j in range(first, model.njoints)}
        moving = [r for r in self.rows if JOINT_NV[r[1]] > 0]
        ours, theirs = sorted(r[0] for r in moving), sorted(self.pin_joint)
        assert ours == theirs, f"moving joints differ by name: ours {ours}, Pinocchio {theirs}"
        nv = sum(JOINT_NV[r[1]] for r in rows)
        assert nv == model.nv, f"nv {nv} vs Pinocchio {model.nv}"
        self.v_perm = np.zeros(nv, dtype=int)  # v_pin = v_ours[v_perm]
        if self.base != "fixed":
            jm = model.joints[1]
            self.v_perm[jm.idx_v : jm.idx_v + jm.nv] = np.arange(self.base_v.start, self.base_v.stop)
        for name, t, _qs, vs in moving:
            jm = model.joints[self.pin_joint[name]]
            assert jm.nv == JOINT_NV[t], f"{name}: nv {jm.nv} in Pinocchio vs {JOINT_NV[t]} ({t})"
            self.v_perm[jm.idx_v : jm.idx_v + jm.nv] = np.arange(vs.start, vs.stop)
        assert sorted(self.v_perm) == list(range(nv))

    def q_to_pin(self, q) -> np.ndarray:
        q = np.asarray(q, float)
        qp = np.zeros(self.model.nq)
        if self.base == "free":
            qp[:7] = q[self.base_q]
        elif self.base == "planar":
            x, y, yaw = q[self.base_q]
            qp[:4] = [x, y, math.cos(yaw), math.sin(yaw)]
        for name, t, qs, _ in self.rows:
            if JOINT_NV[t] == 0:
                continue
            jm = self.model.joints[self.pin_joint[name]]
            if jm.nq == 2 and jm.nv == 1:  # unbounded revolute: cos, sin
                qp[jm.idx_q : jm.idx_q + 2] = [math.cos(q[qs][0]), math.sin(q[qs][0])]
            else:
                qp[jm.idx_q : jm.idx_q + jm.nq] = q[qs]
        return qp

    def v_to_pin(self, v) -> np.ndarray:
        return np.asarray(v, float)[self.v_perm].copy()

    def v_from_pin(self, vp) -> np.ndarray:
        out = np.zeros(len(self.v_perm))
        out[self.v_perm] = np.asarray(vp, float)
        return out

    def cols_from_pin(self, A) -> np.ndarray:
        A = np.asarray(A, float).reshape(-1, len(self.v_perm))
        out = np.zeros_like(A)
        out[:, self.v_perm] = A
        return out

    def matrix_from_pin(self, M) -> np.ndarray:
        """An nv x nv Pinocchio matrix (e.g. crba, symmetrised) in our layout."""
        M = np.asarray(M, float).reshape(self.model.nv, self.model.nv)
        M = np.triu(M) + np.triu(M, 1).T
        return self.cols_from_pin(self.cols_from_pin(M).T).T

    def body_frame(self, name):
        """(frame id, carrying joint, placement in that joint) of a URDF link's Pinocchio BODY frame."""
        import pinocchio as pin

        assert self.model.existFrame(name, pin.FrameType.BODY), f"no Pinocchio BODY frame named {name!r}"
        fid = self.model.getFrameId(name, pin.FrameType.BODY)
        f = self.model.frames[fid]
        return fid, f.parentJoint, f.placement

    def fext_to_pin(self, body_names, fext):
        import pinocchio as pin

        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        for name, f in zip(body_names, np.asarray(fext, float)):
            _, j, X = self.body_frame(name)
            out[j] = out[j] + X.act(pin.Force(f[:3], f[3:]))
        return out


def urdf_depth_first_joint_order(urdf_text) -> list[str]:
    """Moving joints depth-first from the root link, children in document order."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(urdf_text)
    joints = root.findall("joint")
    children: dict[str, list] = {}
    for j in joints:
        children.setdefault(j.find("parent").get("link"), []).append(j)
    child_links = {j.find("child").get("link") for j in joints}
    (root_link,) = [link.get("name") for link in root.findall("link") if link.get("name") not in child_links]
    order = []
    # iterative DFS (URDF chains can be deeper than Python's recursion limit); children in document order
    pending = [(root_link, iter(children.get(root_link, [])))]
    while pending:
        _, it = pending[-1]
        j = next(it, None)
        if j is None:
            pending.pop()
            continue
        if j.get("type") != "fixed":
            order.append(j.get("name"))
        child = j.find("child").get("link")
        pending.append((child, iter(children.get(child, []))))
    return order


def urdf_total_mass(urdf_text) -> float:
    """Total mass read straight from URDF text."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(urdf_text)
    return float(sum(float(m.get("value")) for m in root.findall("link/inertial/mass")))


# --------------------------------------------------------------------------------------------------------------
# Pinocchio helpers shared by the random-tree and the URDF tests (Pinocchio q/v layout)
# --------------------------------------------------------------------------------------------------------------


def pin_total_mass(model) -> float:
    """Mass of every body, including bodies welded to the universe (which pin.centerOfMass leaves out)."""
    return float(sum(model.inertias[j].mass for j in range(model.njoints)))


def pin_center_of_mass(model, data, qp) -> np.ndarray:
    """Whole-system CoM.  pin.centerOfMass skips model.inertias[0] (the universe), where a fixed base and the
    bodies welded to it live, so add that part back (the universe frame is the world frame)."""
    import pinocchio as pin

    c_moving = pin.centerOfMass(model, data, qp).copy()
    m_moving = float(data.mass[0])
    Y0 = model.inertias[0]
    if Y0.mass == 0.0:
        return c_moving
    return (m_moving * c_moving + Y0.mass * Y0.lever) / (m_moving + Y0.mass)


def pin_momentum_at_origin(model, data, qp, vp) -> np.ndarray:
    """[p; L_O] in world axes.  computeCentroidalMomentum gives h_G (angular part about the CoM G of the moving
    bodies, world axes); shift it with L_O = L_G + c x p.  Welded bodies do not move, so using the moving-body
    CoM that Pinocchio used is exactly right."""
    import pinocchio as pin

    hg = pin.computeCentroidalMomentum(model, data, qp, vp)
    c = data.com[0].copy()
    p = hg.linear.copy()
    return np.concatenate([p, hg.angular + np.cross(c, p)])


def pin_momentum_matrix_at_origin(model, data, qp) -> np.ndarray:
    """A_O with [p; L_O] = A_O v, from Pinocchio's centroidal map A_G (same shift as above, row-wise)."""
    import pinocchio as pin

    Ag = np.array(pin.ccrba(model, data, qp, np.zeros(model.nv)), float).reshape(6, model.nv)
    c = data.com[0].copy()
    return np.vstack([Ag[:3], Ag[3:] + skew(c) @ Ag[:3]])


# --------------------------------------------------------------------------------------------------------------
# comparison helper
# --------------------------------------------------------------------------------------------------------------


def assert_close(actual, expected, rtol=1e-9, atol=1e-12, what=""):
    """Norm-relative comparison: |actual - expected| <= rtol |expected| + atol (Frobenius norms).

    Element-wise relative tolerances are meaningless for entries that are zero by structure or cancellation;
    a norm-relative test checks the quantity as a whole, with a tiny floor for all-zero references.
    """
    a = np.asarray(actual, dtype=float)
    e = np.asarray(expected, dtype=float)
    assert a.shape == e.shape, f"{what}: shape {a.shape} != expected {e.shape}"
    assert np.all(np.isfinite(a)), f"{what}: non-finite values {a}"
    err = float(np.linalg.norm(a - e))
    ref = float(np.linalg.norm(e))
    assert err <= rtol * ref + atol, (
        f"{what}: |actual - expected| = {err:.3e} > {rtol:g} * |expected| ({ref:.3e}) + {atol:g}\n"
        f"actual=\n{a}\nexpected=\n{e}"
    )
