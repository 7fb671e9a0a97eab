"""The declared schema of every scenario kind (`freefloat scenarios`) and of the campaign spec: which keys a file
may have, their types and ranges. `scenario_files.read` checks each file against its kind's schema before the
command reads it, so a typo, a value of the wrong type or out of range is refused with the file, line and key
(see `schema.py`). Each command still checks what only it can (a list's length against the robot, say).

A key that is not declared here is refused: a new key of a scenario kind is declared in its class below, a new
block shared by several kinds with `schema.register_block`."""

from __future__ import annotations

from pydantic import model_validator

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
    integer,
    literal,
    number,
    numbers,
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
    accelerations: literal("exact", "central_difference") = "exact"
    impulses: literal("simpson", "trapezoid") = "simpson"


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
    initial_state: dict | None = None
    reference: dict
    schedule: Anything = None
    weights: dict
    keep_out: dict | None = None
    initial_controls: literal("zero", "gaussian") = "zero"
    gaussian: dict | None = None
    solver: dict | None = None
    mpc: dict | None = None


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


register_kind("postcapture", Postcapture)
register_kind("control_adaptive", ControlAdaptive)
register_kind("identify_cl", IdentifyCl)
register_kind("control_ddp", ControlDdp)
register_kind("campaign", Campaign)
