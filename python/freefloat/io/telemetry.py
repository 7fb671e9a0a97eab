"""Measured motion ("telemetry"): time, configuration and velocity samples of a robot, read from and
written to Parquet or CSV with named columns, validated on reading, and the measurement model of
Naveen, Shah, Misra (Sec. VI.C and Appendix C): white Gaussian noise on the measured rates and poses rebuilt by
integrating those noisy rates. Realistic sensors (gyro bias and random walks, star tracker, quantised
encoders and tachometers, latency, force/torque) are `freefloat.sensors.measure`, which builds a Telemetry;
its preset `sensors.naveen()` is the same measurement model as `add_noise` (docs/sensors.md).

Columns are named like `Trajectory.to_parquet`: `t`, `q.<label>` for `model.q_labels()` and `v.<label>`
for `model.v_labels()`, optionally `momentum.<px…Lz>` (the total momentum, when it is measured or known) or
`wrench.<fx…mz>` (the external wrench on the robot — thrusters, contact — in the inertial frame with the moment
about the inertial origin; the momentum is then its time integral, see `Telemetry.integrated_momentum`).
Conventions (docs/architecture.md): q = [base position, base quaternion xyzw, joints], v = [base linear, base
angular velocity in the BASE frame, joint rates]."""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .._core import InputError
from ..constants import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN
from ..simulation import MOMENTUM_NAMES

#: external wrench columns: force, then moment about the inertial origin, both in the inertial frame
WRENCH_NAMES = ["fx", "fy", "fz", "mx", "my", "mz"]

#: A time step longer than this multiple of the median step is reported as a gap.
GAP_FACTOR = 1.5


@dataclass
class Telemetry:
    """Samples of a motion: t (T,), q (T, nq), v (T, nv), optional momentum (T, 6) = [p; L about the
    inertial origin] in the inertial frame (e.g. the known total momentum), with the model's name and
    column labels."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    model_name: str = ""
    q_labels: list = field(default_factory=list)
    v_labels: list = field(default_factory=list)
    momentum: np.ndarray | None = None
    wrench: np.ndarray | None = None
    #: standard deviations (base linear, base angular, joint) of the white noise on the rates, when known (set by
    #: `add_noise`, kept in the file's metadata): identification then removes the errors-in-variables bias
    rate_noise: list | None = None

    def __post_init__(self):
        # Check shapes once here so every later step can trust them; name the offending field.
        self.t = np.asarray(self.t, dtype=float)
        self.q = np.asarray(self.q, dtype=float)
        self.v = np.asarray(self.v, dtype=float)
        n = self.t.shape[0] if self.t.ndim == 1 else -1
        if n < 0:
            raise InputError(f"Telemetry: t must be 1-D, got shape {self.t.shape}")
        for name in ("q", "v"):
            a = getattr(self, name)
            if a.ndim != 2 or a.shape[0] != n:
                raise InputError(f"Telemetry: {name} must be ({n}, n{name}) like t, got shape {a.shape}")
            labels = getattr(self, f"{name}_labels")
            if not labels:
                setattr(self, f"{name}_labels", [str(j) for j in range(a.shape[1])])
            elif len(labels) != a.shape[1]:
                raise InputError(f"Telemetry: {len(labels)} {name}_labels for {a.shape[1]} columns of {name}")
        if self.momentum is not None:
            self.momentum = np.asarray(self.momentum, dtype=float)
            if self.momentum.shape != (n, 6):
                raise InputError(f"Telemetry: momentum must be ({n}, 6), got shape {self.momentum.shape}")
        if self.wrench is not None:
            self.wrench = np.asarray(self.wrench, dtype=float)
            if self.wrench.shape != (n, 6):
                raise InputError(f"Telemetry: wrench must be ({n}, 6), got shape {self.wrench.shape}")

    def integrated_momentum(self, h0=None) -> np.ndarray:
        """(T, 6) total momentum h(t) = h0 + ∫₀ᵗ w dt from the recorded external wrench w = [f; m about the
        inertial origin] (trapezoidal rule; exact for a piecewise-linear wrench), starting at h0 (default
        zero: released at rest).  This is Naveen, Shah, Misra's "integrated external impulses" right-hand side."""
        if self.wrench is None:
            raise InputError("Telemetry.integrated_momentum: this telemetry has no wrench.* columns")
        h0 = np.zeros(6) if h0 is None else np.asarray(h0, dtype=float)
        if h0.shape != (6,):
            raise InputError(f"argument `h0`: expected 6 numbers [p; L], got shape {h0.shape}")
        steps = 0.5 * (self.wrench[1:] + self.wrench[:-1]) * np.diff(self.t)[:, None]
        return h0 + np.vstack([np.zeros(6), np.cumsum(steps, axis=0)])

    def __len__(self) -> int:
        return len(self.t)

    # -- building ------------------------------------------------------------------------------------
    @classmethod
    def from_trajectory(cls, traj) -> Telemetry:
        """The true (noise-free) telemetry of a simulated `Trajectory`."""
        return cls(
            t=traj.t.copy(),
            q=traj.q.copy(),
            v=traj.v.copy(),
            model_name=traj.model_name,
            q_labels=list(traj.q_labels),
            v_labels=list(traj.v_labels),
            momentum=traj.momentum.copy(),
        )

    # -- files ---------------------------------------------------------------------------------------
    def columns(self) -> dict:
        """Named columns in file order: t, q.*, v.*, then momentum.* and wrench.* if present."""
        cols = {"t": self.t}
        cols.update({f"q.{n}": self.q[:, j] for j, n in enumerate(self.q_labels)})
        cols.update({f"v.{n}": self.v[:, j] for j, n in enumerate(self.v_labels)})
        if self.momentum is not None:
            cols.update({f"momentum.{n}": self.momentum[:, j] for j, n in enumerate(MOMENTUM_NAMES)})
        if self.wrench is not None:
            cols.update({f"wrench.{n}": self.wrench[:, j] for j, n in enumerate(WRENCH_NAMES)})
        return cols

    def to_parquet(self, path) -> None:
        """Write one row per sample; the model name goes in the file metadata."""
        import pyarrow.parquet as pq

        from . import arrow

        info = {"model": self.model_name, "kind": "telemetry"}
        if self.rate_noise is not None:
            info["rate_noise"] = [float(x) for x in self.rate_noise]
        meta = {"freefloat": json.dumps(info)}
        pq.write_table(arrow.table(self.columns(), meta), str(path))

    def to_csv(self, path) -> None:
        """Write a comma-separated file: a `# model: <name>` comment line, a header of column names,
        then one row per sample at full double precision (%.17g, so a round trip is exact)."""
        cols = self.columns()
        data = np.column_stack(list(cols.values()))
        header = f"# model: {self.model_name}\n"
        if self.rate_noise is not None:
            header += "# rate_noise: " + ",".join(repr(float(x)) for x in self.rate_noise) + "\n"
        header += ",".join(cols)
        np.savetxt(str(path), data, delimiter=",", fmt="%.17g", header=header, comments="")

    @classmethod
    def from_file(cls, path, model) -> Telemetry:
        """Read Parquet (.parquet/.pq) or CSV (anything else) with named columns for `model` and
        validate it; problems raise `InputError` naming the column and/or row (0-based data rows,
        header excluded): missing columns, NaN/inf values, time not strictly increasing, gaps (a step
        longer than 1.5× the median step). Extra columns (e.g. ddq.*, tau.* of a Trajectory file) are
        ignored."""
        p = Path(path)
        if not p.exists():
            raise FileNotFoundError(f"telemetry file not found: {p}")
        telem = _from_columns(read_columns(p), model, str(p))
        telem.rate_noise = _read_rate_noise(p)
        return telem


# -- reading and validation ------------------------------------------------------------------------------
def _read_rate_noise(p: Path):
    """The rate-noise levels a file declares (Parquet metadata, or a `# rate_noise: a,b,c` CSV comment), or None."""
    try:
        if p.suffix.lower() in (".parquet", ".pq"):
            import pyarrow.parquet as pq

            meta = pq.read_schema(str(p)).metadata or {}
            r = json.loads(meta.get(b"freefloat", b"{}")).get("rate_noise")
        else:
            r = None
            with open(p, encoding="utf-8-sig") as f:
                for line in f:
                    if not line.startswith("#"):
                        break
                    if line.startswith("# rate_noise:"):
                        r = [float(x) for x in line.split(":", 1)[1].split(",")]
    except (ValueError, OSError):
        return None
    return None if r is None else [float(x) for x in r]


def read_columns(p: Path) -> dict:
    """The named float columns of a Parquet (.parquet/.pq) or CSV (anything else) file; a malformed file or a
    value that is not a number raises InputError naming the file, column and row."""
    return _read_parquet(p) if p.suffix.lower() in (".parquet", ".pq") else _read_csv(p)


def _read_parquet(p: Path) -> dict:
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(str(p))
    except (OSError, pa.ArrowException) as e:
        raise InputError(f"{p}: cannot be read as Parquet ({e})") from None
    cols = {}
    for c in table.column_names:
        try:
            cols[c] = np.asarray(table[c].to_numpy(zero_copy_only=False), dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{p}: column '{c}' is of type {table[c].type}, not numbers") from None
    return cols


def _read_csv(p: Path) -> dict:
    try:  # utf-8-sig: a byte-order mark (as spreadsheet programs write) is not part of the first column's name
        lines = p.read_text(encoding="utf-8-sig").splitlines()
    except UnicodeDecodeError as e:
        raise InputError(f"{p}: not UTF-8 text (byte {e.start}: {e.reason}); save the CSV file as UTF-8") from None
    body = [(i, ln) for i, ln in enumerate(lines) if ln.strip() and not ln.lstrip().startswith("#")]
    if not body:
        raise InputError(f"{p}: empty CSV file (no header line)")
    names = [c.strip().strip('"') for c in body[0][1].split(",")]  # pyarrow and spreadsheets quote the names
    rows = []
    for r, (i, ln) in enumerate(body[1:]):
        fields = ln.split(",")
        if len(fields) != len(names):
            raise InputError(f"{p}: data row {r} (line {i + 1}) has {len(fields)} fields, the header has {len(names)}")
        try:
            rows.append([float(x) for x in fields])
        except ValueError:
            bad = next(k for k, x in enumerate(fields) if not _is_float(x))
            raise InputError(
                f"{p}: column '{names[bad]}' row {r} (line {i + 1}): '{fields[bad].strip()}' is not a number"
            ) from None
    data = np.array(rows, dtype=float).reshape(len(rows), len(names))
    return {n: data[:, k] for k, n in enumerate(names)}


def _is_float(x: str) -> bool:
    try:
        float(x)
        return True
    except ValueError:
        return False


def _from_columns(cols: dict, model, where: str) -> Telemetry:
    ql, vl = model.q_labels(), model.v_labels()
    need = ["t"] + [f"q.{n}" for n in ql] + [f"v.{n}" for n in vl]
    missing = [c for c in need if c not in cols]
    if missing:
        raise InputError(f"{where}: missing columns for model '{model.name}': {', '.join(missing)}")
    has_h = _optional_block(cols, "momentum", MOMENTUM_NAMES, where)
    has_w = _optional_block(cols, "wrench", WRENCH_NAMES, where)
    used = (
        need
        + ([f"momentum.{n}" for n in MOMENTUM_NAMES] if has_h else [])
        + ([f"wrench.{n}" for n in WRENCH_NAMES] if has_w else [])
    )
    check_finite(cols, used, where)
    t = cols["t"]
    _check_time(t, where)
    return Telemetry(
        t=t.copy(),
        q=np.column_stack([cols[f"q.{n}"] for n in ql]),
        v=np.column_stack([cols[f"v.{n}"] for n in vl]),
        model_name=model.name,
        q_labels=ql,
        v_labels=vl,
        momentum=np.column_stack([cols[f"momentum.{n}"] for n in MOMENTUM_NAMES]) if has_h else None,
        wrench=np.column_stack([cols[f"wrench.{n}"] for n in WRENCH_NAMES]) if has_w else None,
    )


def _optional_block(cols: dict, prefix: str, names: list, where: str) -> bool:
    """True when all of prefix.<names> are present, False when none are; a partial block is an error."""
    have = [n for n in names if f"{prefix}.{n}" in cols]
    if have and len(have) != len(names):
        missing = [f"{prefix}.{n}" for n in names if n not in have]
        raise InputError(f"{where}: incomplete {prefix} columns: missing {', '.join(missing)}")
    return bool(have)


def check_finite(cols: dict, names: list, where: str) -> None:
    for c in names:
        bad = ~np.isfinite(cols[c])
        if bad.any():
            r = int(np.argmax(bad))
            raise InputError(
                f"{where}: column '{c}' row {r} is {cols[c][r]} (not finite); "
                f"{int(bad.sum())} such value(s) in this column"
            )


def check_increasing(t: np.ndarray, where: str, first_line: int | None = None) -> None:
    """InputError naming the first row (counted from 0) whose time is not later than the one before; with
    `first_line` (the file line of row 0, 2 for a CSV with its header) also that row's line."""
    dt = np.diff(t)
    if np.any(dt <= 0):
        r = int(np.argmax(dt <= 0)) + 1
        line = f", line {r + first_line}" if first_line is not None else ""
        raise InputError(
            f"{where}: time is not strictly increasing at row {r}{line} (t = {float(t[r])!r} after {float(t[r - 1])!r})"
        )


def _check_time(t: np.ndarray, where: str) -> None:
    if t.size < 2:
        return
    check_increasing(t, where)
    dt = np.diff(t)
    med = float(np.median(dt))
    gap = dt > GAP_FACTOR * med
    if gap.any():
        r = int(np.argmax(gap)) + 1
        raise InputError(
            f"{where}: gap in time before row {r}: step {dt[r - 1]:.6g} s from t = {float(t[r - 1])!r} to "
            f"{float(t[r])!r} is more than {GAP_FACTOR}× the median step {med:.6g} s ({int(gap.sum())} gap(s))"
        )


# -- measurement model (Naveen, Shah, Misra Sec. VI.C, Appendix C) -------------------------------------------------
def add_noise(
    telem: Telemetry,
    model,
    rng,
    sigma_lin: float = SIGMA_LIN,
    sigma_ang: float = SIGMA_ANG,
    sigma_joint: float = SIGMA_JOINT,
    reconstruct_poses: bool = True,
) -> Telemetry:
    """Noisy telemetry as in Naveen, Shah, Misra Sec. VI.C (`rng`: a numpy Generator or a seed): zero-mean white
    Gaussian noise, independent per sample and component, added to the measured rates with standard deviations
    sigma_lin on the base linear velocity (m/s), sigma_ang on the base angular velocity (rad/s) and sigma_joint on every
    joint rate (rad/s, or m/s for prism. joints), reaction wheels included (they are joints; the paper
    adds noise to "the joint rates and base velocities").

    Frame: the paper's velocities are inertial-frame; ours are base-frame. Isotropic noise n ~ N(0, σ²E)
    satisfies R n ~ N(0, σ²E) for any rotation R independent of n, so adding it in the base frame is
    statistically the same measurement model. The paper measures Euler rates and converts them to ω
    (eq. 46) yet quotes σ on ω; we add the noise to ω directly.

    reconstruct_poses: rebuild q by integrating the NOISY rates from the true initial pose, as the paper
    does (Appendix C), so rate noise leaks into the poses (see `integrate_poses` for the scheme).
    Otherwise q is left exact. The momentum column, if any, is left unchanged (it is a known quantity)."""
    rng = np.random.default_rng(rng)  # accepts a Generator (used as is) or a seed
    if telem.v.shape[1] != model.nv:
        raise InputError(
            f"add_noise: telemetry has {telem.v.shape[1]} velocity columns, model '{model.name}' has nv = {model.nv}"
        )
    v = telem.v.copy()
    nb = _base_dofs(model)
    if nb == 6:
        v[:, 0:3] += rng.normal(0.0, sigma_lin, (len(v), 3))
        v[:, 3:6] += rng.normal(0.0, sigma_ang, (len(v), 3))
    elif nb == 3:  # planar base: (vx, vy, wz)
        v[:, 0:2] += rng.normal(0.0, sigma_lin, (len(v), 2))
        v[:, 2] += rng.normal(0.0, sigma_ang, len(v))
    v[:, nb:] += rng.normal(0.0, sigma_joint, (len(v), model.nv - nb))
    q = integrate_poses(model, telem.t, v, telem.q[0]) if reconstruct_poses else telem.q.copy()
    return replace(
        telem,
        q=q,
        v=v,
        momentum=None if telem.momentum is None else telem.momentum.copy(),
        rate_noise=[float(sigma_lin), float(sigma_ang), float(sigma_joint)],
    )


def integrate_poses(model, t, v, q0, rule: str = "trapezoid") -> np.ndarray:
    """Configurations (T, nq) obtained by integrating velocities v (T, nv) from q0 at times t (T,).

    The paper (Appendix C, eqs. 44–47) uses explicit Euler on the base position, Z-X-Y Euler angles and
    joint angles. We use the trapezoidal rule on every step instead (second order, and it uses both
    samples of a step, which is what a sampled measurement gives), and keep the attitude on the rotation
    group rather than on Euler angles (no singularity, our q stores a quaternion):
      joints    q_{k+1} = q_k + (q̇_k + q̇_{k+1}) Δt/2
      attitude  Q_{k+1} = Q_k ⊗ exp((ω_k + ω_{k+1}) Δt/2)     (ω body-frame, so right multiplication)
      position  r_{k+1} = r_k + (R_k v_k + R_{k+1} v_{k+1}) Δt/2   (v body-frame, R_k from Q_k)
    A planar base integrates yaw like a joint and its position with R(yaw); a fixed base has no base
    pose. Time steps may be uneven.

    The base pose is the engine's `integrate_base_poses` (one copy of the rule, shared with the exciting-
    trajectory design); the joints' trapezoid is a cumulative sum here.

    `rule="hermite"`: fourth order. Every step adds the endpoint correction of the cubic Hermite interpolant,
    h²/12 (a_k − a_{k+1}) for the joints (a the rates' derivative), and the engine's fourth-order correction for the
    base (its Magnus term for the attitude). The derivatives are the rates' second-order differences
    (`np.gradient`, one-sided at the ends), whose O(h²) error changes the step only at O(h⁵). On noisy rates the
    correction adds about a twelfth of the trapezoid's own noise per step."""
    from ..algorithms import integrate_base_poses

    if rule not in ("trapezoid", "hermite"):
        raise InputError(f"integrate_poses: rule must be 'trapezoid' or 'hermite', got {rule!r}")
    t = np.asarray(t, dtype=float)
    v = np.asarray(v, dtype=float)
    q = np.empty((len(t), model.nq))
    q[0] = q0
    dt = np.diff(t)[:, None]
    nb = _base_dofs(model)
    jq, jv = _joint_slices(model)
    a = np.gradient(v, t, axis=0, edge_order=2) if rule == "hermite" and len(t) >= 3 else None
    # Joints: cumulative trapezoid (and its Hermite correction), vectorised.
    step = (v[:-1, jv] + v[1:, jv]) * dt / 2
    if a is not None:
        step = step + (a[:-1, jv] - a[1:, jv]) * dt**2 / 12
    q[1:, jq] = q0[jq] + np.cumsum(step, axis=0)
    if nb == 6:
        q[:, 0:7] = integrate_base_poses(t, v[:, 0:6], q0[0:7], None if a is None else a[:, 0:6])
    elif nb == 3:
        q[:, 0:3] = integrate_base_poses(t, v[:, 0:3], q0[0:3], None if a is None else a[:, 0:3])
    return q


def _base_dofs(model) -> int:
    jt = model.joint_types[0]
    if jt == "free":
        return 6
    if jt == "planar":
        return 3
    if model.nvs[0] == 0:
        return 0
    raise InputError(f"model '{model.name}': base joint type '{jt}' is not supported by the telemetry tools")


def _joint_slices(model):
    """Index arrays of the (1-DoF) joint coordinates in q and v, base excluded."""
    iq, iv = [], []
    for b in range(1, model.nbodies):
        if model.nqs[b] != model.nvs[b]:
            raise InputError(
                f"model '{model.name}': joint '{model.joint_names[b]}' ({model.joint_types[b]}) has nq != nv; "
                "only revolute/prismatic joints are supported by pose reconstruction"
            )
        iq += range(model.idx_q[b], model.idx_q[b] + model.nqs[b])
        iv += range(model.idx_v[b], model.idx_v[b] + model.nvs[b])
    return np.array(iq, dtype=int), np.array(iv, dtype=int)


def from_trajectory(traj) -> Telemetry:
    """Module-level alias of `Telemetry.from_trajectory`."""
    return Telemetry.from_trajectory(traj)
