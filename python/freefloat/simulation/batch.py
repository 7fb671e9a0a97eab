"""Many simulations of one robot in one call, spread over the cores (`simulate_many`).

    import freefloat as ff
    m = ff.models.load("naveen_dual_arm_consistent")
    Q0 = np.tile(m.neutral(), (8, 1)); V0 = 0.01 * rng.normal(size=(8, m.nv))
    runs = ff.simulate_many(m, Q0, V0, t_final=10.0, dt=1e-3, torques=table)   # 8 trajectories
    runs.failures                                                              # {} or {index: exception}

Every argument that varies is stacked on a leading batch axis of B members (q0 (B, nq), v0 (B, nv), params
(B, nbodies, 10), torques (B, T, nv)); one that does not is given once and shared. Each member is exactly the
`simulate` run of its own arguments (same engine code, own work buffers), whatever the number of threads."""

from __future__ import annotations

from .. import _core
from .._arrays import as_f64
from .._core import InputError
from ..model import Model
from .run import Trajectory


class Trajectories(list):
    """The B trajectories of `simulate_many`, in member order. A member that failed is `None` here and its
    exception is in `failures[index]`; the others are kept."""

    failures: dict

    def __init__(self, items, failures):
        super().__init__(items)
        self.failures = dict(failures)

    def __repr__(self) -> str:
        ok = len(self) - len(self.failures)
        bad = f", failed: {sorted(self.failures)}" if self.failures else ""
        return f"Trajectories({len(self)} members, {ok} ran{bad})"


def simulate_many(
    model: Model,
    q0,
    v0,
    t_final: float,
    dt: float,
    *,
    torques=None,
    torque_times=None,
    hold: str = "zoh",
    params=None,
    method: str = "rk4",
    rtol: float = 1e-9,
    atol: float = 1e-12,
    max_step: float | None = None,
    record_every: int = 1,
    threads: int = 0,
    max_steps: int = 50_000_000,
) -> Trajectories:
    """Simulate B members of a batch in one call on `threads` threads (0: one per core), the GIL released.

    q0 (nq,) or (B, nq); v0 (nv,) or (B, nv); params: None (the model's own), (nbodies, 10) or (B, nbodies, 10)
    standard inertial parameters (as `Model.parameters()`); torques: None, a table (T, nv) for all members or
    (B, T, nv), read at torque_times (default k·dt) with hold "zoh" or "linear". Arguments stacked on a batch
    axis must agree on B; an empty batch (B = 0) or mismatched sizes raise InputError naming the argument. A
    member that fails (e.g. non-physical parameters, a singular state) does not stop the others: see
    `Trajectories.failures`. Torque functions of the state are not batched; use `simulate` for those.

    Ctrl-C stops every member within ~20 ms and raises `freefloat.Interrupted` whose `partial` is the
    Trajectories so far: finished members whole, running ones up to the stop (`stats["interrupted"]`), members
    not started in `failures`."""
    if not isinstance(model, Model):
        raise TypeError(f"expected a freefloat.Model, got {type(model).__name__}")
    q0, v0 = as_f64(q0, "q0"), as_f64(v0, "v0")
    P = None if params is None else as_f64(params, "params")
    tq = None if torques is None else as_f64(torques, "torques")
    tt = None if torque_times is None else as_f64(torque_times, "torque_times")
    try:
        dicts, failures = _simulate_many(
            model, q0, v0, t_final, dt, method, rtol, atol, max_step, record_every, tq, tt, hold, P, threads, max_steps
        )
    except _core.Interrupted as e:
        # Ctrl-C: `partial` becomes the Trajectories so far (finished members whole, running ones cut short with
        # stats["interrupted"], members not started in `failures`)
        if isinstance(getattr(e, "partial", None), tuple):
            e.partial = _trajectories(model, *e.partial, method, dt, t_final)
        raise
    return _trajectories(model, dicts, failures, method, dt, t_final)


def _simulate_many(
    model, q0, v0, t_final, dt, method, rtol, atol, max_step, record_every, tq, tt, hold, P, threads, max_steps
):
    return _core.simulate_many(
        model._core,
        q0,
        v0,
        float(t_final),
        float(dt),
        method,
        rtol,
        atol,
        max_step,
        int(record_every),
        tq,
        tt,
        hold,
        P,
        int(threads),
        int(max_steps),
    )


def _trajectories(model, dicts, failures, method, dt, t_final) -> Trajectories:
    out = []
    for d in dicts:
        if d is None:
            out.append(None)
            continue
        stats = {k: d.pop(k) for k in ("steps", "rejected", "evaluations")}
        if "interrupted" in d:
            stats["interrupted"] = d.pop("interrupted")
        stats.update(method=method, formulation="aba", dt=dt, t_final=t_final, total_mass=model.total_mass)
        out.append(
            Trajectory(**d, model_name=model.name, q_labels=model.q_labels(), v_labels=model.v_labels(), stats=stats)
        )
    return Trajectories(out, {int(k): e for k, e in failures})


def torque_table(torques_of_t, t_final: float, dt: float):
    """The vectorised alternative to a Python torque function of time: `torques_of_t(t)` is called ONCE with every
    RK4 stage time (the grid k·dt/2, shape (T,)) and returns (T, nv); the result goes to `simulate` or
    `simulate_many` as `torques=values, torque_times=times, hold="linear"`, which reads it exactly at the stage
    times. A per-step Python callback costs about a microsecond of crossing per call (4 per step); this costs one
    call. Torques that depend on the state need `simulate(torques=f)` or a sampled `controller`.

        times, values = ff.torque_table(lambda t: np.outer(np.sin(t), gains), 10.0, 1e-3)
        traj = ff.simulate(m, q0, v0, 10.0, 1e-3, torques=values, torque_times=times, hold="linear")
    """
    import numpy as np

    times = np.arange(round(2 * float(t_final) / float(dt)) + 1) * (float(dt) / 2)
    values = np.asarray(torques_of_t(times), dtype=float)
    if values.ndim != 2 or values.shape[0] != len(times):
        raise InputError(
            f"torques_of_t(t) must return an array of shape ({len(times)}, nv) for the {len(times)} times, "
            f"got {values.shape}"
        )
    return times, values


__all__ = ["Trajectories", "simulate_many", "torque_table"]
