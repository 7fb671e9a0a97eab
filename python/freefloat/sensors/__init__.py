"""Sensor models and `measure`: a simulated run turned into the telemetry a spacecraft sends down.

Each sensor (rate gyro, star tracker, joint encoders, wheel/joint tachometers, base velocity and position, a
force/torque sensor at a joint) samples the run at its own rate, optionally late by a latency, and adds its
errors. The error models and the resampling are the engine's (`freefloat._core.measure`); this module holds the
typed configuration, the presets, and the assembly of the sensors' streams into a `Telemetry` that every
identification method reads (docs/sensors.md).

    from freefloat import sensors
    meas = sensors.measure(model, trajectory, [sensors.Gyro(rate=100, noise_density=1e-4), sensors.Tachometer()],
                           seed=1)
    meas.telemetry        # a Telemetry (t, q, v, momentum, rate_noise) for identify_minimal
    meas.streams["gyro"]  # the gyro's own samples
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .. import _core
from .._core import InputError
from ..constants import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN

__all__ = [
    "Gyro",
    "StarTracker",
    "Encoder",
    "Tachometer",
    "BaseVelocity",
    "BasePosition",
    "ForceTorque",
    "SensorSet",
    "Stream",
    "Measurement",
    "PRESETS",
    "naveen",
    "load",
    "measure",
    "smooth_rates",
]


@dataclass
class _Sensor:
    #: sample rate [Hz]; None: every sample of the run
    rate: float | None = None
    #: delay between the instant measured and its time stamp [s]
    latency: float = 0.0
    #: unique name (default: the type)
    name: str | None = None

    TYPE = ""

    def to_dict(self) -> dict:
        d = {"type": self.TYPE}
        d.update({k: v for k, v in asdict(self).items() if v is not None})
        return d


@dataclass
class Gyro(_Sensor):
    """Three-axis rate gyro on the base (IEEE Std 952-1997 terms): angle random walk `noise_density` N
    [rad/s/√Hz], constant `bias` [rad/s] (one number or three), `bias_instability` B [rad/s] as a Gauss-Markov
    bias of `bias_correlation_time` [s], `rate_random_walk` K [rad/s/√s]."""

    noise_density: float | None = None
    #: the white noise as a per-sample standard deviation [rad/s] instead of a density (exclusive with it)
    noise_per_sample: float | None = None
    bias: float | list | None = None
    bias_instability: float = 0.0
    bias_correlation_time: float | None = None
    rate_random_walk: float = 0.0
    TYPE = "gyro"


@dataclass
class StarTracker(_Sensor):
    """Base attitude with a small random rotation of standard deviation `sigma` [rad] about the base x, y, z
    axes (one number or three)."""

    sigma: float | list = 0.0
    TYPE = "star_tracker"


@dataclass
class Encoder(_Sensor):
    """Joint angles rounded to `counts_per_rev` (or a `resolution` [rad or m]), with white `noise` before
    quantisation. `joints`: names (None: every revolute/prismatic joint)."""

    joints: list | None = None
    counts_per_rev: float | None = None
    resolution: float | None = None
    noise: float = 0.0
    TYPE = "encoder"


@dataclass
class Tachometer(_Sensor):
    """Joint (wheel) rates with white `noise` [rad/s per sample], constant `bias`, quantised to `resolution`
    [rad/s] (0: none). `joints`: names (None: every revolute/prismatic joint)."""

    joints: list | None = None
    resolution: float = 0.0
    noise: float = 0.0
    bias: float = 0.0
    TYPE = "tachometer"


@dataclass
class BaseVelocity(_Sensor):
    """Base linear velocity (base frame) with white `noise` [m/s per sample] and `bias` [m/s]."""

    noise: float | list = 0.0
    bias: float | list | None = None
    TYPE = "base_velocity"


@dataclass
class BasePosition(_Sensor):
    """Base position (inertial frame) with white `noise` [m per sample] and `bias` [m]."""

    noise: float | list = 0.0
    bias: float | list | None = None
    TYPE = "base_position"


@dataclass
class ForceTorque(_Sensor):
    """Six-axis force/torque sensor measuring the wrench `joint` transmits to its child body (child frame),
    with white `force_noise` [N], `torque_noise` [N·m] and biases."""

    joint: str = ""
    force_noise: float = 0.0
    torque_noise: float = 0.0
    force_bias: float | list | None = None
    torque_bias: float | list | None = None
    TYPE = "force_torque"


_TYPES = {c.TYPE: c for c in (Gyro, StarTracker, Encoder, Tachometer, BaseVelocity, BasePosition, ForceTorque)}

#: how the telemetry's configuration columns are made: "integrate" (Naveen, Shah, Misra, Appendix C: poses
#: rebuilt by integrating the measured rates from the true initial configuration) or "measured" (from a
#: star tracker, encoders and a base position sensor)
POSES = ("integrate", "measured")


@dataclass
class SensorSet:
    """A list of sensors and how their streams become one telemetry table: `poses` (see POSES) and
    `telemetry_rate` [Hz] (None: the rate of the fastest sensor feeding q or v; slower sensors are held, as a
    flight computer's telemetry frame holds the latest sample)."""

    sensors: list = field(default_factory=list)
    poses: str = "integrate"
    telemetry_rate: float | None = None

    def __post_init__(self):
        if self.poses not in POSES:
            raise InputError(f"telemetry.poses: expected one of {', '.join(POSES)}, got {self.poses!r}")
        if self.telemetry_rate is not None and not (float(self.telemetry_rate) > 0):
            raise InputError(f"telemetry.rate: must be a positive number of Hz, got {self.telemetry_rate!r}")

    def to_dicts(self) -> list:
        return [s.to_dict() if isinstance(s, _Sensor) else dict(s) for s in self.sensors]

    def to_json(self) -> str:
        return json.dumps(self.to_dicts())

    def names(self) -> list:
        """Check the set with the engine (keys, signs, types) and return the sensors' names."""
        return list(_core.check_sensors(self.to_json()))

    def to_dict(self) -> dict:
        d = {"sensors": self.to_dicts(), "telemetry": {"poses": self.poses}}
        if self.telemetry_rate is not None:
            d["telemetry"]["rate"] = float(self.telemetry_rate)
        return d


def naveen(
    sigma_lin: float = SIGMA_LIN, sigma_ang: float = SIGMA_ANG, sigma_joint: float = SIGMA_JOINT, rate=None
) -> SensorSet:
    """The measurement model of Naveen, Shah, Misra (Sec. VI.C, Appendix C) as a sensor set: white Gaussian
    noise of per-sample standard deviation sigma_lin [m/s] on the base linear velocity, sigma_ang [rad/s] on the
    base angular velocity (a gyro with angle random walk N = sigma_ang·√P, P the sample period) and sigma_joint on
    every joint rate (tachometers), all sampled at `rate` (None: every sample of the run, as `add_noise` does),
    poses rebuilt by integrating the noisy rates. Same statistical model as `io.telemetry.add_noise` (a different
    random generator, so not the same draws; tests/test_sensors.py checks the equivalence)."""
    gyro = Gyro(rate=rate, noise_per_sample=float(sigma_ang))
    return SensorSet(
        [
            BaseVelocity(rate=rate, noise=float(sigma_lin)),
            gyro,
            Tachometer(rate=rate, noise=float(sigma_joint)),
        ],
        poses="integrate",
    )


#: built-in sensor sets by name (`--preset` on the command line)
PRESETS = {"naveen": naveen}


def load(spec) -> SensorSet:
    """A SensorSet from a SensorSet, a list of sensors (objects or dicts), a dict with `sensors:` and optionally
    `telemetry: {rate, poses}`, a preset name, or a YAML/JSON file holding one of those."""
    if isinstance(spec, SensorSet):
        return spec
    if isinstance(spec, str) and spec in PRESETS:
        return PRESETS[spec]()
    if isinstance(spec, (str, Path)):
        p = Path(spec)
        if not p.exists():
            raise FileNotFoundError(f"sensors file not found: {p} (or a preset: {', '.join(PRESETS)})")
        import yaml

        try:
            spec = yaml.safe_load(p.read_text())
        except yaml.YAMLError as e:
            raise InputError(f"{p}: not YAML ({e})") from None
    if isinstance(spec, list):
        return SensorSet(list(spec))
    if isinstance(spec, dict):
        unknown = set(spec) - {"sensors", "telemetry", "preset"}
        if unknown:
            raise InputError(
                f"sensors file: unknown top-level key(s) {sorted(unknown)} (known: sensors, telemetry, preset)"
            )
        tel = spec.get("telemetry") or {}
        if not isinstance(tel, dict) or set(tel) - {"rate", "poses"}:
            raise InputError(f"telemetry: expected a mapping with keys rate, poses; got {tel!r}")
        if "preset" in spec:
            name = spec["preset"]
            if name not in PRESETS:
                raise InputError(f"preset: unknown preset {name!r} (known: {', '.join(PRESETS)})")
            base = PRESETS[name]()
            sensors = base.sensors + list(spec.get("sensors") or [])
            poses = tel.get("poses", base.poses)
        else:
            if "sensors" not in spec:
                raise InputError("sensors file: missing the `sensors:` list (or `preset:`)")
            sensors, poses = list(spec["sensors"] or []), tel.get("poses", "integrate")
        return SensorSet(sensors, poses=poses, telemetry_rate=tel.get("rate"))
    raise InputError(f"argument `sensors`: expected a SensorSet, a list, a dict, a preset name or a file, got {spec!r}")


@dataclass
class Stream:
    """One sensor's samples: time stamps t (N,), values (N, len(columns)) under telemetry column names."""

    sensor: str
    columns: list
    t: np.ndarray
    values: np.ndarray
    white_sigma: np.ndarray
    period: float

    def to_csv(self, path) -> None:
        header = f"# sensor: {self.sensor}\n" + ",".join(["t"] + list(self.columns))
        np.savetxt(
            str(path), np.column_stack([self.t, self.values]), delimiter=",", fmt="%.17g", header=header, comments=""
        )


@dataclass
class Measurement:
    """The result of `measure`: every sensor's stream, and their assembly into one Telemetry."""

    streams: dict
    #: the assembled Telemetry, or None when the sensors do not measure every velocity (see why_no_telemetry)
    telemetry: object
    sensors: SensorSet
    seed: int
    why_no_telemetry: str = ""

    def require_telemetry(self):
        """The Telemetry, or an InputError saying which columns no sensor measures."""
        if self.telemetry is None:
            raise InputError(self.why_no_telemetry)
        return self.telemetry

    def summary(self) -> dict:
        return {
            "seed": int(self.seed),
            "sensors": self.sensors.to_dict(),
            "streams": {
                n: {"samples": len(s.t), "period_s": s.period, "columns": list(s.columns)}
                for n, s in self.streams.items()
            },
            "telemetry": None
            if self.telemetry is None
            else {
                "samples": len(self.telemetry.t),
                "t_start": float(self.telemetry.t[0]),
                "t_end": float(self.telemetry.t[-1]),
                "rate_noise": self.telemetry.rate_noise,
            },
            **({"why_no_telemetry": self.why_no_telemetry} if self.telemetry is None else {}),
        }

    def write(self, out) -> list:
        """Write DIR/telemetry.csv (what `freefloat identify minimal` reads; when assembled), DIR/sensor_<name>.csv
        for each sensor, and DIR/results.json. Returns the paths written."""
        d = Path(out)
        d.mkdir(parents=True, exist_ok=True)
        written = []
        if self.telemetry is not None:
            written.append(d / "telemetry.csv")
            self.telemetry.to_csv(written[0])
        for n, s in self.streams.items():
            p = d / f"sensor_{n}.csv"
            s.to_csv(p)
            written.append(p)
        p = d / "results.json"
        p.write_text(json.dumps(self.summary(), indent=2))
        written.append(p)
        return written


def _run_arrays(model, run):
    """(t, q, v, ddq or None, momentum or None, model name) from a Trajectory, a Telemetry or a dict."""
    get = (lambda k: run.get(k)) if isinstance(run, dict) else (lambda k: getattr(run, k, None))
    t, q, v = get("t"), get("q"), get("v")
    if t is None or q is None or v is None:
        raise InputError(
            f"argument `run`: expected a Trajectory, Telemetry or dict with t, q, v; got {type(run).__name__}"
        )
    ddq = get("ddq")
    if ddq is not None and np.asarray(ddq).size == 0:
        ddq = None
    return np.asarray(t, float), np.asarray(q, float), np.asarray(v, float), ddq, get("momentum")


def measure(model, run, sensors, seed: int = 0) -> Measurement:
    """Sample `run` (a Trajectory, a Telemetry, or a dict of t, q, v[, ddq, momentum]) of `model` with `sensors`
    (see `load`) from the random streams of `seed`, and assemble the telemetry.

    Resampling (engine rule): the run must be evenly sampled; each sensor's period must be a whole number of the
    run's sample spacing and its latency a whole number of spacings; otherwise an InputError names the sensor's
    key (no interpolation). Assembly: the telemetry's time grid is the time stamps of the fastest sensor that
    feeds q or v (or `telemetry_rate`), from the first instant at which every such sensor has reported; each
    column holds its sensor's latest sample (zero-order hold). Every v column must come from a sensor; q columns
    too with poses="measured", else they are rebuilt by integrating the measured v (poses="integrate"). The
    momentum column, if the run has one, is the true momentum at the grid times (a known quantity, as in
    Naveen, Shah, Misra). When the sensors do not measure every velocity, `telemetry` is None (the streams are
    still there; `Measurement.require_telemetry()` raises the reason). `rate_noise` of the telemetry is the
    per-component white-noise standard deviation the rate sensors declare (for identification's
    errors-in-variables bias removal), None if all are zero."""
    from ..io.telemetry import Telemetry, integrate_poses

    sset = load(sensors)
    t, q, v, ddq, momentum = _run_arrays(model, run)
    if len(t) < 2:
        raise InputError(f"argument `run`: needs at least 2 samples, got {len(t)}")
    dt = (t[-1] - t[0]) / (len(t) - 1)
    raw = _core.measure(model._core, sset.to_json(), t, q, v, ddq, int(seed))
    streams = {
        r["sensor"]: Stream(r["sensor"], list(r["columns"]), r["t"], r["values"], r["white_sigma"], r["period"])
        for r in raw
    }
    qlab, vlab = model.q_labels(), model.v_labels()
    owner = {}
    for s in streams.values():
        for j, c in enumerate(s.columns):
            if c.startswith(("q.", "v.")):
                if c in owner:
                    raise InputError(f"sensors.{s.sensor}: column {c} is already measured by sensor '{owner[c][0]}'")
                owner[c] = (s.sensor, j)
    need_v = [f"v.{n}" for n in vlab]
    missing = [c for c in need_v if c not in owner]
    need_q = [f"q.{n}" for n in qlab] if sset.poses == "measured" else []
    missing += [c for c in need_q if c not in owner]
    if missing:
        why = (
            f"sensors: no sensor measures {', '.join(missing)} (velocities need a base_velocity, a gyro and "
            "tachometers on the joints; with poses: measured the configuration needs base_position, star_tracker "
            "and encoders)"
        )
        return Measurement(streams=streams, telemetry=None, sensors=sset, seed=int(seed), why_no_telemetry=why)
    feeders = sorted({owner[c][0] for c in need_v + need_q}, key=lambda n: streams[n].period)
    if sset.telemetry_rate is None:
        grid = streams[feeders[0]].t
    else:
        grid = t[0] + np.arange(0.0, t[-1] - t[0] + 0.5 * dt, 1.0 / float(sset.telemetry_rate))
    start = max(streams[n].t[0] for n in feeders)
    eps = 1e-9 * dt
    grid = grid[grid >= start - eps]
    if len(grid) < 2:
        raise InputError("sensors: fewer than 2 telemetry samples once every sensor has reported (latency too long?)")

    def column(c):
        s = streams[owner[c][0]]
        k = np.searchsorted(s.t, grid + eps, side="right") - 1
        return s.values[k, owner[c][1]]

    vm = np.column_stack([column(c) for c in need_v])
    k_true = np.clip(np.rint((grid - t[0]) / dt).astype(int), 0, len(t) - 1)
    if sset.poses == "measured":
        qm = np.column_stack([column(c) for c in need_q])
    else:
        qm = integrate_poses(model, grid, vm, q[k_true[0]])
    sig = np.array([streams[owner[c][0]].white_sigma[owner[c][1]] for c in need_v])
    telem = Telemetry(
        t=grid.copy(),
        q=qm,
        v=vm,
        model_name=model.name,
        q_labels=qlab,
        v_labels=vlab,
        momentum=None if momentum is None else np.asarray(momentum, float)[k_true],
        rate_noise=[float(x) for x in sig] if np.any(sig > 0) else None,
    )
    return Measurement(streams=streams, telemetry=telem, sensors=sset, seed=int(seed))


def smooth_rates(y, h: float, log_ratio: float | None = None) -> dict:
    """Accelerations from noisy rates: the Rauch-Tung-Striebel smoother of the white-jerk rate model (the state is
    a rate and its derivative, the jerk white with density q, the rate measured with white noise of variance r),
    applied to each column of `y` (N, k), sampled every `h` seconds. `log_ratio` fixes log10(q h³ / r) for every
    column; None (the default) gives each column the ratio that minimises its generalised cross-validation score
    (Craven & Wahba 1979), so the bandwidth follows the noise the record shows. The prior on the first sample is
    diffuse, which makes the smoothed rate the cubic smoothing spline of the rates with penalty r/q. Returns
    {"rate": (N, k), "accel": (N, k), "log_ratio": (k,), "sigma": (k,) the estimated white rate noise per
    sample}. Computed by the engine (`sensors::smooth_rates`); docs/postcapture.md measures it against central
    differences and Savitzky-Golay."""
    return _core.smooth_rates(np.ascontiguousarray(np.asarray(y, float)), float(h), log_ratio)
