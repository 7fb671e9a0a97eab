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

import inspect
import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .. import _core
from .._core import InputError
from ..constants import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN
from ..io.schema import NonNegative, Number, Positive, Text, key, numbers

# The keys of each sensor, their schema types, ranges and defaults: declared once, here, by the classes that run
# them; the scenario files' `sensors:` block (`io/scenario_schemas.py`) is made from these classes (`schema.block_of`).
_VEC3_OR_ONE = numbers(3, scalar_ok=True)
_NONNEG_OR_NONNEGS = numbers(scalar_ok=True, lo=0.0)

__all__ = [
    "Gyro",
    "StarTracker",
    "Encoder",
    "Tachometer",
    "BaseVelocity",
    "BasePosition",
    "ForceTorque",
    "SensorSet",
    "TYPES",
    "Stream",
    "Measurement",
    "PRESETS",
    "naveen",
    "mems",
    "tactical",
    "navigation",
    "GyroSheet",
    "EncoderSheet",
    "ForceTorqueSheet",
    "HARDWARE",
    "FORCE_TORQUE",
    "load",
    "measure",
    "smooth_rates",
]


@dataclass
class _Sensor:
    #: sample rate [Hz]; None: every sample of the run
    rate: float | None = key(Positive | None, None)
    #: delay between the instant measured and its time stamp [s]
    latency: float = key(NonNegative, 0.0)
    #: unique name (default: the type)
    name: str | None = key(Text | None, None)

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

    noise_density: float | None = key(NonNegative | None, None)
    #: the white noise as a per-sample standard deviation [rad/s] instead of a density (exclusive with it)
    noise_per_sample: float | None = key(NonNegative | None, None)
    bias: float | list | None = key(_VEC3_OR_ONE, None)
    bias_instability: float = key(NonNegative, 0.0)
    bias_correlation_time: float | None = key(Positive | None, None)
    rate_random_walk: float = key(NonNegative, 0.0)
    TYPE = "gyro"


@dataclass
class StarTracker(_Sensor):
    """Base attitude with a small random rotation of standard deviation `sigma` [rad] about the base x, y, z
    axes (one number or three)."""

    sigma: float | list = key(numbers(3, scalar_ok=True, lo=0.0), 0.0)
    TYPE = "star_tracker"


@dataclass
class Encoder(_Sensor):
    """Joint angles rounded to `counts_per_rev` (or a `resolution` [rad or m]), with white `noise` before
    quantisation. `joints`: names (None: every revolute/prismatic joint)."""

    joints: list | None = key(list[Text] | None, None)
    counts_per_rev: float | None = key(Positive | None, None)
    resolution: float | None = key(Positive | None, None)
    noise: float = key(NonNegative, 0.0)
    TYPE = "encoder"


@dataclass
class Tachometer(_Sensor):
    """Joint (wheel) rates with white `noise` [rad/s per sample], constant `bias`, quantised to `resolution`
    [rad/s] (0: none). `joints`: names (None: every revolute/prismatic joint)."""

    joints: list | None = key(list[Text] | None, None)
    resolution: float = key(NonNegative, 0.0)
    noise: float = key(NonNegative, 0.0)
    bias: float = key(Number, 0.0)
    TYPE = "tachometer"


@dataclass
class BaseVelocity(_Sensor):
    """Base linear velocity (base frame) with white `noise` [m/s per sample] and `bias` [m/s]."""

    noise: float | list = key(_NONNEG_OR_NONNEGS, 0.0)
    bias: float | list | None = key(_VEC3_OR_ONE, None)
    TYPE = "base_velocity"


@dataclass
class BasePosition(_Sensor):
    """Base position (inertial frame) with white `noise` [m per sample] and `bias` [m]."""

    noise: float | list = key(_NONNEG_OR_NONNEGS, 0.0)
    bias: float | list | None = key(_VEC3_OR_ONE, None)
    TYPE = "base_position"


@dataclass(kw_only=True)
class ForceTorque(_Sensor):
    """Six-axis force/torque sensor measuring the wrench `joint` transmits to its child body (child frame),
    with white `force_noise` [N], `torque_noise` [N·m] and biases. `joint` is required (keyword-only: the
    sensor has no sensible default joint)."""

    joint: str = key(Text)
    force_noise: float = key(NonNegative, 0.0)
    torque_noise: float = key(NonNegative, 0.0)
    force_bias: float | list | None = key(_VEC3_OR_ONE, None)
    torque_bias: float | list | None = key(_VEC3_OR_ONE, None)
    TYPE = "force_torque"


#: every sensor class by its `type` key (the scenario schema's `sensors:` entries are made from these)
TYPES = {c.TYPE: c for c in (Gyro, StarTracker, Encoder, Tachometer, BaseVelocity, BasePosition, ForceTorque)}

#: how the telemetry's configuration columns are made: "integrate" (Naveen, Shah, Misra, Appendix C: poses
#: rebuilt by integrating the measured rates from the true initial configuration) or "measured" (from a
#: star tracker, encoders and a base position sensor)
POSES = ("integrate", "measured")
#: the rule that integrates the rates into poses (poses="integrate"): "trapezoid" (second order, the default) or
#: "hermite" (fourth order: the trapezoid plus the endpoint correction from the rates' derivatives, differenced
#: from the telemetry; `io.telemetry.integrate_poses`)
INTEGRATION = ("trapezoid", "hermite")
#: the default rule. The Hermite rule is far better on motions whose accelerations are continuous between samples
#: (the post-capture runs: the momentum form's floor 2.0 % -> 0.09 %), but worse where they jump every few samples
#: (held commands: the mission's adaptive berth at 20 Hz, 0.08 % -> 0.49 % on the target's inertia), so it is
#: chosen, not assumed (docs/sensors.md, "Poses")
DEFAULT_INTEGRATION = "trapezoid"


@dataclass
class SensorSet:
    """A list of sensors and how their streams become one telemetry table: `poses` (see POSES), `integration`
    (see INTEGRATION) and `telemetry_rate` [Hz] (None: the rate of the fastest sensor feeding q or v; slower sensors
    are held, as a flight computer's telemetry frame holds the latest sample)."""

    sensors: list = field(default_factory=list)
    poses: str = "integrate"
    telemetry_rate: float | None = None
    integration: str = DEFAULT_INTEGRATION

    def __post_init__(self):
        if self.poses not in POSES:
            raise InputError(f"telemetry.poses: expected one of {', '.join(POSES)}, got {self.poses!r}")
        if self.integration not in INTEGRATION:
            raise InputError(
                f"telemetry.integration: expected one of {', '.join(INTEGRATION)}, got {self.integration!r}"
            )
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
        d["telemetry"]["integration"] = self.integration
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
        integration="trapezoid",  # Appendix C's reconstruction, as `add_noise`, whatever the default
    )


# -- presets by hardware class ------------------------------------------------------------------------------
# Each preset stands for a class of hardware through one product's datasheet figures, kept below in the
# datasheet's own units with the document they come from; the SI values are computed from them here (and the
# tests recompute them), and docs/sensors.md tabulates both. Conversions:
#   1 °/√h = (π/180)/60 rad/√s ≈ 2.909e-4 rad/s/√Hz (angle random walk N; a rad/√s is a rad/s/√Hz)
#   1 °/s/√Hz = π/180 rad/s/√Hz ≈ 1.745e-2 rad/s/√Hz
#   1 °/h = (π/180)/3600 rad/s ≈ 4.848e-6 rad/s (bias instability B)
DEG = math.pi / 180.0
DEG_PER_SQRT_HOUR = DEG / 60.0
DEG_PER_HOUR = DEG / 3600.0


@dataclass(frozen=True)
class GyroSheet:
    """A rate gyro's datasheet figures in the datasheet's units: angle random walk `arw_deg_per_sqrt_h` [°/√h]
    or a rate noise density `density_deg_per_s_per_sqrt_hz` [°/s/√Hz] (the same white noise in other units),
    bias instability `bias_instability_deg_per_h` [°/h]; `correlation_time_s` is the Gauss-Markov stand-in's
    T_c, which the datasheets do not give (an assumption, see docs/sensors.md). No rate random walk: none of
    the cited datasheets specifies one."""

    product: str
    document: str
    bias_instability_deg_per_h: float
    correlation_time_s: float
    arw_deg_per_sqrt_h: float | None = None
    density_deg_per_s_per_sqrt_hz: float | None = None

    @property
    def noise_density(self) -> float:
        """N [rad/s/√Hz]."""
        if self.arw_deg_per_sqrt_h is not None:
            return self.arw_deg_per_sqrt_h * DEG_PER_SQRT_HOUR
        return self.density_deg_per_s_per_sqrt_hz * DEG

    @property
    def bias_instability(self) -> float:
        """B [rad/s]."""
        return self.bias_instability_deg_per_h * DEG_PER_HOUR


@dataclass(frozen=True)
class EncoderSheet:
    """A joint angle sensor's datasheet figures: `counts_per_rev` (the output's resolution) and its white
    `noise` [rad rms] (0 when the datasheet gives none), with how the noise was read (`noise_note`)."""

    product: str
    document: str
    counts_per_rev: float
    noise: float = 0.0
    noise_note: str = ""

    @property
    def resolution(self) -> float:
        """Δ [rad]."""
        return 2.0 * math.pi / self.counts_per_rev


@dataclass(frozen=True)
class ForceTorqueSheet:
    """A six-axis force/torque sensor's noise [N, N·m] and where it comes from."""

    product: str
    document: str
    force_noise: float
    torque_noise: float


#: RESOLUTE's ring: the smallest listed diameter [m] (the largest angle for a given jitter)
_RESOLUTE_RING_DIAMETER = 0.052

#: the hardware each preset stands for (docs/sensors.md, "Presets by hardware class", cites each document)
HARDWARE = {
    "mems": {
        "gyro": GyroSheet(
            product="Analog Devices ADIS16470 (industrial MEMS IMU)",
            document="ADIS16470 data sheet, features list: 0.008 °/s/√Hz rms rate noise density, 8 °/h in-run "
            "bias stability",
            density_deg_per_s_per_sqrt_hz=0.008,
            bias_instability_deg_per_h=8.0,
            correlation_time_s=100.0,
        ),
        "encoder": EncoderSheet(
            product="ams AS5048A (14-bit magnetic rotary encoder)",
            document="AS5048A/AS5048B data sheet v1-06: 14-bit resolution (0.0219 °/LSB), sensor output noise "
            "0.06 ° rms (maximum)",
            counts_per_rev=2.0**14,
            noise=0.06 * DEG,
            noise_note="the data sheet's maximum output noise, 0.06 ° rms, taken as the noise",
        ),
    },
    "tactical": {
        "gyro": GyroSheet(
            product="KVH DSP-1750 / DSP-1760 (tactical fibre-optic gyro)",
            document="KVH DSP-1760 data sheet: angle random walk ≤ 0.012 °/√h (≤ 0.7 °/h/√Hz); KVH DSP-1750 "
            "technical manual: bias instability 0.05 °/h",
            arw_deg_per_sqrt_h=0.012,
            bias_instability_deg_per_h=0.05,
            correlation_time_s=1000.0,
        ),
        "encoder": EncoderSheet(
            product="ROBOTIS DYNAMIXEL-P PH54-200-S500-R (geared servo actuator)",
            document="ROBOTIS e-Manual, PH54-200-S500-R specifications: resolution 1,003,846 pulse/rev at the "
            "output (gear ratio 501.923:1, backlash < 6 arcmin)",
            counts_per_rev=1_003_846.0,
            noise=0.0,
            noise_note="no noise figure in the specification; quantisation only",
        ),
    },
    "navigation": {
        "gyro": GyroSheet(
            product="Honeywell HG9900 (navigation-grade ring-laser-gyro IMU)",
            document="HG9900 IMU brochure N61-1638-000-000: angle random walk 0.002 °/√h (max), gyro bias "
            "0.0035 °/h (1σ)",
            arw_deg_per_sqrt_h=0.002,
            bias_instability_deg_per_h=0.0035,
            correlation_time_s=3600.0,
        ),
        "encoder": EncoderSheet(
            product="Renishaw RESOLUTE absolute optical encoder with a Ø52 mm RESA/REXA ring",
            document="Renishaw RESOLUTE rotary (angle) product pages: resolutions to 32 bits/rev, jitter "
            "< 10 nm RMS, rings from Ø52 mm",
            counts_per_rev=2.0**32,
            noise=10e-9 / (_RESOLUTE_RING_DIAMETER / 2.0),
            noise_note="10 nm RMS jitter at the scale, on the Ø52 mm ring's radius: 10 nm / 26 mm rad",
        ),
    },
}

#: one force/torque class for every preset (the F/T sensor does not follow the IMU's grade)
FORCE_TORQUE = ForceTorqueSheet(
    product="ATI Axia80-M20, calibration SI-500-20 (Fx, Fy 500 N; Fz 900 N; Tx, Ty, Tz 20 N·m)",
    document="ATI manual 9610-05-Ethernet Axia: unloaded jumps above 0.05 % of full scale are abnormal; 0.05 % of "
    "500 N and of 20 N·m, taken as the noise (an upper bound, not a measured noise)",
    force_noise=0.0005 * 500.0,
    torque_noise=0.0005 * 20.0,
)


def _preset_rate(rate) -> float:
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not (math.isfinite(rate) and rate > 0):
        raise InputError(f"preset rate: expected a positive number of Hz, got {rate!r}")
    return float(rate)


def _hardware_class(cls: str, rate, force_torque, base_velocity_noise) -> SensorSet:
    rate = _preset_rate(rate)
    period = 1.0 / rate
    g, e = HARDWARE[cls]["gyro"], HARDWARE[cls]["encoder"]
    n = g.noise_density
    if base_velocity_noise is None:
        # modelling convention, not a datasheet figure (see `mems`): the gyro's density times a 1 m lever arm
        base_velocity_noise = n * 1.0 / math.sqrt(period)
    elif isinstance(base_velocity_noise, bool) or not isinstance(base_velocity_noise, (int, float)):
        raise InputError(f"preset base_velocity_noise: expected a number of m/s, got {base_velocity_noise!r}")
    # joint rates: the difference of two successive encoder readings over one period (see `mems`)
    tach_noise = math.sqrt(2.0 * e.noise**2 + e.resolution**2 / 6.0) / period
    sensors = [
        BaseVelocity(rate=rate, noise=float(base_velocity_noise)),
        Gyro(
            rate=rate,
            noise_density=n,
            bias_instability=g.bias_instability,
            bias_correlation_time=g.correlation_time_s,
        ),
        Tachometer(rate=rate, noise=tach_noise),
        Encoder(rate=rate, counts_per_rev=e.counts_per_rev, noise=e.noise),
    ]
    if force_torque is not None:
        if not isinstance(force_torque, str) or not force_torque:
            raise InputError(f"preset force_torque: expected a joint name, got {force_torque!r}")
        ft = FORCE_TORQUE
        sensors.append(
            ForceTorque(rate=rate, joint=force_torque, force_noise=ft.force_noise, torque_noise=ft.torque_noise)
        )
    return SensorSet(sensors, poses="integrate")


def mems(rate: float = 100.0, force_torque: str | None = None, base_velocity_noise: float | None = None) -> SensorSet:
    """Industrial MEMS class: the sensors of a low-cost free-flyer, sampled at `rate` [Hz] (100: the usual
    telemetry rate), poses rebuilt by integrating the rates (as `naveen`). Figures in `HARDWARE["mems"]`,
    sources and SI values in docs/sensors.md ("Presets by hardware class").

    - gyro: Analog Devices ADIS16470, N = 0.008 °/s/√Hz = 1.396e-4 rad/s/√Hz, B = 8 °/h = 3.879e-5 rad/s
      as a Gauss-Markov bias of T_c = 100 s (T_c assumed; the data sheet gives none), no rate random walk and
      no constant bias (a turn-on bias is taken as calibrated out);
    - joint encoders: ams AS5048A, 14 bits/rev, white noise 0.06 ° rms (the data sheet's maximum), every
      revolute joint (a prismatic joint needs its own encoder with `resolution` [m]);
    - joint tachometers: the encoder differenced, below;
    - base velocity: a modelling convention, below;
    - `force_torque`: a joint name adds a six-axis force/torque sensor of class `FORCE_TORQUE` (ATI Axia80)
      measuring the wrench that joint transmits.

    Joint rates. A joint with only a position sensor reports its rate as the difference of two successive
    readings over the period P: ω̃_k = (θ̃_k − θ̃_{k−1})/P. The reading errors (white noise σ_n and quantisation
    of variance Δ²/12, independent from one reading to the next when the joint crosses many counts) give the
    rate an error of variance (2σ_n² + Δ²/6)/P², so the tachometer's white noise is derived from the encoder
    and the rate rather than quoted: σ_ω = √(2σ_n² + Δ²/6)/P, which grows as the rate rises (0.149 rad/s here
    at 100 Hz, the AS5048A's noise dominating). A dedicated rate sensor or a filter in the joint's controller
    would do better; give your own `Tachometer` then. Two things the white model leaves out: successive
    differences share a reading (their errors have a lag-one correlation of −1/2, so the angle integrated from
    them stays within the encoder's error where the white model lets it random-walk), and a difference is the
    mean rate over the period, not the rate at its end.

    Base velocity. No inertial sensor measures the base's linear velocity: an accelerometer's integral drifts
    as a random walk, which the `base_velocity` model (white noise and bias) cannot represent, and relative
    navigation (a camera or lidar on the target) has no single datasheet class. So its noise is a modelling
    convention, not a datasheet figure: a white density equal to the gyro's N times a 1 m lever arm,
    σ_v = N·(1 m)/√P per sample, which keeps the classes in order; `base_velocity_noise` [m/s per sample]
    overrides it."""
    return _hardware_class("mems", rate, force_torque, base_velocity_noise)


def tactical(
    rate: float = 100.0, force_torque: str | None = None, base_velocity_noise: float | None = None
) -> SensorSet:
    """Tactical fibre-optic-gyro class, built as `mems` (read its notes on joint rates and base velocity):

    - gyro: KVH DSP-1750 / DSP-1760, N = 0.012 °/√h = 3.491e-6 rad/s/√Hz, B = 0.05 °/h = 2.424e-7 rad/s as
      a Gauss-Markov bias of T_c = 1000 s (assumed);
    - joint encoders: ROBOTIS DYNAMIXEL-P PH54-200-S500-R geared actuator, 1,003,846 pulses per output
      revolution, no noise figure (quantisation only; its backlash, < 6 arcmin, is not modelled);
    - joint tachometers: the encoder differenced, σ_ω = Δ/(P√6) = 2.56e-4 rad/s at 100 Hz;
    - base velocity: N·(1 m)/√P per sample (convention), or `base_velocity_noise`;
    - `force_torque`: a joint name adds the ATI Axia80 class force/torque sensor."""
    return _hardware_class("tactical", rate, force_torque, base_velocity_noise)


def navigation(
    rate: float = 100.0, force_torque: str | None = None, base_velocity_noise: float | None = None
) -> SensorSet:
    """Navigation-grade class (ring-laser-gyro IMU, precision optical joint encoders), built as `mems` (read
    its notes on joint rates and base velocity):

    - gyro: Honeywell HG9900, N = 0.002 °/√h = 5.818e-7 rad/s/√Hz, B = 0.0035 °/h = 1.697e-8 rad/s as a
      Gauss-Markov bias of T_c = 3600 s (assumed);
    - joint encoders: Renishaw RESOLUTE, 32 bits/rev, white noise of its < 10 nm RMS jitter on a Ø52 mm
      ring, 10 nm / 26 mm = 3.85e-7 rad;
    - joint tachometers: the encoder differenced, 5.44e-5 rad/s at 100 Hz (the jitter dominating);
    - base velocity: N·(1 m)/√P per sample (convention), or `base_velocity_noise`;
    - `force_torque`: a joint name adds the ATI Axia80 class force/torque sensor."""
    return _hardware_class("navigation", rate, force_torque, base_velocity_noise)


#: built-in sensor sets by name (`--sensors NAME` on the command line, `preset:` in a sensors file)
PRESETS = {"naveen": naveen, "mems": mems, "tactical": tactical, "navigation": navigation}


def _known_presets() -> str:
    return ", ".join(PRESETS)


def _from_preset(spec) -> SensorSet:
    """A preset's SensorSet from `NAME` or `{name: NAME, <option>: value, ...}` (the preset function's keyword
    arguments: `rate`, `force_torque`, `base_velocity_noise`; naveen: `sigma_lin`, `sigma_ang`, `sigma_joint`,
    `rate`)."""
    if isinstance(spec, dict):
        opts = dict(spec)
        name = opts.pop("name", None)
        if name is None:
            raise InputError(f"preset: a mapping needs `name:` (one of {_known_presets()}), got {spec!r}")
    else:
        name, opts = spec, {}
    if not isinstance(name, str) or name not in PRESETS:
        raise InputError(f"preset: unknown preset {name!r} (known: {_known_presets()})")
    fn = PRESETS[name]
    params = list(inspect.signature(fn).parameters)
    for k in opts:
        if k not in params:
            raise InputError(f"preset.{k}: not an option of preset '{name}' (its options: {', '.join(params)})")
    return fn(**opts)


def load(spec) -> SensorSet:
    """A SensorSet from a SensorSet, a list of sensors (objects or dicts), a dict with `sensors:` and optionally
    `telemetry: {rate, poses, integration}`, a preset name (see PRESETS), a dict with `preset:` (a name, or
    `{name: NAME, rate: Hz, ...}` with the preset's options) plus optionally more `sensors:`, or a YAML/JSON file
    holding one of those."""
    if isinstance(spec, SensorSet):
        return spec
    if isinstance(spec, str) and spec in PRESETS:
        return PRESETS[spec]()
    if isinstance(spec, (str, Path)):
        p = Path(spec)
        if not p.exists():
            if isinstance(spec, str) and not p.suffix and len(p.parts) == 1:
                # a bare word: meant as a preset, most likely
                raise InputError(
                    f"sensors: unknown preset {spec!r} (known: {_known_presets()}) and no sensors file of that name"
                )
            raise FileNotFoundError(f"sensors file not found: {p} (or a preset: {_known_presets()})")
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
        if not isinstance(tel, dict) or set(tel) - {"rate", "poses", "integration"}:
            raise InputError(f"telemetry: expected a mapping with keys rate, poses, integration; got {tel!r}")
        if "preset" in spec:
            base = _from_preset(spec["preset"])
            sensors = base.sensors + list(spec.get("sensors") or [])
            poses, integration = tel.get("poses", base.poses), tel.get("integration", base.integration)
        else:
            if "sensors" not in spec:
                raise InputError("sensors file: missing the `sensors:` list (or `preset:`)")
            sensors, poses = list(spec["sensors"] or []), tel.get("poses", "integrate")
            integration = tel.get("integration", DEFAULT_INTEGRATION)
        return SensorSet(sensors, poses=poses, telemetry_rate=tel.get("rate"), integration=integration)
    raise InputError(
        f"argument `sensors`: expected a SensorSet, a list, a dict, a preset name ({_known_presets()}) or a file, "
        f"got {spec!r}"
    )


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
        qm = integrate_poses(model, grid, vm, q[k_true[0]], rule=sset.integration)
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
