"""The adaptive berth: MPC that re-plans on the online estimate. The detumble's recursive least squares goes on
during the berth with the berth's own telemetry (the mission's sensors on the true plant), and whenever the
estimate has moved, the controller's model takes it (`DdpMpc.set_parameters`) from its next re-plan on.

Rows. The berth's base wrench is the controller's own command u[0:6] ([f; τ] in the base frame about its origin,
held over each control step), so the momentum form needs no accelerations: over a segment of the berth,
p(t) − p(t₀) = ∫ F dt and, about the moving base point as in the detumble (`postcapture::momentum_point`),
L_B(t) − L_B(t₀) + ∫ v_B × P dt = ∫ M_B dt (Zhang 2020, eqs. (9)-(10) moved to the base point; the rows
`standard_momentum_rows` forms, the transport term on the segment's telemetry frames), the
impulses integrated from the held command with the plant's attitude at every RK4 step (trapezoid; the attitude
between telemetry frames is the flight computer's business, as in the detumble's `measure`). Each segment of
`update_every_s` is measured on its own (its own sensor noise stream; a gyro-integrated attitude restarts from
the segment's first frame, as after a star-tracker fix), and its rows are differences from its first sample.
The berth uses the momentum form whatever the detumble used (the command is known exactly; the force form
would difference noisy rates).

Update rule: the controller takes the estimate when any physical parameter of base or target moved by more
than `update_tolerance` relative (see `phases.relative_scale`) since the one it plans on."""

from __future__ import annotations

import numpy as np

from .. import algorithms as alg
from .. import sensors as sn
from ..algorithms import quat_to_matrix
from ..postcapture import equations as eq
from ..postcapture.estimators import target_index
from . import phases

DEFAULTS = {"update_every_s": 1.0, "update_tolerance": 1e-3}


def physical(x_std: np.ndarray, std_cols) -> np.ndarray:
    """Physical parameters [m, c (3), I# (6)] of base and target (the order of `identify_online`'s estimates)
    from a standard-parameter estimate (base block, then target block)."""
    k = len(std_cols)
    out = []
    for sl in (slice(0, k), slice(k, 2 * k)):
        full = np.zeros((1, 10))
        full[0, std_cols] = np.asarray(x_std, float)[sl]
        m, b, I = eq.from_standard(full)
        out.append(np.r_[m[0], b[0], eq.inertia_sharp(I[0])])
    return np.concatenate(out)


def segment_impulses(truth, t, q, u) -> tuple[np.ndarray, np.ndarray]:
    """∫F dt and ∫M_B dt (inertial; the moment about the moving base origin B) from t[0] to each t[i] of the base
    wrench u[i, :6] held over [t[i], t[i+1]] (base frame, about the base origin), the attitude at the steps' ends:
    trapezoid on each step with its own held value at both ends (no jump is smeared across a step)."""
    fk = np.asarray(alg.forward_kinematics(truth, np.asarray(q, float)))[:, 0]
    A = quat_to_matrix(fk[:, 3:])
    f, tau = np.asarray(u, float)[:, :3], np.asarray(u, float)[:, 3:6]
    dt = np.diff(t)

    def world(i0):  # the held wrench of each step, at the step's start (i0 = 0) or end (i0 = 1)
        Ai = A[i0 : len(A) - 1 + i0]
        return eq.mv(Ai, f), eq.mv(Ai, tau)

    (F0, M0), (F1, M1) = world(0), world(1)
    z = np.zeros((1, 3))
    IF = np.concatenate([z, np.cumsum(0.5 * (F0 + F1) * dt[:, None], 0)])
    IM = np.concatenate([z, np.cumsum(0.5 * (M0 + M1) * dt[:, None], 0)])
    return IF, IM


class BerthEstimator:
    """The `observer` of `ddp_closed_loop.run` for the adaptive berth: measures each segment, folds its rows into
    the estimator of the handover, and returns the merged model's parameters when the estimate moved (else
    None). `history` holds (berth time, physical estimate) after each segment; `updates` the times it sent."""

    def __init__(self, truth, ident: dict, berth: dict, seed: int = 0):
        self.truth, self.target = truth, target_index(truth)
        self.sc = ident["scenario"]
        self.rls = ident["rls"]
        self.std_cols = ident["std_cols"]
        self.tol = float(berth.get("update_tolerance", DEFAULTS["update_tolerance"]))
        self.every_s = float(berth.get("update_every_s", DEFAULTS["update_every_s"]))
        self.seed = int(seed)
        self.t0 = float(ident["handover_time"])
        est = physical(self.rls.estimate, self.std_cols)
        self.scale = phases.relative_scale(est)  # sizes from the estimate (the controller does not know the truth)
        self.sent = est
        self.history = [(0.0, est)]
        self.updates: list[float] = []
        self.rows = 0
        self.segments = 0

    def check_sensors(self, step: float) -> None:
        """Refuse, before the berth, sensors that cannot sample the berth's record (one every RK4 step `step`):
        the error names the sensor's key."""
        if self.sc.sensors is None:
            return
        n = 20
        q = np.tile(np.asarray(self.truth.neutral(), float), (n, 1))
        run = {"t": np.arange(n) * step, "q": q, "v": np.zeros((n, self.truth.nv))}
        sn.measure(self.truth, run, self.sc.sensors, seed=0).require_telemetry()

    def _samples(self, seg: dict):
        """The segment's record (t, q, v) -- the telemetry frames measured by the sensors, or the true states
        without them -- and the indices of its sample instants (one every `sample_period` on its grid)."""
        t, q, v = seg["t"], seg["q"], seg["v"]
        period = float(self.sc.sample_period)
        if self.sc.sensors is not None:
            tel = sn.measure(
                self.truth, {"t": t, "q": q, "v": v}, self.sc.sensors, seed=self.seed * 100_003 + self.segments
            ).require_telemetry()
            tt, tq, tv = np.asarray(tel.t, float), np.asarray(tel.q, float), np.asarray(tel.v, float)
        else:
            tt, tq, tv = t, q, v
        want = np.arange(tt[0], t[-1] + 1e-9, period)
        j = np.searchsorted(tt, want - 1e-9)
        ok = j < len(tt)
        j = j[ok]
        j = j[np.abs(tt[j] - want[ok]) <= 1e-6]
        return (tt, tq, tv), j

    def segment_rows(self, seg: dict):
        """The momentum rows of one segment (differences from its first sample), None if it holds fewer than two
        samples."""
        (tt, tq, tv), j = self._samples(seg)
        ts, qs, vs = tt[j], tq[j], tv[j]
        self.segments += 1
        t_seg = seg["t"]
        if len(ts) < 2:
            return None
        IF, IM = segment_impulses(self.truth, t_seg, seg["q"], seg["u"])
        i = np.clip(np.searchsorted(t_seg, ts - 1e-9), 0, len(t_seg) - 1)
        held = np.vstack([seg["u"], seg["u"][-1:]])[i, :6]
        transport = eq.momentum_transport(self.truth, tt, tq, tv, j)
        meas = eq.Measurements(ts, qs, vs, np.zeros_like(vs), held, IF[i], IM[i], transport)
        return eq.standard_momentum_rows(self.truth, meas, 0, self.target)

    def __call__(self, k: int, seg: dict):
        rows = self.segment_rows(seg)
        if rows is not None:
            for tj, phi, y in zip(rows.t, rows.Phi, rows.y):
                self.rls.update(self.t0 + float(tj), phi, y)  # mission time: the estimator's clock goes on
            self.rows += len(rows.t)
        t_seg = seg["t"]
        est = physical(self.rls.estimate, self.std_cols)
        self.history.append((float(t_seg[-1]), est))
        if np.max(np.abs(est - self.sent) / self.scale) <= self.tol:
            return None
        model = phases.model_from_estimate(self.truth, self.rls.estimate, self.std_cols)
        self.sent = est
        self.updates.append(float(t_seg[-1]))
        return np.asarray(model.with_fixed_leaves_merged().parameters(), float)


def target_errors(est: np.ndarray, tru: np.ndarray) -> dict:
    """The target's errors of an estimate (physical, base then target): mass and largest principal-moment error
    relative, CoM in metres."""
    h = len(tru) // 2
    e, t = est[h:], tru[h:]
    return {
        "mass_relative": float(abs(e[0] - t[0]) / abs(t[0])),
        "com_m": float(np.linalg.norm(e[1:4] - t[1:4])),
        "inertia_relative": float((np.abs(e[[4, 7, 9]] - t[[4, 7, 9]]) / np.abs(t[[4, 7, 9]])).max()),
    }


def summary(obs: BerthEstimator, ident: dict) -> dict:
    """results.json numbers of the adaptive berth's estimator: what it measured, how often the controller took a
    new estimate, and the target's errors at the handover and at the berth's end (against the truth, which the
    controller never saw)."""
    tru = ident["truth_physical"]
    return {
        "form": "momentum",
        "update_every_s": float(obs.every_s),
        "update_tolerance": obs.tol,
        "segments": obs.segments,
        "rows": obs.rows,
        "model_updates": len(obs.updates),
        "update_times_s": obs.updates,
        "target_error_at_handover": target_errors(obs.history[0][1], tru),
        "target_error_at_end": target_errors(obs.history[-1][1], tru),
    }
