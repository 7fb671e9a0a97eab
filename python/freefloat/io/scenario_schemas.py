"""The declared schema of every scenario kind (`freefloat scenarios`) and of the campaign spec: which keys a file
may have, their types and ranges. `scenario_files.read` checks each file against its kind's schema before the
command reads it, so a typo, a value of the wrong type or out of range is refused with the file, line and key
(see `schema.py`). Each command still checks what only it can (a list's length against the robot, say).

A key that is not declared here is refused: a new key of a scenario kind is declared in its class below, a new
block shared by several kinds with `schema.register_block`."""

from __future__ import annotations

import math
import typing
from typing import Annotated

from pydantic import BeforeValidator, Field, create_model, model_validator

from ..sensors import TYPES as SENSOR_CLASSES
from ..simulation import environment as env
from ..simulation.actuators import BLOCKS as ACTUATOR_BLOCKS
from .schema import (
    _TYPES_ONLY,
    Anything,
    Block,
    Bool,
    NonNegative,
    Number,
    Positive,
    Text,
    _Bad,
    block_of,
    integer,
    literal,
    number,
    numbers,
    refuse_block,
    register_block,
    register_kind,
)

Numbers = numbers()
NumberOrNumbers = numbers(scalar_ok=True)


class _Scenario(Block):
    name: Text | None = None
    description: Text | None = None
    paper: Anything = None


# -- postcapture (freefloat identify postcapture; Zhang, Yue, Yuan 2020) ------------------------------------
class PcInitial(Block):
    base_position: Numbers = None
    base_yaw_deg: Number = 0.0
    joints_deg: Numbers
    base_velocity: Numbers
    base_rate: NumberOrNumbers


class PcControl(Block):
    F_max: Positive
    K_F: Number
    M_max: Positive
    K_M: Number
    K_D: NumberOrNumbers
    K_P: NumberOrNumbers
    jet: numbers(3) = None


class PcExcitation(Block):
    damping: NonNegative = 0.0
    amplitude: Numbers
    frequency: Numbers
    phase_deg: Numbers = None


class PcGuessBody(Block):
    mass: Positive
    com: Numbers
    inertia: numbers(scalar_ok=True, nested_ok=True, lo=0.0, lo_open=True)


class PcGuess(Block):
    base: PcGuessBody
    target: PcGuessBody


class PcIdentification(Block):
    transit_tolerance: Positive
    P0: Positive = 1e6
    forgetting: number(lo=0.0, hi=1.0, lo_open=True) = 1.0
    guess: PcGuess
    project: Bool = False


class PcMeasurement(Block):
    accelerations: literal("exact", "central_difference", "savgol", "rts") = "exact"
    impulses: literal("simpson", "trapezoid") = "simpson"
    # the point the momentum form balances angular momentum about: the moving base point (robust to a drifting
    # system measured with an integrated attitude) or the inertial origin (the paper's eqs. 9-10)
    momentum_point: literal("base", "origin") = "base"
    # Savitzky-Golay derivative (accelerations: savgol): window in samples of the differentiated rates (the
    # telemetry's with sensors, else one every sample_period), odd; polynomial degree below it
    savgol_window: integer(lo=3) = None
    savgol_polyorder: integer(lo=1) = None

    @model_validator(mode="after")
    def _savgol(self):
        if _TYPES_ONLY.get():
            return self
        given = [k for k in ("savgol_window", "savgol_polyorder") if getattr(self, k) is not None]
        if given and self.accelerations != "savgol":
            raise _Bad(
                f"key 'measurement.{given[0]}': applies to accelerations: savgol only (accelerations is "
                f"'{self.accelerations}')"
            )
        w = self.savgol_window
        if w is not None and w % 2 == 0:
            raise _Bad(f"key 'measurement.savgol_window': must be an odd number of samples, got {w}")
        p = self.savgol_polyorder
        if p is not None and w is not None and p >= w:
            raise _Bad(f"key 'measurement.savgol_polyorder': {p} must be below savgol_window = {w}")
        return self


class PcNoise(Block):
    velocity: NonNegative = 0.0
    acceleration: NonNegative = 0.0
    force: NonNegative = 0.0


class PcSweep(Block):
    velocities: Anything


# the largest number of integration steps a scenario may ask for up front (a 1e7 s run at 1 ms is 1e10 steps:
# hours of work and tens of GB of trajectory): refused with the keys to change rather than started
MAX_STEPS = 50_000_000


class Postcapture(_Scenario):
    kind: literal("postcapture") = "postcapture"
    model: Text
    duration: Positive
    dt: Positive = 1e-3
    sample_period: Positive = 0.1
    initial: PcInitial
    control: PcControl
    excitation: PcExcitation
    identification: PcIdentification
    measurement: PcMeasurement | None = None
    noise: PcNoise | None = None
    sweep: PcSweep | None = None
    paper_sweep: Anything = None

    @model_validator(mode="after")
    def _timing(self):
        if _TYPES_ONLY.get():
            return self
        ratio = self.sample_period / self.dt
        if round(ratio) < 2 or abs(ratio - round(ratio)) > 1e-6 * ratio or round(ratio) % 2:
            raise _Bad(
                f"key 'sample_period': must be an even multiple (>= 2) of dt = {self.dt:g} s (Simpson's rule "
                f"between samples), got {self.sample_period:g} s"
            )
        if self.sample_period > self.duration / 2:
            raise _Bad(
                f"key 'sample_period': {self.sample_period:g} s leaves fewer than 3 samples in duration = "
                f"{self.duration:g} s"
            )
        sensors = getattr(self, "sensors", None)
        check_sensor_names(sensors)
        check_sensor_rates(sensors, self.dt)
        steps = self.duration / self.dt
        if steps > MAX_STEPS:
            raise _Bad(
                f"key 'duration': {self.duration:g} s at dt = {self.dt:g} s is {steps:.3g} steps, above the limit "
                f"of {MAX_STEPS:.0e} (shorten duration or lengthen dt)"
            )
        return self


# -- control_adaptive (freefloat control adaptive; Valverde 2018 ch. 4) -------------------------------------
class Harmonic(Block):
    offset: numbers(3) = None
    amplitude: numbers(3) = None
    frequency: numbers(3) = None
    phase: numbers(3) = None


class AdInitial(Block):
    attitude: numbers(4)
    position: numbers(3)
    angular_velocity: numbers(3)
    linear_velocity: numbers(3)
    estimate: numbers(7) = None


_Gain = numbers(scalar_ok=True, nested_ok=True)


class AdGains(Block):
    K_r: _Gain
    K_q: _Gain
    K_v: _Gain
    K_w: _Gain
    K_i: _Gain


class AdLearning(Block):
    mode: literal("continuous", "discrete") = "continuous"
    alpha: numbers(scalar_ok=True, lo=0.0) = None
    n_s: integer(lo=2) = 50
    sigma_stop: Positive | None = None
    selection: literal("elementwise", "max_min_sv") = "elementwise"
    seed: integer(lo=0) = 0
    law: Text = "corrected"
    alpha_off_after: NonNegative | None = None


class AdReference(Block):
    angular: Harmonic | None = None
    linear: Harmonic | None = None
    table: Anything = None


class AdSimulation(Block):
    duration: Positive
    method: literal("dopri5", "rk4") = "dopri5"
    dt: Positive = 0.01
    rtol: number(lo=0.0, hi=1.0, lo_open=True, hi_open=True) = 1e-10
    atol: Positive = 1e-10
    max_step: Positive | None = None
    output_dt: Positive = 0.01


class ControlAdaptive(_Scenario):
    kind: literal("control_adaptive")
    truth: numbers(7)
    initial: AdInitial
    gains: AdGains
    learning: AdLearning | None = None
    reference: AdReference | None = None
    simulation: AdSimulation


# -- identify_cl (freefloat identify cl; Valverde 2018 ch. 9) -----------------------------------------------
class ClInitial(Block):
    joints_deg: Anything = None  # joint name -> value: the names are checked against the robot by the command
    joints: Anything = None
    rates: Anything = None


class ClExcitation(Block):
    amplitude: Number = None
    frequency: Number = None
    phase: Number = None
    t_start: Number = None
    t_end: Number = None


class ClEstimator(Block):
    ns: integer(lo=1) = None
    sigma_th: NonNegative = None
    t_th: NonNegative = None
    aggressive: Bool = None
    t_th2: NonNegative = None
    sigma_th2: NonNegative = None
    sigma_new: NonNegative = None
    gain: literal("thesis", "truncated") = None  # (9.27) for every weak direction, or only where data beat noise
    kappa: Positive = None  # the truncated gain's evidence threshold (in noise standard deviations)
    seed: integer(lo=0) = None
    initial_estimate: Anything = None  # body name -> 7 numbers: checked against the robot by the command


class ClStudies(Block):
    ns_sweep: Anything = None
    wrench_noise: numbers(lo=0.0) = None
    rate_noise: numbers(lo=0.0) = None
    noise_seed: integer(lo=0) = None


class IdentifyCl(_Scenario):
    kind: literal("identify_cl")
    model: Text
    duration: Positive = 10.0
    dt: Positive = 0.01
    initial: ClInitial | None = None
    excitation: ClExcitation | None = None
    estimator: ClEstimator | None = None
    studies: ClStudies | None = None


# -- control_ddp (freefloat control ddp; Valverde 2018 ch. 8) -----------------------------------------------
# The top-level keys are declared; the blocks' insides are checked by the DDP command itself (its settings are
# still growing: MPC, schedules), so here they only need to be mappings.
class ControlDdp(_Scenario):
    kind: literal("control_ddp")
    robot: Text
    frame: Text = None
    dt: Positive
    horizon: integer(lo=1)
    cost: literal("dq", "log") = "dq"
    # the dq cost against the reference's sign: 'nearest' (±q_D, a pose metric) or 'literal' (the thesis' q_G − q_D)
    dq_sign: literal("nearest", "literal") = "nearest"
    # 'rate': the thesis' massless wrist, its joints (wrist_joints, the model's last) driven by Euler-angle rates;
    # 'torque': the model's wrist bodies driven by joint torques
    wrist: literal("rate", "torque") = "torque"
    wrist_joints: list[Text] | None = None
    initial_state: dict | None = None
    reference: dict
    schedule: Anything = None
    weights: dict
    keep_out: dict | None = None
    initial_controls: literal("zero", "gaussian") = "zero"
    gaussian: dict | None = None
    solver: dict | None = None
    mpc: dict | None = None


# -- simulate (freefloat simulate SCENARIO.yaml): a model, its initial state, torques, and the blocks below ------
class SimInitial(Block):
    q: Numbers = None
    v: Numbers = None


class SimTorques(Block):
    # one of three forms; joint names and table columns are checked against the robot when the file is read
    # joint name -> generalized force held through the run [N m or N]
    constant: dict[str, Number] | None = None
    # a piecewise-constant schedule: [{t: 0.0, J0: 0.1}, {t: 2.0, J0: 0.0}, ...], each entry changing the named
    # joints from its time t on (the others keep their value; zero before a joint's first entry)
    steps: list[dict[str, Number]] | None = None
    # a CSV or Parquet file (relative to the scenario file) with a column t and tau.<coordinate> columns
    table: Text | None = None
    hold: literal("zoh", "linear") = None

    @model_validator(mode="after")
    def _one_form(self):
        if _TYPES_ONLY.get():
            return self
        given = [k for k in ("constant", "steps", "table") if getattr(self, k) is not None]
        if len(given) > 1:
            raise _Bad(f"key 'torques': give one of constant, steps or table, not {' and '.join(given)}")
        if self.hold is not None and self.table is None:
            raise _Bad("key 'torques.hold': applies to torques.table only (steps and constant are held as given)")
        t_prev = None
        for k, entry in enumerate(self.steps or []):
            t = entry.get("t")
            if t is None:
                raise _Bad(f"key 'torques.steps[{k}]': every entry needs its time t [s], e.g. {{t: 0.0, J1: 0.1}}")
            if not math.isfinite(t) or t < 0 or (t_prev is not None and t <= t_prev):
                need = "at least 0" if t_prev is None else f"later than the previous entry's {t_prev:g} s"
                raise _Bad(f"key 'torques.steps[{k}].t': {t!r} s must be finite and {need}")
            if len(entry) < 2:
                raise _Bad(f"key 'torques.steps[{k}]': names no joint (give joint: value pairs beside t)")
            t_prev = t
        return self


class Simulate(_Scenario):
    kind: literal("simulate")
    model: Text
    duration: Positive
    dt: Positive = 1e-3
    method: literal("rk4", "rk45") = "rk4"
    rtol: number(lo=0.0, hi=1.0, lo_open=True, hi_open=True) = 1e-9
    atol: Positive = 1e-12
    record_every: integer(lo=1) = 1
    formulation: literal("aba", "dq") = "aba"
    input_timing: literal("step", "stage") = "step"
    initial: SimInitial | None = None
    torques: SimTorques | None = None
    seed: integer(lo=0) = 0

    @model_validator(mode="after")
    def _timing(self):
        if _TYPES_ONLY.get():
            return self
        sensors = getattr(self, "sensors", None)
        check_sensor_names(sensors)
        # the sensors sample the recorded run: one sample every record_every steps of dt
        check_sensor_rates(sensors, self.dt * self.record_every, "dt × record_every")
        steps = self.duration / self.dt
        if steps > MAX_STEPS:
            raise _Bad(
                f"key 'duration': {self.duration:g} s at dt = {self.dt:g} s is {steps:.3g} steps, above the limit "
                f"of {MAX_STEPS:.0e} (shorten duration or lengthen dt)"
            )
        return self


# -- mission (freefloat mission): capture, identify online, berth with the estimate -------------------------
class MissionBody(Block):
    mass: Positive
    com: numbers(3) = None
    inertia: Numbers


class MissionTarget(MissionBody):
    velocity: numbers(3) = None
    rate: numbers(3) = None
    guess: MissionBody


class MissionCapture(Block):
    approach_s: NonNegative = 10.0
    joints_deg: Numbers
    base_velocity: numbers(3) = None
    base_rate: numbers(3) = None


class MissionConvergence(Block):
    mass: Positive = 0.02
    com: Positive = 0.01
    inertia: Positive = 0.05
    window: Positive = 5.0


class MissionIdentify(Block):
    method: literal("momentum", "force") = "momentum"
    max_duration: Positive = 60.0
    min_duration: NonNegative = 2.0
    convergence: MissionConvergence | None = None


class MissionBerth(Block):
    duration: Positive = 20.0
    dt: Positive = 0.05
    position: numbers(3)
    rpy_deg: numbers(3) = None
    position_tolerance: Positive = 0.01
    angle_tolerance_deg: Positive = 1.0
    weights: dict | None = None
    max_iter: integer(lo=1) = 100
    controller: literal("policy", "mpc") = "policy"
    isp: Positive = 220.0
    # the adaptive berth: MPC re-planning on the estimate the berth's own telemetry keeps refining
    adaptive: Bool = True
    update_every_s: Positive = 1.0
    update_tolerance: Positive = 1e-3


class MissionGrasp(Block):
    body: Text
    xyz: numbers(3) = None
    rpy_deg: numbers(3) = None


class MissionDetumble(Block):
    # the post-capture blocks of a scenario, for a servicer that has no post-capture scenario of its own
    dt: Positive = 1e-3
    sample_period: Positive = 0.1
    control: PcControl
    excitation: PcExcitation
    identification: PcIdentification


class Mission(_Scenario):
    kind: literal("mission")
    servicer: Text
    grasp: MissionGrasp | None = None
    detumble: Text | MissionDetumble
    target: MissionTarget
    capture: MissionCapture
    identify: MissionIdentify | None = None
    berth: MissionBerth


# -- campaign specs (freefloat campaign) --------------------------------------------------------------------
class MonteCarlo(Block):
    runs: integer(lo=1)
    seed: integer(lo=0) = 0
    parameters: dict | None = None


class Campaign(Block):
    name: Text
    description: Text | None = None
    kind: Text
    scenario: Anything
    set: dict | None = None
    grid: dict | None = None
    monte_carlo: MonteCarlo | None = None
    paper: Anything = None


register_kind("postcapture", Postcapture, command="freefloat identify postcapture")
register_kind("control_adaptive", ControlAdaptive, command="freefloat control adaptive")
register_kind("identify_cl", IdentifyCl, command="freefloat identify cl")
register_kind("control_ddp", ControlDdp, command="freefloat control ddp")
register_kind("simulate", Simulate, command="freefloat simulate")
register_kind("mission", Mission, command="freefloat mission")
register_kind("campaign", Campaign)


# -- shared blocks: actuators, environment, sensors (issue 17) ---------------------------------------------
# Each block maps 1:1 onto the Python API object that runs it (freefloat.Actuators, freefloat.Environment,
# freefloat.sensors.SensorSet): the keys are those objects' fields, so a scenario block and a
# `simulate --actuators/--environment` / `measure --sensors` file read the same. Checks that need the robot (a
# tank heavier than its body, a joint name) are the engine's, run when the scenario is read (scenario readers).
Vec3 = numbers(3)
NonNegOrNonNegs = numbers(scalar_ok=True, lo=0.0)
OptPositive = Positive | None


def _norm(x) -> float:
    return math.sqrt(sum(float(c) ** 2 for c in x))


# the keys of each actuator, their types, ranges and defaults: declared once, by the classes that run them
# (`freefloat.Wheel`, ...; the engine's key order and wheel defaults)
ActLimit = ACTUATOR_BLOCKS["limits"]
ActWheel = ACTUATOR_BLOCKS["wheels"]
ActThruster = ACTUATOR_BLOCKS["thrusters"]
ActTank = ACTUATOR_BLOCKS["tanks"]


class ActuatorsBlock(Block):
    limits: list[ActLimit] = []
    wheels: list[ActWheel] = []
    thrusters: list[ActThruster] = []
    tanks: list[ActTank] = []

    @model_validator(mode="after")
    def _cross(self):
        if _TYPES_ONLY.get():
            return self
        limited = {}
        for j, lim in enumerate(self.limits):
            at = f"actuators.limits[{j}]"
            if lim.joint in limited:
                raise _Bad(
                    f"key '{at}.joint': joint '{lim.joint}' is limited twice (actuators.limits[{limited[lim.joint]}] "
                    "limits it too)"
                )
            limited[lim.joint] = j
            if lim.effort is None and lim.velocity is None:
                raise _Bad(f"key '{at}': give an effort, a velocity limit or both for joint '{lim.joint}'")
        seen = set()
        for j, w in enumerate(self.wheels):
            at = f"actuators.wheels[{j}]"
            if w.joint in seen:
                raise _Bad(f"key '{at}.joint': joint '{w.joint}' has two wheel models")
            seen.add(w.joint)
            if w.static_friction and w.static_friction < w.coulomb:
                raise _Bad(
                    f"key '{at}.static_friction': {w.static_friction:g} N m is below the Coulomb friction "
                    f"{w.coulomb:g} N m (inverted: static friction must be >= coulomb)"
                )
            if w.static_friction > w.coulomb and w.stribeck_speed is None:
                raise _Bad(f"key '{at}.stribeck_speed': static friction above Coulomb needs a Stribeck speed")
        names = [t.name for t in self.tanks]
        for j, t in enumerate(self.tanks):
            if names.index(t.name) != j:
                raise _Bad(f"key 'actuators.tanks[{j}].name': tank name '{t.name}' is used twice")
        for j, th in enumerate(self.thrusters):
            at = f"actuators.thrusters[{j}]"
            if not _norm(th.direction) > 1e-12:
                raise _Bad(f"key '{at}.direction': has zero length (a thrust direction needs a non-zero vector)")
            if th.tank is not None:
                if isinstance(th.tank, int) and th.tank >= len(self.tanks):
                    raise _Bad(f"key '{at}.tank': tank {th.tank} does not exist ({len(self.tanks)} tanks)")
                if isinstance(th.tank, str) and th.tank not in names:
                    raise _Bad(f"key '{at}.tank': no tank named '{th.tank}' (tanks: {', '.join(names) or 'none'})")
                if th.isp is None:
                    raise _Bad(f"key '{at}.isp': a thruster fed by a tank needs its Isp (s)")
            last_end = -math.inf
            for k, (start, dur) in enumerate(th.firings):
                if dur < 0:
                    raise _Bad(f"key '{at}.firings': firing {k} has a negative duration {dur:g} s")
                if start < last_end:
                    raise _Bad(
                        f"key '{at}.firings': firing {k} starts at {start:g} s, before firing {k - 1} ends at "
                        f"{last_end:g} s (firings must be in time order and not overlap)"
                    )
                last_end = start + max(dur, th.min_on_time)
        return self


# the keys of the `environment:` block, their types and defaults (the Earth's constants): declared once, by the
# module that reads the block (`freefloat.simulation.environment`)
EnvCentralBody = create_model("EnvCentralBody", __base__=Block, **env.CENTRAL_BODY_KEYS)
EnvOrbit = create_model("EnvOrbit", __base__=Block, **env.ORBIT_KEYS)
EnvDisturbance = create_model("EnvDisturbance", __base__=Block, **env.DISTURBANCE_KEYS)


class EnvironmentBlock(Block):
    central_body: EnvCentralBody | None = None
    orbit: EnvOrbit | None = None
    gravity_gradient: Bool = False
    j2: Bool = False
    disturbance: EnvDisturbance | None = None

    @model_validator(mode="after")
    def _cross(self):
        if _TYPES_ONLY.get():
            return self
        cb = self.central_body or EnvCentralBody()
        o = self.orbit
        if o is not None:
            given = [k for k in ("altitude", "semi_major_axis", "position") if getattr(o, k) is not None]
            if len(given) != 1:
                raise _Bad(
                    "key 'environment.orbit': give exactly one of altitude, semi_major_axis or position (+ velocity), "
                    f"got {', '.join(given) or 'none'}"
                )
            for k in ("inclination", "raan", "arg_periapsis", "true_anomaly"):
                if getattr(o, k) is not None and getattr(o, f"{k}_deg") is not None:
                    raise _Bad(f"key 'environment.orbit.{k}': give {k} or {k}_deg, not both")
            if o.semi_major_axis is not None:
                rp = o.semi_major_axis * (1.0 - (o.eccentricity or 0.0))
                if not rp > cb.radius:
                    raise _Bad(
                        f"key 'environment.orbit.semi_major_axis': the periapsis radius {rp:.6g} m is not above the "
                        f"central body's radius {cb.radius:.6g} m (the orbit would be below its surface)"
                    )
            if o.position is not None:
                if o.velocity is None:
                    raise _Bad("key 'environment.orbit.velocity': an orbit from a position needs its velocity")
                if not _norm(o.position) > cb.radius:
                    raise _Bad(
                        f"key 'environment.orbit.position': {_norm(o.position):.6g} m from the centre is not above "
                        f"the central body's radius {cb.radius:.6g} m"
                    )
        elif self.gravity_gradient or self.j2:
            which = "gravity_gradient" if self.gravity_gradient else "j2"
            raise _Bad(f"key 'environment.{which}': needs an orbit (add environment.orbit)")
        d = self.disturbance
        if d is not None and d.force is None and d.torque is None:
            raise _Bad("key 'environment.disturbance': give a force, a torque or both")
        return self


# the keys of each sensor, their types, ranges and defaults: declared once, by the classes that run them
# (`freefloat.sensors.Gyro`, ...); the file adds the `type` key that picks the class
class _GyroChecks(Block):
    @model_validator(mode="after")
    def _one_noise(self):
        if not _TYPES_ONLY.get() and self.noise_density is not None and self.noise_per_sample is not None:
            raise _Bad("key 'noise_per_sample': give noise_density or noise_per_sample, not both")
        return self


_SENSOR_CHECKS = {"gyro": _GyroChecks}
#: the schema block of each sensor type, made from its class
SENSOR_TYPES = {
    t: block_of(
        cls,
        name=f"Sen{cls.__name__}",
        base=_SENSOR_CHECKS.get(t),
        tags={"type": literal(t)},
    )
    for t, cls in SENSOR_CLASSES.items()
}
Sensor = Annotated[typing.Union[tuple(SENSOR_TYPES.values())], Field(discriminator="type")]


def _sensors_preset(x):
    """`sensors: {preset: NAME}` or `{preset: {name: NAME, rate: Hz, ...}}`: a preset of freefloat.sensors
    written out as its list of sensors, then checked as if the file had listed them."""
    if not isinstance(x, dict):
        return x
    if set(x) != {"preset"}:
        raise _Bad(
            "expected a list of sensors or a mapping {preset: NAME} (or {preset: {name: NAME, rate: Hz, ...}}), "
            f"got the keys {', '.join(map(str, x))}"
        )
    from .. import sensors
    from .._core import InputError

    try:
        return sensors.load({"preset": x["preset"]}).to_dicts()
    except InputError as e:
        raise _Bad(str(e)) from None


#: a list of sensors, or a preset that stands for one
SensorsBlock = Annotated[list[Sensor], BeforeValidator(_sensors_preset)]


class TelemetryBlock(Block):
    poses: literal("integrate", "measured") = "integrate"
    rate: Positive | None = None
    # poses: integrate only: the trapezoid (second order) or its Hermite correction (fourth order)
    integration: literal("trapezoid", "hermite") = "trapezoid"


def check_sensor_names(sensors) -> None:
    seen = {}
    for j, s in enumerate(sensors or []):
        n = s.name or s.type
        if n in seen:
            raise _Bad(f"key 'sensors[{j}].name': sensor name '{n}' is used twice (sensors[{seen[n]}] has it)")
        seen[n] = j


def check_sensor_rates(sensors, dt: float, run_key: str = "dt") -> None:
    """A sensor cannot sample faster than the run records (every integration step of `dt` seconds)."""
    for j, s in enumerate(sensors or []):
        if s.rate is not None and s.rate * dt > 1.0 + 1e-9:
            raise _Bad(
                f"key 'sensors[{j}].rate': {s.rate:g} Hz is above the integration rate {1.0 / dt:g} Hz "
                f"({run_key} = {dt:g} s); lower the rate or the step"
            )


# The kinds whose runner simulates the robot with the engine's simulator, and so applies these blocks. The other
# kinds refuse them with a message that says so (`schema.refuse_block`): control_adaptive integrates its own
# rigid-body dual-quaternion model, identify_cl its own estimator loop, control_ddp optimises over its own
# dynamics; none of them would pass a block to the simulator, and a block silently ignored is worse than none.
BLOCK_KINDS = ("postcapture", "simulate")
_NOT_APPLIED = {
    "control_adaptive": "its runner integrates its own rigid-body model (Valverde 2018 ch. 4), not the simulator",
    "identify_cl": "its runner drives the concurrent-learning estimator's own loop (Valverde 2018 ch. 9), not the "
    "simulator",
    "control_ddp": "its runner optimises over its own dynamics (Valverde 2018 ch. 8)",
}
for _name, _block in (
    ("actuators", ActuatorsBlock),
    ("environment", EnvironmentBlock),
    ("sensors", SensorsBlock),
    ("telemetry", TelemetryBlock),
):
    # a mission's detumble is a post-capture run: its own sensors replace the detumble scenario's; actuators and
    # environment belong to that scenario (the mission does not re-declare the spacecraft)
    register_block(_name, _block, kinds=BLOCK_KINDS + (("mission",) if _name in ("sensors", "telemetry") else ()))
    if _name in ("actuators", "environment"):
        refuse_block(
            _name,
            "mission",
            "a mission takes the spacecraft's actuators and environment from its detumble scenario (key 'detumble'); "
            "put the block there",
        )
    for _kind, _why in _NOT_APPLIED.items():
        refuse_block(
            _name,
            _kind,
            f"a {_kind} scenario cannot apply it: {_why}; the kinds that apply it: " + ", ".join(BLOCK_KINDS),
        )
