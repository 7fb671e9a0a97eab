"""Joint trajectories of Naveen, Shah, Misra (Naveen, Shah, Misra, "Momentum model-based minimal parameter
identification of a space robot"): the multi-interval cycloidal exciting trajectory (Section V.B–D,
eqs. 28–31) and the Fourier trajectory used to evaluate the estimates (Section VI.D, eqs. 40–41).

Both give joint angle, rate and acceleration as functions of time, vectorised over time, and a
`prescription(model, joint_names)` that `freefloat.simulate(..., prescribed=..., prescription=...)`
accepts. The reaction wheels of Naveen, Shah, Misra are ordinary joints of the model, so they are driven like the
arm joints: `with_wheels` appends their predetermined seeds (start 0, range 3π per interval, Sec. VI.A.2)."""

from __future__ import annotations

import numpy as np

from ._core import InputError
from .constants import WHEEL_RANGE, WHEEL_START


def direction_combinations(n: int, fixed: int = 0, fastest: str = "last") -> np.ndarray:
    """All 2**(n-1) sign patterns of n joint velocities with joint `fixed` kept at +1 (Naveen, Shah, Misra V.B:
    one joint keeps its direction, so there are 2^(n-1) combinations, 256 for 6 arm joints + 3 wheels).

    The paper fixes neither the joint nor the order. Ordering chosen here:
    row k is the binary expansion of k over the free joints in column order, most significant bit
    first, with bit 0 -> +1 and bit 1 -> -1. So row 0 is all +1 and the last free joint alternates
    fastest (lexicographic order with + before -). With fastest="first" the bit order is reversed: the
    first free joint alternates every interval, the next every second, and so on — joint j's accumulated
    travel then stays within 2^(j-1) ranges, which is what position limits need (the excitation design puts
    the arm joints first and fixes the last wheel). Returns an int array (2**(n-1), n)."""
    n = int(n)
    if n < 1:
        raise InputError(f"direction_combinations: n must be >= 1, got {n}")
    if not 0 <= fixed < n:
        raise InputError(f"direction_combinations: fixed joint index {fixed} is outside 0..{n - 1}")
    if fastest not in ("last", "first"):
        raise InputError(f"direction_combinations: fastest must be 'last' or 'first', got {fastest!r}")
    k = np.arange(2 ** (n - 1))[:, None]
    shifts = np.arange(n - 2, -1, -1)[None, :]  # MSB first over the n-1 free joints
    if fastest == "first":
        shifts = shifts[:, ::-1]
    bits = (k >> shifts) & 1
    free = 1 - 2 * bits
    return np.insert(free, fixed, 1, axis=1).astype(int)


def with_wheels(start, range_, n_wheels: int = 3):
    """Append `n_wheels` reaction wheels with the seed-001 predetermined seeds (start 0 rad, range 3π
    rad per interval, Sec. VI.A.2) to arm seeds `start`, `range_` (n,). Returns the
    (n + n_wheels,) pair to pass to `Cycloidal`, whose directions then need n + n_wheels columns
    (e.g. `direction_combinations(n + n_wheels)`)."""
    start = np.concatenate([np.atleast_1d(np.asarray(start, float)), np.full(n_wheels, WHEEL_START)])
    range_ = np.concatenate([np.atleast_1d(np.asarray(range_, float)), np.full(n_wheels, WHEEL_RANGE)])
    return start, range_


class _JointTrajectory:
    """Shared part: turn evaluate(t) into a full-length prescription for `freefloat.simulate`."""

    n: int

    def evaluate(self, t):  # pragma: no cover - abstract
        raise NotImplementedError

    def prescription(self, model, joint_names):
        """A function f(t) -> (q, v, a) of full model length (nq, nv, nv) for `simulate`: the named
        joints (one per trajectory column, 1-DoF joints) follow this trajectory; every other entry is
        the model's neutral configuration and zero rate/acceleration (simulate ignores them anyway)."""
        names = list(joint_names)
        if len(names) != self.n:
            raise InputError(f"prescription: {len(names)} joint names for a trajectory of {self.n} joints")
        iq, iv = [], []
        for name in names:
            if name not in model.joint_names:
                raise InputError(
                    f"prescription: '{name}' is not a joint of model '{model.name}' "
                    f"(joints: {', '.join(model.joint_names[1:])})"
                )
            b = model.joint_names.index(name)
            if model.nvs[b] != 1:
                raise InputError(
                    f"prescription: joint '{name}' has {model.nvs[b]} DoF; only 1-DoF joints can be prescribed here"
                )
            iq.append(model.idx_q[b])
            iv.append(model.idx_v[b])
        return _StageLookahead(self.evaluate, model.neutral(), model.nv, np.array(iq), np.array(iv))


class _StageLookahead:
    """The prescription function f(t) -> (q, v, a) that `prescription` returns.

    A fixed-step Runge-Kutta simulation asks for the prescription at every stage, and RK4's stage times lie on a
    grid of half steps (t_k + {0, 1/2, 1} h). One numpy evaluation per stage costs about 30 times more than the
    same point inside a vectorised block, and at 1 kHz it dominated whole runs. So once two requests reveal the grid
    spacing, the next `BLOCK` grid times are evaluated in one call and later requests that fall on the grid (to
    within round-off of t itself) are served from that block. A time off the grid (an adaptive step, a caller's own
    time) is evaluated on its own, so every answer is the trajectory at the requested time."""

    BLOCK = 4096

    def __init__(self, evaluate, q_rest, nv, iq, iv):
        self.evaluate, self.q_rest, self.nv, self.iq, self.iv = evaluate, q_rest, nv, iq, iv
        self.prev = None  # last requested time, to learn the grid spacing from
        self.spacing = None
        self.origin = 0.0
        self.first = 0  # grid index of the block's first row
        self.rows = None  # (q, v, a) of the block, full model length

    def _embed(self, times):
        qj, vj, aj = self.evaluate(times)
        q = np.repeat(self.q_rest[None, :], len(times), axis=0)
        v, a = np.zeros((len(times), self.nv)), np.zeros((len(times), self.nv))
        q[:, self.iq], v[:, self.iv], a[:, self.iv] = qj, vj, aj
        return q, v, a

    def __call__(self, t):
        t = float(t)
        h = self.spacing
        if h is not None:
            j = round((t - self.origin) / h)
            if abs(t - (self.origin + j * h)) <= 1e-9 * h:
                k = j - self.first
                if self.rows is None or not 0 <= k < len(self.rows[0]):
                    self.first, k = j, 0
                    self.rows = self._embed(self.origin + h * np.arange(j, j + self.BLOCK))
                return tuple(x[k].copy() for x in self.rows)
        elif self.prev is not None and t > self.prev:
            self.spacing, self.origin = t - self.prev, self.prev
        self.prev = t
        return tuple(x[0] for x in self._embed(np.array([t])))


class MultiSine(_JointTrajectory):
    """Per joint a sum of sines in the rate: qd_j(t) = Σ_k A_jk cos(w_jk t + φ_jk), so
    q_j(t) = Σ_k A_jk / w_jk sin(w_jk t + φ_jk). Smooth and persistently exciting; a quick way to excite a robot
    when no designed trajectory is at hand. `amplitude`, `frequency` (rad/s, > 0) and `phase` are (n, K)."""

    def __init__(self, amplitude, frequency, phase):
        self.amp, self.w, self.ph = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (amplitude, frequency, phase))
        if not (self.amp.shape == self.w.shape == self.ph.shape):
            raise InputError(
                f"MultiSine: amplitude, frequency and phase must share a shape, "
                f"got {self.amp.shape}, {self.w.shape}, {self.ph.shape}"
            )
        if np.any(self.w <= 0):
            raise InputError("MultiSine: frequencies must be positive")
        self.n = self.amp.shape[0]

    @classmethod
    def random(cls, n: int, rng, terms: int = 3, amplitude=(0.2, 0.6), frequency=(0.5, 3.0)) -> MultiSine:
        """Random amplitudes (rad/s), frequencies (rad/s) and phases, uniform in the given ranges."""
        rng = np.random.default_rng(rng)
        return cls(
            rng.uniform(*amplitude, (n, terms)),
            rng.uniform(*frequency, (n, terms)),
            rng.uniform(0.0, 2 * np.pi, (n, terms)),
        )

    def evaluate(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))[:, None, None]
        s = self.w * t + self.ph
        return (
            (self.amp / self.w * np.sin(s)).sum(2),
            (self.amp * np.cos(s)).sum(2),
            (-self.amp * self.w * np.sin(s)).sum(2),
        )


class Cycloidal(_JointTrajectory):
    """Multi-interval cycloidal joint trajectory of Naveen, Shah, Misra, eqs. 28–31.

    start (n,)      θ_js, angle at t = 0 (eq. 30, k = 1)
    range_ (n,)     θ_jd > 0, distance moved per interval
    directions (K, n) ±1, sign of each joint's rate in each interval (one row per interval, e.g. rows of
                    `direction_combinations`)
    interval        T_p, duration of every interval (1 s in the paper)

    Interval k (1-based) moves joint j from θ_ji^k to θ_jf^k = θ_ji^k + d_jk·θ_jd, with θ_ji^1 = θ_js and
    θ_ji^k = θ_jf^(k-1) (eqs. 30–31; the printed eq. 31 uses θ_jf^(k-1), which is the same thing for
    k > 1 and must read θ_js for k = 1). Within the interval (τ = t − (k−1)T_p):
        q  = θ_i + Δ/T_p [τ − T_p/(2π) sin(2πτ/T_p)]                          (28)
        q̇  = Δ/T_p [1 − cos(2πτ/T_p)]                                          (29)
        q̈  = Δ/T_p (2π/T_p) sin(2πτ/T_p)                                      (derivative of 29)
    Rate and acceleration vanish at both ends of every interval, so intervals join with continuous
    q, q̇ and q̈ (rest-to-rest). Before t = 0 and after `duration` the joints rest at the end angles."""

    def __init__(self, start, range_, directions, interval: float = 1.0):
        self.start = np.atleast_1d(np.asarray(start, dtype=float))
        self.range_ = np.atleast_1d(np.asarray(range_, dtype=float))
        self.directions = np.atleast_2d(np.asarray(directions, dtype=float))
        self.interval = float(interval)
        self.n = self.start.size
        self._check()
        # Angles at the interval boundaries (K+1, n): cumulative form of eqs. 30–31.
        steps = self.directions * self.range_[None, :]
        self.boundaries = self.start[None, :] + np.vstack([np.zeros(self.n), np.cumsum(steps, axis=0)])

    def _check(self):
        if self.range_.shape != (self.n,):
            raise InputError(f"Cycloidal: range_ has shape {self.range_.shape}, expected ({self.n},) like start")
        if self.directions.shape[1] != self.n:
            raise InputError(
                f"Cycloidal: directions have {self.directions.shape[1]} columns, expected {self.n} (one per joint)"
            )
        if not np.all(np.isfinite(self.start)) or not np.all(np.isfinite(self.range_)):
            raise InputError("Cycloidal: start and range_ must be finite")
        if np.any(self.range_ <= 0):
            j = int(np.argmax(self.range_ <= 0))
            raise InputError(
                f"Cycloidal: range_ must be > 0 (Naveen, Shah, Misra eq. 37); joint {j} has {self.range_[j]}"
            )
        if not np.all(np.isin(self.directions, (-1.0, 1.0))):
            raise InputError("Cycloidal: directions must be +1 or -1")
        if not (self.interval > 0 and np.isfinite(self.interval)):
            raise InputError(f"Cycloidal: interval must be a positive number, got {self.interval}")

    @property
    def n_intervals(self) -> int:
        return self.directions.shape[0]

    @property
    def duration(self) -> float:
        """Total time K·T_p."""
        return self.n_intervals * self.interval

    def peak_rate(self) -> np.ndarray:
        """max |q̇_j| = 2θ_jd/T_p."""
        return 2.0 * self.range_ / self.interval

    def peak_acceleration(self) -> np.ndarray:
        """max |q̈_j| = 2πθ_jd/T_p² (at τ = T_p/4 and 3T_p/4)."""
        return 2.0 * np.pi * self.range_ / self.interval**2

    def evaluate(self, t):
        """Angles, rates and accelerations at times t: three arrays (len(t), n)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        T = self.interval
        tc = np.clip(t, 0.0, self.duration)
        # Interval index; the last interval owns t == duration so the end angle is reached exactly.
        k = np.minimum(np.floor(tc / T).astype(int), self.n_intervals - 1)
        tau = (tc - k * T)[:, None]
        th_i = self.boundaries[k]
        delta = self.boundaries[k + 1] - th_i
        s, c = np.sin(2 * np.pi * tau / T), np.cos(2 * np.pi * tau / T)
        q = th_i + delta / T * (tau - T / (2 * np.pi) * s)
        qd = delta / T * (1 - c)
        qdd = delta / T * (2 * np.pi / T) * s
        # Outside [0, duration] the joints rest (clipping already holds the angle).
        outside = ((t < 0) | (t > self.duration))[:, None]
        return q, np.where(outside, 0.0, qd), np.where(outside, 0.0, qdd)


class Fourier(_JointTrajectory):
    """Finite Fourier joint trajectory of Naveen, Shah, Misra Sec. VI.D, eqs. 40–41:
        q_j  = q_j0 + Σ_i a_ji sin(iω_f t) + b_ji cos(iω_f t)                  (40)
        q̇_j  = Σ_i iω_f (a_ji cos(iω_f t) − b_ji sin(iω_f t))                   (41)
        q̈_j  = −Σ_i (iω_f)² (a_ji sin(iω_f t) + b_ji cos(iω_f t))              (derivative of 41)
    a = q^(s) and b = q^(c) are (n, n_h); q0 is (n,). The paper uses N_h = 2 and ω_f = π/20 (a 40-s
    period) but does not print the coefficients (they are only in its Fig. 6)."""

    def __init__(self, a, b, q0, omega_f: float = np.pi / 20, n_h: int = 2):
        self.q0 = np.atleast_1d(np.asarray(q0, dtype=float))
        self.n = self.q0.size
        self.n_h = int(n_h)
        self.a = np.asarray(a, dtype=float).reshape(self.n, -1)
        self.b = np.asarray(b, dtype=float).reshape(self.n, -1)
        self.omega_f = float(omega_f)
        if self.a.shape != (self.n, self.n_h) or self.b.shape != (self.n, self.n_h):
            raise InputError(f"Fourier: a and b must be ({self.n}, {self.n_h}); got {self.a.shape} and {self.b.shape}")

    @property
    def duration(self) -> float:
        """One period, 2π/ω_f."""
        return 2 * np.pi / self.omega_f

    def evaluate(self, t):
        """Angles, rates and accelerations at times t: three arrays (len(t), n)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        w = self.omega_f * np.arange(1, self.n_h + 1)  # iω_f
        s, c = np.sin(t[:, None] * w), np.cos(t[:, None] * w)  # (T, n_h)
        q = self.q0 + s @ self.a.T + c @ self.b.T
        qd = (c * w) @ self.a.T - (s * w) @ self.b.T
        qdd = -(s * w**2) @ self.a.T - (c * w**2) @ self.b.T
        return q, qd, qdd


class Stacked(_JointTrajectory):
    """Several joint trajectories side by side (columns concatenated), e.g. Fourier arm joints with cycloidal
    wheels. Duration: the longest part's."""

    def __init__(self, *parts):
        if not parts:
            raise InputError("Stacked: needs at least one trajectory")
        self.parts = parts
        self.n = sum(p.n for p in parts)

    @property
    def duration(self) -> float:
        return max(p.duration for p in self.parts)

    def evaluate(self, t):
        out = [p.evaluate(t) for p in self.parts]
        return tuple(np.hstack([o[k] for o in out]) for k in range(3))
