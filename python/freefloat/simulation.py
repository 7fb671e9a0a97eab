"""Simulation front end and the `Trajectory` it returns.

The integrators are the engine's: fixed-step RK4 and adaptive Dormand-Prince 5(4), both on the
configuration group (rotations advanced by the exponential map with the dexp⁻¹ correction, so RK4
stays fourth order on the base attitude)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import _core
from ._arrays import as_f64
from ._core import InputError
from .model import Model

MOMENTUM_NAMES = ["px", "py", "pz", "Lx", "Ly", "Lz"]


@dataclass
class Trajectory:
    """A recorded motion. Arrays have a leading time axis: q (T, nq), v/ddq/tau (T, nv),
    momentum (T, 6) = [p; L about the inertial origin] in the inertial frame, kinetic_energy and
    work (T,). `tau` holds the generalized forces that acted (for prescribed joints: those they
    needed); `work` is the integral of tau·v since t = 0, so kinetic_energy - kinetic_energy[0]
    should equal it."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    ddq: np.ndarray
    tau: np.ndarray
    momentum: np.ndarray
    kinetic_energy: np.ndarray
    work: np.ndarray
    model_name: str = ""
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
        return cols

    def to_numpy(self) -> dict:
        """All recorded arrays by name."""
        return {k: getattr(self, k) for k in ("t", "q", "v", "ddq", "tau", "momentum", "kinetic_energy", "work")}

    # -- conservation summaries -------------------------------------------------------------------------
    def momentum_drift(self) -> dict:
        """Largest deviation of linear and angular momentum from their initial values, absolute and
        relative to a momentum scale: the largest |p| (|L|) reached, or, if larger, the momentum the
        motion's kinetic energy represents (sqrt(2 M E) and sqrt(2 J E), with M the total mass and
        J = M R², R the largest distance of a body from the centre of mass at t = 0, both recorded
        by `simulate` in stats). The second scale keeps the figure meaningful when the momentum
        itself is zero, as in a robot starting at rest."""
        dp = np.linalg.norm(self.momentum[:, :3] - self.momentum[0, :3], axis=1).max()
        dl = np.linalg.norm(self.momentum[:, 3:] - self.momentum[0, 3:], axis=1).max()
        e = np.abs(self.kinetic_energy).max()
        mass, radius = self.stats.get("total_mass", 0.0), self.stats.get("radius", 0.0)
        sp = max(np.linalg.norm(self.momentum[:, :3], axis=1).max(), np.sqrt(2 * mass * e), 1e-300)
        sl = max(np.linalg.norm(self.momentum[:, 3:], axis=1).max(), np.sqrt(2 * mass * radius**2 * e), 1e-300)
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
        momentum.<px…Lz>, kinetic_energy, work; the model name and run statistics in the metadata."""
        import pyarrow as pa
        import pyarrow.parquet as pq

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
        meta = {"freefloat": json.dumps({"model": self.model_name, "stats": self.stats})}
        table = pa.table(cols).replace_schema_metadata(meta)
        pq.write_table(table, str(path))

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
    environment: _core.Environment | None = None,
) -> Trajectory:
    """Simulate the model from (q0, v0) for t_final seconds.

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
    environment: a `freefloat.Environment` (orbit with gravity gradient, J2, a constant disturbance); its forces
      reach every body as external wrenches, and the returned trajectory's `orbit` holds the inertial state of
      the simulation frame's origin. None (the default): no external forces at all."""
    if not isinstance(model, Model):
        raise TypeError(f"expected a freefloat.Model, got {type(model).__name__}")
    if isinstance(prescribed, str):
        prescribed = [prescribed]
    bar = None
    if progress is True:
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
            environment,
        )
        if bar is not None:  # a finished run fills its bar (however fast it was: tqdm redraws at most every 0.1 s)
            bar.update(bar.total - bar.n)
            bar.refresh()
    finally:
        if bar is not None:
            bar.close()
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
    )
    return Trajectory(
        **out, model_name=model.name, q_labels=model.q_labels(), v_labels=model.v_labels(), stats=stats, orbit=orbit
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
    from .algorithms import base_twist_for_momentum

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
    from .algorithms import center_of_mass, forward_kinematics, quat_to_matrix

    fk = forward_kinematics(model, q)
    P = model.parameters()
    massive = P[:, 0] > 0
    coms = fk[massive, :3] + np.einsum("bij,bj->bi", quat_to_matrix(fk[massive, 3:7]), P[massive, 1:4] / P[massive, :1])
    return float(np.linalg.norm(coms - center_of_mass(model, q), axis=1).max())
