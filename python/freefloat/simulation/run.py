"""Simulation front end and the `Trajectory` it returns.

The integrators are the engine's: fixed-step RK4 and adaptive Dormand-Prince 5(4), both on the
configuration group (rotations advanced by the exponential map with the dexp⁻¹ correction, so RK4
stays fourth order on the base attitude)."""

from __future__ import annotations

import json
import math
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _core
from .._arrays import as_f64
from .._core import InputError
from ..model import Model

MOMENTUM_NAMES = ["px", "py", "pz", "Lx", "Ly", "Lz"]
#: the standard inertial parameters of a body, in `Model.parameters()` order (the `base_parameters` columns)
PARAMETER_NAMES = ["m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz"]
#: inertial position and velocity of the simulation frame's origin (the `orbit` columns)
ORBIT_NAMES = ["x", "y", "z", "vx", "vy", "vz"]


@dataclass
class Trajectory:
    """A recorded motion. Arrays have a leading time axis: q (T, nq), v/ddq/tau (T, nv),
    momentum (T, 6) = [p; L about the inertial origin] in the inertial frame, kinetic_energy and
    work (T,). `tau` holds the generalized forces that acted (for prescribed joints: those they
    needed; for wheels: motor torque minus friction); `work` is the integral of tau·v (plus the power of
    thrusters and wheel jitter) since t = 0, so kinetic_energy - kinetic_energy[0] should equal it.
    With propellant tanks, `propellant` (T, number of tanks) is the mass left in each and `base_parameters`
    (T, 10) the base's standard inertial parameters over time; otherwise both are empty (T, 0)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    ddq: np.ndarray
    tau: np.ndarray
    momentum: np.ndarray
    kinetic_energy: np.ndarray
    work: np.ndarray
    model_name: str = ""
    propellant: np.ndarray | None = None
    base_parameters: np.ndarray | None = None
    q_labels: list = field(default_factory=list)
    v_labels: list = field(default_factory=list)
    stats: dict = field(default_factory=dict)
    orbit: np.ndarray | None = None
    """With an orbital environment: (T, 6) inertial [position, velocity] of the simulation frame's origin (from
    the central body's centre); a body's inertial position is this plus its local one."""

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        """A summary (model, samples, time span, sizes, conservation), not every array."""
        if len(self.t) == 0:
            return f"Trajectory('{self.model_name}': no samples)"
        d, e = self.momentum_drift(), self.energy_balance()
        how = ", ".join(f"{k}={self.stats[k]}" for k in ("method", "formulation") if k in self.stats)
        return (
            f"Trajectory('{self.model_name}': {len(self.t)} samples, t = {self.t[0]:g} .. {self.t[-1]:g} s, "
            f"nq={self.q.shape[1]}, nv={self.v.shape[1]}{', ' + how if how else ''}; momentum drift "
            f"linear {d['linear_rel']:.2g}, angular {d['angular_rel']:.2g} (relative); "
            f"energy - work {e['rel']:.2g} (relative))"
        )

    def integration_warning(self, limit: float = 1e-8) -> str | None:
        """A sentence when the integration error is visible — momentum drift or kinetic energy minus work
        above `limit` (relative) — suggesting a smaller step or rk45; None when the run stays near round-off."""
        if self.stats.get("external_forces"):
            return None  # an environment's forces change momentum and do work that `work` does not hold
        d, e = self.momentum_drift(), self.energy_balance()
        worst = max(d["linear_rel"], d["angular_rel"], e["rel"])
        if worst <= limit:
            return None
        dt = self.stats.get("dt")
        step = f"a smaller step (--dt {dt / 10:g})" if dt else "a smaller step"
        return (
            f"integration error is visible: momentum drift (linear {d['linear_rel']:.2g}, angular "
            f"{d['angular_rel']:.2g}) or energy minus work ({e['rel']:.2g}) exceeds {limit:g} relative; "
            f"these should stay near round-off. Use {step} or the adaptive integrator (--method rk45); fast "
            "start-up transients (large accelerations) are the usual cause."
        )

    def to_csv(self, path) -> None:
        """Write a comma-separated file with the columns of `to_parquet`, a `# model:` comment first, every
        number at full double precision (%.17g)."""
        cols = self._columns()
        header = f"# model: {self.model_name}\n" + ",".join(cols)
        np.savetxt(
            str(path), np.column_stack(list(cols.values())), delimiter=",", fmt="%.17g", header=header, comments=""
        )

    def _columns(self) -> dict:
        cols = {"t": self.t}
        ql = self.q_labels or [str(j) for j in range(self.q.shape[1])]
        vl = self.v_labels or [str(j) for j in range(self.v.shape[1])]
        for prefix, arr, labels in (("q", self.q, ql), ("v", self.v, vl), ("ddq", self.ddq, vl), ("tau", self.tau, vl)):
            for j in range(arr.shape[1]):
                cols[f"{prefix}.{labels[j]}"] = arr[:, j]
        for j, n in enumerate(MOMENTUM_NAMES):
            cols[f"momentum.{n}"] = self.momentum[:, j]
        cols["kinetic_energy"] = self.kinetic_energy
        cols["work"] = self.work
        # what only some runs record: propellant left per tank, the base's inertial parameters (they change as a
        # tank drains), the orbit of the frame origin (with an environment)
        for prefix, arr, names in (
            ("propellant", self.propellant, None),
            ("base_parameters", self.base_parameters, PARAMETER_NAMES),
            ("orbit", self.orbit, ORBIT_NAMES),
        ):
            if arr is not None and np.size(arr) and np.shape(arr)[0] == len(self.t):
                for j in range(np.shape(arr)[1]):
                    cols[f"{prefix}.{names[j] if names else j}"] = np.asarray(arr)[:, j]
        return cols

    def to_numpy(self) -> dict:
        """All recorded arrays by name (with tanks also `propellant` and `base_parameters`)."""
        out = {k: getattr(self, k) for k in ("t", "q", "v", "ddq", "tau", "momentum", "kinetic_energy", "work")}
        for k in ("propellant", "base_parameters"):
            x = getattr(self, k)
            if x is not None and x.size:
                out[k] = x
        return out

    # -- conservation summaries -------------------------------------------------------------------------
    def momentum_drift(self) -> dict:
        """Largest deviation of linear and angular momentum from their initial values, absolute and
        relative to a momentum scale: the largest |p| (|L|) reached, or, if larger, the momentum the
        motion's kinetic energy represents (sqrt(2 M E) and sqrt(2 J E), with M the total mass and
        J the larger of M R² (R the largest distance of a body from the centre of mass at t = 0) and the
        largest principal moment of the whole system's inertia about its centre of mass at t = 0, both
        recorded by `simulate` in stats). The second scale keeps the figure meaningful when the momentum
        itself is zero, as in a robot starting at rest; the principal moment keeps it meaningful when
        every body sits at the centre of mass (R = 0, a hub with balanced wheels)."""
        dp = np.linalg.norm(self.momentum[:, :3] - self.momentum[0, :3], axis=1).max()
        dl = np.linalg.norm(self.momentum[:, 3:] - self.momentum[0, 3:], axis=1).max()
        e = np.abs(self.kinetic_energy).max()
        mass, radius = self.stats.get("total_mass", 0.0), self.stats.get("radius", 0.0)
        sp = max(np.linalg.norm(self.momentum[:, :3], axis=1).max(), np.sqrt(2 * mass * e), 1e-300)
        j = max(mass * radius**2, self.stats.get("rotational_inertia", 0.0))
        sl = max(np.linalg.norm(self.momentum[:, 3:], axis=1).max(), np.sqrt(2 * j * e), 1e-300)
        return {
            "linear_abs": float(dp),
            "angular_abs": float(dl),
            "linear_rel": float(dp / sp),
            "angular_rel": float(dl / sl),
        }

    def energy_balance(self) -> dict:
        """Largest |ΔE_kin − W| over the run, absolute and relative to the largest kinetic energy."""
        err = np.abs(self.kinetic_energy - self.kinetic_energy[0] - self.work).max()
        scale = max(np.abs(self.kinetic_energy).max(), np.abs(self.work).max(), 1e-300)
        return {"abs": float(err), "rel": float(err / scale)}

    # -- files ----------------------------------------------------------------------------------------
    def to_parquet(self, path) -> None:
        """Write to a Parquet file: one row per sample, columns t, q.<joint>[.k], v.…, ddq.…, tau.…,
        momentum.<px…Lz>, kinetic_energy, work (and, when the run has them, propellant.<tank index>,
        base_parameters.<m…Izz>, orbit.<x…vz>); the model name and run statistics in the metadata."""
        import pyarrow.parquet as pq

        from ..io import arrow

        meta = {"freefloat": json.dumps({"model": self.model_name, "stats": self.stats})}
        pq.write_table(arrow.table(self._columns(), meta), str(path))

    @classmethod
    def from_parquet(cls, path) -> Trajectory:
        """Read a file written by `to_parquet`."""
        import pyarrow.parquet as pq

        p = Path(path)
        if not p.exists():
            raise FileNotFoundError(f"trajectory file not found: {p}")
        table = pq.read_table(str(p))
        names = table.column_names
        need = ["t", "kinetic_energy", "work"] + [f"momentum.{n}" for n in MOMENTUM_NAMES]
        missing = [n for n in need if n not in names]
        if missing:
            raise InputError(f"{p}: not a freefloat trajectory; missing columns {missing}")

        def block(prefix):
            # Columns keep the file's order, which is q/v order.
            cs = [c for c in names if c.startswith(prefix + ".")]
            return np.column_stack([table[c].to_numpy() for c in cs]) if cs else np.zeros((table.num_rows, 0))

        def labels(prefix):
            return [c[len(prefix) + 1 :] for c in names if c.startswith(prefix + ".")]

        raw = (table.schema.metadata or {}).get(b"freefloat", b"{}")
        meta = json.loads(raw)
        return cls(
            t=table["t"].to_numpy(),
            q=block("q"),
            v=block("v"),
            ddq=block("ddq"),
            tau=block("tau"),
            momentum=np.column_stack([table[f"momentum.{n}"].to_numpy() for n in MOMENTUM_NAMES]),
            kinetic_energy=table["kinetic_energy"].to_numpy(),
            work=table["work"].to_numpy(),
            model_name=meta.get("model", ""),
            q_labels=labels("q"),
            v_labels=labels("v"),
            stats=meta.get("stats", {}),
            propellant=block("propellant") if labels("propellant") else None,
            base_parameters=block("base_parameters") if labels("base_parameters") else None,
            orbit=block("orbit") if labels("orbit") else None,
        )


def simulate(
    model: Model,
    q0,
    v0,
    t_final: float,
    dt: float,
    *,
    method: str = "rk4",
    rtol: float = 1e-9,
    atol: float = 1e-12,
    max_step: float | None = None,
    record_every: int = 1,
    torques=None,
    torque_times=None,
    hold: str = "zoh",
    controller=None,
    controller_period: float | None = None,
    prescribed=None,
    prescription=None,
    progress=False,
    max_steps: int = 50_000_000,
    formulation: str = "aba",
    actuators=None,
    input_timing: str | None = None,
    max_memory: float | None = None,
    environment: _core.Environment | None = None,
) -> Trajectory:
    """Simulate the model from (q0, v0) for t_final seconds.

    The run is sized before it starts: the recorded trajectory (samples x state size x 8 bytes) must fit in
    `max_memory` bytes (default: half the memory available, see `memory_limit`; `math.inf` turns the check
    off), and RK4 must finish within max_steps; otherwise it is refused with an InputError. Ctrl-C (or a
    `progress` callable returning False) stops it within a fraction of a second and raises
    `freefloat.Interrupted` (a KeyboardInterrupt) whose `partial` is the Trajectory recorded so far.

    method: "rk4" (fixed step dt) or "rk45" (Dormand-Prince with rtol/atol; dt is then the output
    interval and steps land exactly on output times and controller samples).
    torques: generalized forces (nv,) — None (zero), a function torques(t, q, v), or an array
      (T, nv) read at torque_times (default k·dt) with hold="zoh" or "linear". For a free base the
      first six entries are the thruster wrench [force; torque] in the base frame; reaction wheels
      are ordinary joints.
    controller: controller(t, q, v) -> (nv,) called at t = k·controller_period for every such t up to
      and including t_final; its output is held (zero-order hold) and added to torques. With RK4 the
      period should be a multiple of dt (otherwise a sample waits for the next step).
    prescribed / prescription: joint names that follow prescription(t) -> (q, v, a) (full-length
      arrays; only the prescribed joints' entries are used) while the rest responds (hybrid
      dynamics); the recorded tau then holds the forces these joints needed.
    progress: True for a progress bar, or a callable progress(fraction) returning False to abort.
    formulation: "aba" (the engine's articulated-body algorithm) or "dq" (the dual-quaternion Newton-Euler
      system of Valverde 2018 ch. 6, `dq_dynamics`: same motion to round-off, slower; free or fixed base with
      revolute, prismatic, spherical, cylindrical, universal and fixed joints). With "dq" the recorded momentum
      and kinetic energy are the formulation's own (2.53)/(2.54).
    actuators: a `freefloat.Actuators` (reaction wheels on revolute joints, thrusters, propellant tanks) or the
      equivalent mapping (a YAML `actuators:` block), evaluated in the engine at every step (docs/actuators.md).
      The model's joint limits (effort, velocity) apply in every run: the commanded force is clipped to
      ±effort and a command that would drive a joint further past its velocity limit becomes zero.
    input_timing: when the torques are read within a step. "step": once, at the step's start, and held through
      its stages, with the joint limits and the wheel saturation applied to that held command; a zero-order-hold
      switch on a step boundary then acts from exactly there (rk45 lands on every table time). "stage": at every
      Runge-Kutta stage time (keeps RK4's fourth order for a smooth torque function; a held table switch on a step
      boundary then leaks 1/6 of a step into the step before). Default (None): "stage" for a torque function
      f(t, q, v) (a control law acts continuously) and "step" for a table or no torques. A table with
      hold="linear" is read at every stage in both cases.
    environment: a `freefloat.Environment` (orbit with gravity gradient, J2, a constant disturbance); its forces
      reach every body as external wrenches, and the returned trajectory's `orbit` holds the inertial state of
      the simulation frame's origin. None (the default): no external forces at all."""
    if not isinstance(model, Model):
        raise TypeError(f"expected a freefloat.Model, got {type(model).__name__}")
    if isinstance(prescribed, str):
        prescribed = [prescribed]
    bar = None
    try:
        drawable = math.isfinite(float(t_final)) and float(t_final) > 0
    except (TypeError, ValueError):
        drawable = False  # the engine names the argument
    if progress is True and drawable:
        from tqdm.auto import tqdm

        bar = tqdm(
            total=float(t_final),
            desc=f"simulate {model.name}",
            leave=False,
            bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.2f}/{total:.2f} s simulated [{elapsed}<{remaining}]",
        )
        cb = _bar_callback(bar, float(t_final))
    else:
        cb = progress if callable(progress) else None
    tt = None if torque_times is None else as_f64(torque_times, "torque_times")
    if torques is not None and not callable(torques):
        torques = as_f64(torques, "torques")
    acts = None
    if actuators is not None:
        from .actuators import Actuators

        if isinstance(actuators, dict):
            actuators = Actuators.from_dict(actuators)
        if not isinstance(actuators, Actuators):
            raise InputError(
                f"argument `actuators`: expected a freefloat.Actuators or a mapping, got {type(actuators).__name__}"
            )
        acts = actuators.to_dict()
    if input_timing is None:
        input_timing = "stage" if callable(torques) else "step"
    _warn_silent_ends(t_final, dt, method, torques, tt, hold)
    limit = memory_limit() if max_memory is None else float(max_memory)
    try:
        out = _core.simulate(
            model._core,
            as_f64(q0, "q0"),
            as_f64(v0, "v0"),
            float(t_final),
            float(dt),
            method,
            rtol,
            atol,
            max_step,
            int(record_every),
            torques,
            tt,
            hold,
            controller,
            controller_period,
            prescribed,
            prescription,
            int(max_steps),
            cb,
            formulation,
            acts,
            input_timing,
            limit,
            environment,
        )
        if bar is not None:  # a finished run fills its bar (however fast it was: tqdm redraws at most every 0.1 s)
            bar.update(bar.total - bar.n)
            bar.refresh()
    except _core.Interrupted as e:
        # what was finished comes with the interruption, as a Trajectory
        if isinstance(getattr(e, "partial", None), dict):
            e.partial = _trajectory(model, e.partial, q0, method, formulation, dt, t_final, input_timing, environment)
            e.partial.stats["interrupted"] = str(e)
        raise
    finally:
        if bar is not None:
            bar.close()
    return _trajectory(model, out, q0, method, formulation, dt, t_final, input_timing, environment)


def _trajectory(model, out: dict, q0, method, formulation, dt, t_final, input_timing, environment) -> Trajectory:
    stats = {k: out.pop(k) for k in ("steps", "rejected", "evaluations")}
    orbit = out.pop("orbit", None)
    if environment is not None and not environment.is_off:
        stats.update(environment=repr(environment), external_forces=True)
    stats.update(
        method=method,
        formulation=formulation,
        dt=dt,
        t_final=t_final,
        total_mass=model.total_mass,
        radius=_radius(model, q0),
        rotational_inertia=_rotational_inertia(model, q0),
        input_timing=input_timing,
    )
    return Trajectory(
        **out, model_name=model.name, q_labels=model.q_labels(), v_labels=model.v_labels(), stats=stats, orbit=orbit
    )


def memory_limit(fraction: float = 0.5) -> float:
    """The default `max_memory` of `simulate`: `fraction` of the memory available now (Linux: MemAvailable of
    /proc/meminfo; elsewhere the physical memory from os.sysconf; 8 GB when neither can be read), in bytes. The
    environment variable FREEFLOAT_MAX_MEMORY (bytes, or with a suffix: 500M, 4G) overrides it."""
    env = os.environ.get("FREEFLOAT_MAX_MEMORY")
    if env:
        units = {"K": 1e3, "M": 1e6, "G": 1e9, "T": 1e12}
        try:
            e = env.strip().upper().rstrip("B")
            return float(e[:-1]) * units[e[-1]] if e and e[-1] in units else float(e)
        except (ValueError, IndexError):
            raise InputError(f"FREEFLOAT_MAX_MEMORY={env!r}: expected a number of bytes, e.g. 2e9 or 2G") from None
    avail = None
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    avail = float(line.split()[1]) * 1024
                    break
    except OSError:
        pass
    if avail is None:
        try:
            avail = float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
        except (AttributeError, ValueError, OSError):
            avail = 16e9
    return fraction * avail


def _warn_silent_ends(t_final, dt, method, torques, torque_times, hold) -> None:
    """Visible warnings for the two ways a run can quietly differ from what was asked: a fixed-step run whose
    t_final is not a multiple of dt (it ends at round(t_final/dt)·dt), and a torque table that ends long before
    t_final (its last row is then held for the rest of the run)."""
    try:
        t_final, dt = float(t_final), float(dt)
    except (TypeError, ValueError):
        return  # the engine names the argument
    if not (math.isfinite(t_final) and math.isfinite(dt) and t_final > 0 and dt > 0):
        return
    if method == "rk4":
        n = round(t_final / dt)
        t_end = n * dt
        if abs(t_end - t_final) > 1e-9 * max(t_final, dt):
            warnings.warn(
                f"t_final = {t_final:g} s is not a multiple of dt = {dt:g} s: the fixed-step run takes {n} steps and "
                f"ends at t = {t_end:.12g} s; choose t_final = k·dt, or method='rk4' with another dt, or 'rk45'",
                UserWarning,
                stacklevel=3,
            )
    if torques is None or callable(torques) or np.ndim(torques) != 2 or len(torques) < 2:
        return  # None, a function, or one constant row: nothing that can run out
    rows = len(torques)
    times = np.arange(rows) * dt if torque_times is None else np.asarray(torque_times, dtype=float)
    if len(times) != rows or not np.all(np.isfinite(times)):
        return  # the engine reports it
    # zero-order hold: the last row covers one table interval past its time; linear hold ends at its time
    step = float(np.median(np.diff(times))) if rows > 1 else dt
    end = float(times[-1]) + (step if hold == "zoh" else 0.0)
    past = t_final - end
    if past > 1e-9 * t_final and past > 0.01 * t_final:
        warnings.warn(
            f"the torque table ({rows} rows) ends at t = {end:g} s but the run lasts {t_final:g} s: its last row is "
            f"held for the remaining {past:g} s ({100 * past / t_final:.1f} % of the run); give rows up to t_final "
            "or a shorter t_final",
            UserWarning,
            stacklevel=3,
        )


def simulate_driven(
    model: Model,
    trajectory,
    joints,
    dt: float,
    *,
    held=(),
    t_final: float | None = None,
    record_every: int = 1,
    progress=False,
) -> Trajectory:
    """Simulate `model` while the named `joints` follow a joint `trajectory` (an object with `prescription`
    and `duration`, e.g. from `freefloat.trajectories`) and the joints in `held` stay at their neutral angle; the
    base floats with zero total momentum, its initial twist solved from the momentum model,
    A_b v_b = −A_j q̇_j (Naveen, Shah, Misra; the engine's `base_twist_for_momentum`). t_final: default the
    trajectory's duration."""
    from ..algorithms import base_twist_for_momentum

    presc = trajectory.prescription(model, joints)  # entries it does not drive: neutral angle, at rest
    q0, v0, _ = presc(0.0)
    nb = model.nvs[0]
    v0[:nb] = base_twist_for_momentum(model, q0, v0[nb:])
    t_final = trajectory.duration if t_final is None else t_final
    return simulate(
        model,
        q0,
        v0,
        t_final,
        dt,
        prescribed=list(joints) + list(held),
        prescription=presc,
        record_every=record_every,
        progress=progress,
    )


def _bar_callback(bar, total: float):
    """Progress callback that moves a tqdm bar to the simulated time reached (fraction × total seconds)."""

    def cb(frac):
        bar.update(frac * total - bar.n)
        return True

    return cb


def _radius(model: Model, q) -> float:
    """Largest distance of a body's centre of mass from the system's, at q (a length scale)."""
    from ..algorithms import center_of_mass, forward_kinematics, quat_to_matrix

    fk = forward_kinematics(model, q)
    P = model.parameters()
    massive = P[:, 0] > 0
    coms = fk[massive, :3] + np.einsum("bij,bj->bi", quat_to_matrix(fk[massive, 3:7]), P[massive, 1:4] / P[massive, :1])
    return float(np.linalg.norm(coms - center_of_mass(model, q), axis=1).max())


def _rotational_inertia(model: Model, q) -> float:
    """Largest principal moment (kg m²) of the whole system's inertia about its centre of mass at q, the bodies
    locked (from the engine's composite inertia: the base block of the joint-space inertia matrix); 0 for a
    base that is not free."""
    from ..algorithms import crba

    if model.nvs[0] != 6:
        return 0.0
    mb = crba(model, q)[:6, :6]  # [lin; ang] base block, base frame about the base origin
    mass = mb[0, 0]
    if not mass > 0:
        return 0.0
    cx = mb[3:, :3] / mass  # M [c]x
    c = np.array([cx[2, 1], cx[0, 2], cx[1, 0]])
    i_c = mb[3:, 3:] - mass * (c @ c * np.eye(3) - np.outer(c, c))
    return float(np.linalg.eigvalsh(0.5 * (i_c + i_c.T)).max())
