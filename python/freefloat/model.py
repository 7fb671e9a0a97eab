"""The `Model` facade: an immutable rigid-body tree, loaded from URDF, YAML or the built-in robots.

The description itself and every algorithm live in the Rust engine (`freefloat._core`); this class
adds file handling and the conveniences that are naturally Python (random configurations)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import _core
from ._arrays import as_f64
from ._core import InputError


class Model:
    """A floating-base rigid-body tree. Immutable: `with_parameters` and `with_gravity` return new models.

    Conventions (ARCHITECTURE.md): q = [base position, base quaternion (x, y, z, w), joints...],
    v = [base linear, base angular velocity (base frame), joint rates...]; standard parameters per body
    [m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] about the body-frame origin."""

    __slots__ = ("_core",)

    def __init__(self, core: _core.Model):
        if not isinstance(core, _core.Model):
            raise TypeError("use Model.from_urdf, Model.from_yaml or freefloat.models.load to make a Model")
        self._core = core

    # -- loading and saving ---------------------------------------------------------------------------
    @classmethod
    def from_urdf(cls, path, base: str = "free", allow_nonphysical: bool = False) -> Model:
        """Load a URDF file; its root link becomes the base, attached by a `base` joint
        ("free", "planar" or "fixed"). Joints are taken depth-first, children in document order.
        Massless leaf links on fixed joints become frames. Links with physically impossible inertia
        are rejected unless `allow_nonphysical` (many published URDFs have dummy links whose inertia
        is degenerate)."""
        p = Path(path)
        return cls(_core.Model.from_urdf_string(_read(p), base, str(p), allow_nonphysical))

    @classmethod
    def from_urdf_string(cls, text: str, base: str = "free", allow_nonphysical: bool = False) -> Model:
        return cls(_core.Model.from_urdf_string(text, base, "<string>", allow_nonphysical))

    @classmethod
    def from_yaml(cls, path) -> Model:
        """Load the YAML model format (docs/model_format.md)."""
        p = Path(path)
        return cls(_core.Model.from_yaml_string(_read(p), str(p)))

    @classmethod
    def from_yaml_string(cls, text: str) -> Model:
        return cls(_core.Model.from_yaml_string(text, "<string>"))

    def to_urdf(self, path=None) -> str:
        """Write the model as URDF (to `path` if given) and return the text. The base joint type is not
        part of URDF: choose it again with `from_urdf(..., base=...)`."""
        text = self._core.to_urdf_string()
        if path is not None:
            Path(path).write_text(text)
        return text

    @classmethod
    def from_mjcf(cls, path, name: str | None = None) -> Model:
        """Load a MuJoCo MJCF file (needs `pip install freefloat[mujoco]`). MuJoCo's own compiler reads it
        (defaults, angle units, orientations, inertia from geoms are what MuJoCo makes of them); a free joint
        at the root becomes the free base, no joint there a fixed base; hinge -> revolute, slide -> prismatic,
        ball -> spherical, no joint -> fixed, a hinge then a slide on one axis -> cylindrical, two orthogonal
        hinges -> universal. Tendons, equality constraints, contact-enabled geoms, armature and joint types
        freefloat lacks are refused with the element's name (and line when it has one). Tags written by
        `to_mjcf` come back. `path` may also be MJCF text."""
        import yaml

        from .io.mjcf import mjcf_spec

        return cls.from_yaml_string(yaml.safe_dump(mjcf_spec(path, name), sort_keys=False))

    def to_mjcf(self, path=None, gravity: bool = False) -> str:
        """Write the model as MuJoCo MJCF (to `path` if given) and return the text: a free joint on the base,
        inertias at full precision, `fusestatic`, `inertiafromgeom` and `balanceinertia` off (MuJoCo keeps
        every body and every number as written), zero gravity unless `gravity` (then the model's own), RK4
        with a 1 ms step, a motor per 1-DoF joint, frames as sites, body tags kept for `from_mjcf`."""
        text = self._core.to_mjcf_string(bool(gravity))
        if path is not None:
            Path(path).write_text(text)
        return text

    # -- description --------------------------------------------------------------------------------
    name = property(lambda self: self._core.name)
    nq = property(lambda self: self._core.nq, doc="Size of the configuration q.")
    nv = property(lambda self: self._core.nv, doc="Size of the velocity v.")
    nbodies = property(lambda self: self._core.nbodies)
    body_names = property(lambda self: self._core.body_names)
    joint_names = property(lambda self: self._core.joint_names, doc="Joint of each body; the base's is 'root_joint'.")
    joint_types = property(lambda self: self._core.joint_types)
    parents = property(lambda self: self._core.parents, doc="Parent body index of each body, -1 for the base.")
    idx_q = property(lambda self: self._core.idx_q, doc="Start of each body's joint coordinates in q.")
    idx_v = property(lambda self: self._core.idx_v, doc="Start of each body's joint rates in v.")
    nqs = property(lambda self: self._core.nqs)
    nvs = property(lambda self: self._core.nvs)
    joint_axes = property(lambda self: self._core.joint_axes)
    joint_axes2 = property(
        lambda self: self._core.joint_axes2,
        doc="Second axis of each universal joint (intermediate frame); z for other joints.",
    )
    placements = property(
        lambda self: self._core.placements, doc="(nbodies, 4, 4) rest placement of each joint frame in its parent."
    )
    limits = property(lambda self: self._core.limits)
    tags = property(lambda self: self._core.tags)
    frame_names = property(lambda self: self._core.frame_names)
    frames = property(lambda self: self._core.frames)
    gravity = property(lambda self: self._core.gravity)
    total_mass = property(lambda self: self._core.total_mass)

    def parameters(self) -> np.ndarray:
        """(nbodies, 10) standard inertial parameters, rows in `body_names` order."""
        return self._core.parameters()

    def with_parameters(self, P) -> Model:
        """A new model with parameters P (nbodies, 10), checked for physical consistency."""
        return Model(self._core.with_parameters(as_f64(P, "P")))

    def with_fixed_leaves_merged(self) -> Model:
        """A copy with every welded leaf (a fixed joint with nothing below it: a grasped target, a tool) merged
        into its parent body, and a frame of the leaf's name in its place: the same dynamics with fewer bodies
        (for algorithms that take moving joints only, such as DDP)."""
        return Model(self._core.with_fixed_leaves_merged())

    def leading_bodies(self, n: int) -> Model:
        """The model of the first `n` bodies: the last ones and their frames dropped, q and v the leading entries of
        this model's. The dynamics of the rest equal this model's when the dropped tail is massless (the chapter 8
        DDP robot's rate-driven wrist)."""
        return Model(self._core.leading_bodies(int(n)))

    def with_gravity(self, g) -> Model:
        g = as_f64(g, "g")
        if g.shape != (3,):
            raise InputError(f"argument `g`: expected 3 numbers, got shape {g.shape}")
        return Model(self._core.with_gravity(tuple(g)))

    def neutral(self) -> np.ndarray:
        """Configuration with identity quaternions and zero elsewhere."""
        return self._core.neutral()

    def random_configuration(self, rng: np.random.Generator | None = None, position_range: float = 1.0) -> np.ndarray:
        """A random configuration: uniform within joint limits where the model has them (else within
        ±pi for angles and ±`position_range` for positions), uniformly random unit quaternions."""
        rng = np.random.default_rng() if rng is None else rng
        q = self.neutral()
        lo, hi = self.limits["lower"], self.limits["upper"]
        for i, jt in enumerate(self.joint_types):
            s = self.idx_q[i]
            if i == 0 and jt == "free":
                q[s : s + 3] = rng.uniform(-position_range, position_range, 3)
                q[s + 3 : s + 7] = _random_quat(rng)
            elif i == 0 and jt == "planar":
                q[s : s + 2] = rng.uniform(-position_range, position_range, 2)
                q[s + 2] = rng.uniform(-np.pi, np.pi)
            elif jt == "spherical":
                q[s : s + 4] = _random_quat(rng)
            elif jt == "cylindrical":
                # the model's limits are scalars per joint: they are not applied to 2-coordinate joints
                q[s] = rng.uniform(-np.pi, np.pi)
                q[s + 1] = rng.uniform(-position_range, position_range)
            elif jt == "universal":
                q[s : s + 2] = rng.uniform(-np.pi, np.pi, 2)
            elif jt in ("revolute", "prismatic"):
                default = np.pi if jt == "revolute" else position_range
                a = lo[i] if np.isfinite(lo[i]) else -default
                b = hi[i] if np.isfinite(hi[i]) else default
                q[s] = rng.uniform(a, b)
        return q

    def q_labels(self) -> list[str]:
        """A name for every entry of q, e.g. base.x … base.qw, J1, ball.qx …, cyl.theta, cyl.d, cardan.theta1,
        cardan.theta2 (the two coordinates of a cylindrical or universal joint name the same thing in q and v)."""
        return self._labels(
            ("x", "y", "z", "qx", "qy", "qz", "qw"), ("x", "y", "yaw"), ("qx", "qy", "qz", "qw"), self.nqs
        )

    def v_labels(self) -> list[str]:
        """A name for every entry of v, e.g. base.vx … base.wz, J1, ball.wx …"""
        return self._labels(("vx", "vy", "vz", "wx", "wy", "wz"), ("vx", "vy", "wz"), ("wx", "wy", "wz"), self.nvs)

    def _labels(self, free, planar, spherical, sizes) -> list[str]:
        out = []
        for i, (jt, n) in enumerate(zip(self.joint_types, sizes)):
            owner = self.body_names[0] if i == 0 else self.joint_names[i]
            parts = (
                {
                    "free": free,
                    "planar": planar,
                    "spherical": spherical,
                    "cylindrical": ("theta", "d"),
                    "universal": ("theta1", "theta2"),
                }.get(jt)
                if n > 1
                else None
            )
            out += [f"{owner}.{p}" for p in parts] if parts else ([owner] if n == 1 else [])
        return out

    def joints_tagged(self, prefix: str) -> list[str]:
        """Names of the joints whose child body carries a tag starting with `prefix` (e.g. "arm_", "wheel")."""
        return [j for j, tags in zip(self.joint_names, self.tags) if any(t.startswith(prefix) for t in tags)]

    def body_index(self, name: str) -> int:
        try:
            return self.body_names.index(name)
        except ValueError:
            raise InputError(
                f"'{name}' is not a body of model '{self.name}' (bodies: {', '.join(self.body_names)})"
            ) from None

    def __repr__(self) -> str:
        return repr(self._core)


def _random_quat(rng) -> np.ndarray:
    x = rng.normal(size=4)
    return x / np.linalg.norm(x)


def _read(p: Path) -> str:
    if not p.exists():
        raise FileNotFoundError(f"model file not found: {p}")
    try:
        return p.read_text()
    except UnicodeDecodeError as e:
        raise _core.ModelError(f"{p}: not a text file ({e})") from None
