"""Type stub of freefloat._core, the compiled Rust engine (written by tools/stubgen.py: do not edit)."""

from typing import Any, Callable

import numpy as np
from numpy.typing import ArrayLike

class AdaptivePoseController:
    """Adaptive dual-quaternion pose tracking with concurrent learning (Valverde 2018, ch. 4), to drive from your
own loop: `control(t, q_bd, w_bd)` gives the dual force `f + ετ` (8,), `update(t, dt, q_bd, w_bd, w_bd_dot,
force)` records the sample and advances the estimate by dt; `estimate` is `[I11, I12, I13, I22, I23, I33, m]`.
    """
    def __init__(self, k_r: ArrayLike, k_q: ArrayLike, k_v: ArrayLike, k_w: ArrayLike, k_i: ArrayLike, alpha: float, learning: ArrayLike = 'continuous', n_s: ArrayLike = 50, sigma_stop: ArrayLike = Ellipsis, selection: ArrayLike = 'elementwise', seed: ArrayLike = 0, law_form: ArrayLike = 'corrected', estimate0: ArrayLike | None = None, reference_angular: ArrayLike | None = None, reference_linear: ArrayLike | None = None, reference_times: ArrayLike | None = None, reference_twists: ArrayLike | None = None) -> None: ...
    @property
    def cl_matrix(self) -> Any:
        """The CL matrix (7, 7): P (continuous) or Σ R_kᵀR_k (discrete)."""
    @property
    def cl_vector(self) -> Any:
        """The CL vector (7,): Q (continuous) or Σ R_kᵀf_k (discrete)."""
    def control(self, t: ArrayLike, q_bd: ArrayLike, w_bd: ArrayLike, w_di: ArrayLike | None = None, wdot_di: ArrayLike | None = None) -> Any:
        """The dual control force `f_c^B = f + ετ` (8,) at the pose error `q_bd` (unit) and twist `w_bd`."""
    @property
    def estimate(self) -> Any:
        """The present estimate `[I11, I12, I13, I22, I23, I33, m]`."""
    def estimate_rate(self, t: ArrayLike, q_bd: ArrayLike, w_bd: ArrayLike, w_di: ArrayLike | None = None, wdot_di: ArrayLike | None = None) -> Any:
        """`d v(M̂)/dt` (7,) of the update law at this state with the present memory."""
    def realisability(self) -> Any:
        """Whether the present estimate is a realisable rigid body (see `inertia_realisability`)."""
    def reference(self, t: ArrayLike) -> Any:
        """The desired frame's twist and its rate at t, `(w_di, wdot_di)`, each (8,) in D axes."""
    @property
    def singular_values(self) -> Any:
        """Singular values of the CL matrix (P or Σ R_kᵀR_k), descending."""
    @property
    def stack_len(self) -> Any:
        """Samples in the stack (discrete CL) or None (continuous CL)."""
    def update(self, t: ArrayLike, dt: float, q_bd: ArrayLike, w_bd: ArrayLike, w_bd_dot: ArrayLike | None = None, force: ArrayLike | None = None, w_di: ArrayLike | None = None, wdot_di: ArrayLike | None = None) -> Any:
        """One sample period: when `w_bd_dot` (measured ω̇^B_{B/D}) and `force` (the applied dual force) are given,
record the sample (continuous CL: P += dt RᵀR, Q += dt Rᵀf; discrete CL: offer it to the stack), then
advance the estimate by dt (forward Euler). Returns the new estimate (7,).
        """

COMPILED_CPU_FEATURES: list

class ConcurrentEstimator:
    """The concurrent-learning estimator of Valverde 2018 ch. 9 for `nbodies` bodies, driven from the caller's own
loop: `add_sample(R, F)` offers a data point (Algorithm 3 while the time is below t_th), `step(dt)` advances
the estimate by one RK4 step of (9.15), or of (9.23) with the SVD gain once the time reaches t_th2.
`m0` is the initial estimate (7 per body: [I11, I12, I13, I22, I23, I33, m]); `gain`, `kappa` as in `cl_run`.
    """
    def __init__(self, nbodies: ArrayLike, m0: ArrayLike, ns: ArrayLike = 10, sigma_th: ArrayLike = 0.001, t_th: ArrayLike = 5.0, aggressive: ArrayLike = True, t_th2: ArrayLike = 4.9, sigma_th2: ArrayLike = 0.5, sigma_new: ArrayLike = 100.0, gain: ArrayLike = 'thesis', kappa: ArrayLike = 6.0, seed: ArrayLike = 1) -> None: ...
    def add_sample(self, r: ArrayLike, f: ArrayLike) -> Any:
        """Offer the data point (R, F): R as (B, 8, 7) per-body blocks or the (8B, 7B) block-diagonal matrix 𝐑 of
(9.9), F as (B, 8) or (8B,). Returns what Algorithm 3 did: "appended", "replaced", "rejected", "full"
(the stack is good enough: σ_min ≥ σ_th), or "ignored" (time ≥ t_th).
        """
    @property
    def block_singular_values(self) -> Any:
        """Per body, its block's 7 singular values (descending), shape (B, 7)."""
    @property
    def estimate(self) -> Any:
        """The current estimate, 7 per body."""
    @property
    def gain(self) -> Any:
        """The gain K per body, shape (B, 7, 7) (identity until t_th2)."""
    @property
    def gain_active(self) -> Any:
        """Whether the SVD gain K is in use (time ≥ t_th2 at the last step, aggressive mode)."""
    @property
    def gain_withheld(self) -> Any:
        """Per body, the directions the truncated gain withheld (left at the plain law's rate although the thesis'
(9.27) would accelerate them) when the gain was last formed; zeros with gain="thesis".
        """
    @property
    def nbodies(self) -> int:
        """Number of bodies."""
    @property
    def noise_sigma(self) -> Any:
        """Per body, the noise estimate σ̂ = ρ/√(n − r) of the stored data (least-squares residual norm ρ over the
n stored rows that are not identically zero, r the block's rank); infinite without redundancy.
        """
    @property
    def rf(self) -> Any:
        """Rf = Σ𝐑_kᵀ𝐅_k per body, shape (B, 7)."""
    @property
    def rr(self) -> Any:
        """RR = Σ𝐑_kᵀ𝐑_k as its diagonal blocks, shape (B, 7, 7)."""
    @property
    def singular_values(self) -> Any:
        """The 7B singular values of ΣRᵀR, descending (the union of the per-body blocks' ones)."""
    @property
    def stack_size(self) -> Any:
        """Number of stored data points N_c."""
    def step(self, dt: float) -> Any:
        """Advance by one RK4 step of length dt (RR, Rf and the gain held over the step)."""
    @property
    def time(self) -> Any:
        """Current time (advanced by `step`; settable)."""

class DdpMpc:
    """Receding-horizon DDP (model-predictive control) over a task: the problem description of `ddp_solve`
(model, dt, task horizon N, running/terminal costs, keep_out; scheduled weights frozen at their End column).
`control(k, x)` re-solves the window of `mpc_horizon` nodes starting at task node k from the measured state
every `replan` nodes (warm-started by the previous window shifted in time; the first window by
`guess_xs`/`guess_us` over the whole task if given, else zero controls), and in between applies that
window's feedback policy. `options` as in `ddp_solve` (per re-plan; `max_iter` is the re-plan budget);
`first_max_iter` bounds the first solve. `shrink`: no window reaches past the task's last node (the
terminal cost lands on the task's end, a deadline); off, every window has `mpc_horizon` nodes. `stats()`: re-plans, iterations, solve time, slowest re-plan,
troubled re-plans, last stop reason, the cost, wall time and iterations of each re-plan (`replan_costs`,
`replan_times_s`, `replan_iterations`; the first re-plan included). `rate_joints` as in `ddp_solve`.
    """
    def __init__(self, model: Model, dt: float, horizon: ArrayLike, running: ArrayLike, terminal: ArrayLike, mpc_horizon: ArrayLike, replan: ArrayLike, keep_out: ArrayLike | None = None, options: ArrayLike | None = None, first_max_iter: ArrayLike = 50, guess_xs: ArrayLike | None = None, guess_us: ArrayLike | None = None, shrink: ArrayLike = False, rate_joints: ArrayLike | None = None) -> None: ...
    def control(self, k: ArrayLike, x: Any) -> Any:
        """Control (nv,) at task node k for the measured state x = [q; v] (re-plans when due; Ctrl-C is checked
between re-plans by the caller's loop).
        """
    def set_parameters(self, params: ArrayLike) -> Any:
        """Replace the model's inertial parameters P (nbodies, 10), as `Model.parameters()` of the model the
controller was built on: the next re-plan optimises on them (until then the current window's policy
runs). For a controller that follows an online estimate of the plant.
        """
    def stats(self) -> Any:
        """What the controller did so far (dict)."""

class DdpPolicy:
    """The feedback policy of a DDP solution (Valverde 2018, eq. (8.45) with α = 1 on the measured state):
`control(k, x)` = `us[k] + gains[k] (x ⊖ xs[k])`, the state error in the tangent space (base twist, joint
angles, velocities), as the backward pass linearised it; `feedback=False` gives the open-loop `us[k]`.
Nodes past the end use the last one. `xs` (N + 1, nq + nv), `us` (N, nv), `gains` (N, nv, 2 nv).
    """
    def __init__(self, model: Model, xs: ArrayLike, us: ArrayLike, gains: ArrayLike) -> None: ...
    def control(self, k: ArrayLike, x: Any, feedback: ArrayLike = True) -> Any:
        """Control (nv,) at node k for the measured state x = [q; v]."""

class DualQuaternion:
    """A dual quaternion `r + ε d`; poses are unit (`q q* = 1`), twists `ω + εv`, wrenches `f + ετ`."""
    def __init__(self, coeffs: ArrayLike) -> None: ...
    def circle(self, other: DualQuaternion) -> float:
        """Circle product (Table 2.4), the real number `a∘b`."""
    def conj(self) -> DualQuaternion:
        ...
    def cross(self, other: DualQuaternion) -> DualQuaternion:
        ...
    def dot(self, other: DualQuaternion) -> DualQuaternion:
        ...
    @property
    def dual(self) -> Any:
        """Dual part `(w, x, y, z)`."""
    def inverse(self) -> DualQuaternion:
        """General inverse; raises InputError when the real part is zero."""
    def is_unit(self) -> bool:
        ...
    def left_matrix(self) -> np.ndarray:
        """8×8 left product matrix (2.28): `q.left_matrix() @ b == (q * b)`."""
    def log(self) -> DualQuaternion:
        """Principal logarithm of a unit dual quaternion."""
    def norm(self) -> Any:
        ...
    def normalized(self) -> DualQuaternion:
        """Normalisation (2.30)."""
    def properized(self) -> DualQuaternion:
        """Properisation (2.31)."""
    @property
    def real(self) -> Any:
        """Real part `(w, x, y, z)`."""
    def right_matrix(self) -> np.ndarray:
        """8×8 right product matrix (2.28): `b.right_matrix() @ a == (a * b)`."""
    def rotation_matrix(self) -> np.ndarray:
        """3×3 rotation matrix `C(q_r)` (active: `C v = vec(q v q*)`)."""
    def sc(self) -> Any:
        ...
    def screw(self) -> Any:
        """Screw parameters `(theta, d, l, m)` of a unit dual quaternion."""
    def shift_in(self, x: Any) -> Any:
        """`q* x q` (2.41)/(2.43): a wrench or twist in this pose's reference frame, seen in its own frame."""
    def shift_out(self, x: Any) -> Any:
        """`q x q*` (2.42)/(2.44)."""
    def swap(self) -> DualQuaternion:
        ...
    def to_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Pose in the engine convention: `(quat_xyzw, t)`. Raises InputError if not unit (`q q* = 1`)."""
    def tolist(self) -> list[float]:
        """The 8 coefficients as a list (`numpy.asarray(q)` also works)."""
    def translation(self) -> np.ndarray:
        """`r^A = 2 q_d q_r*` (position of the frame in the reference frame)."""
    def unit_defect(self) -> float:
        """`max |q q* − 1|`."""
    def vec(self) -> Any:
        ...

class Environment:
    """The orbital environment of a simulation; every effect is off unless asked for.

Orbit (of the system's centre of mass at t = 0, about a central body; the Earth by default): give either
`altitude` or `semi_major_axis` (m) with `eccentricity`, `inclination`, `raan`, `arg_periapsis` and
`true_anomaly` (radians), or an inertial `position` and `velocity` (m, m/s, from the body's centre).
`mu` (m³/s²), `radius` (m) and `j2_coefficient` override the Earth's constants. With an orbit the
simulator's world frame is a free-falling frame with inertial axes whose origin follows the orbit
(starting at the system's centre of mass), so `q` keeps metre-sized positions.

`gravity_gradient=True` applies the tidal force and gravity-gradient torque to every body; `j2=True` adds
J2 to the orbit and its differential part to every body. A constant disturbance wrench
(`disturbance_force`, `disturbance_torque`, N and N·m about the centre of mass of body
`disturbance_body`, the base by default) is given in `disturbance_axes` "inertial" or "body".
    """
    def __init__(self, altitude: ArrayLike | None = None, semi_major_axis: ArrayLike | None = None, eccentricity: ArrayLike = 0.0, inclination: ArrayLike = 0.0, raan: ArrayLike = 0.0, arg_periapsis: ArrayLike = 0.0, true_anomaly: ArrayLike = 0.0, position: ArrayLike | None = None, velocity: ArrayLike | None = None, mu: ArrayLike | None = None, radius: ArrayLike | None = None, j2_coefficient: ArrayLike | None = None, gravity_gradient: ArrayLike = False, j2: ArrayLike = False, disturbance_force: ArrayLike | None = None, disturbance_torque: ArrayLike | None = None, disturbance_axes: ArrayLike = 'inertial', disturbance_body: ArrayLike = 0) -> None: ...
    def external_wrenches(self, model: Model, q0: ArrayLike, v0: ArrayLike, times: ArrayLike, q: ArrayLike) -> Any:
        """Total external wrench `[force, moment about the frame origin]` (T, 6), inertial axes, that the
environment applies at the samples (times[k], q[k]) of a run that started at (q0, v0).
        """
    @property
    def gravity_gradient(self) -> Any:
        """Whether the tidal force and gravity-gradient torque act on every body."""
    @property
    def is_off(self) -> Any:
        """True when nothing acts (the simulation is then exactly the environment-free one)."""
    @property
    def j2(self) -> Any:
        """Whether J2 acts."""
    @property
    def mu(self) -> Any:
        """Gravitational parameter μ of the central body (m³/s²), or None without an orbit."""
    @property
    def orbit_state(self) -> Any:
        """The system's centre-of-mass orbit at t = 0 as (position, velocity) (inertial, m and m/s), or None."""
    @property
    def period(self) -> Any:
        """Orbital period of the t = 0 state (s), or None without an orbit."""
    def reference_orbit(self, model: Model, q0: ArrayLike, v0: ArrayLike, times: ArrayLike) -> Any:
        """Inertial state `[position, velocity]` (T, 6) of the simulation frame's origin at `times` for a run
from (q0, v0): add a body's local position to get its inertial one. The same propagation as the run.
        """

class InputError(ValueError):
    """An argument has the wrong shape, non-finite entries or an invalid value."""

class Interrupted(KeyboardInterrupt):
    """A long run was stopped (Ctrl-C, or a progress callback returning False); `partial` holds what was finished (a Trajectory for a simulation), or None."""

class Model:
    ...
    @property
    def body_names(self) -> list[str]:
        ...
    @staticmethod
    def builtin(name: str) -> Model:
        ...
    @staticmethod
    def builtin_names() -> list[str]:
        ...
    @staticmethod
    def builtin_source(name: str) -> str:
        ...
    @property
    def frame_names(self) -> list[str]:
        ...
    @property
    def frames(self) -> Any:
        """Frames as a list of (name, body name, position (3,), quaternion xyzw (4,))."""
    @staticmethod
    def from_urdf_string(text: str, base: str = 'free', source: str = '<string>', allow_nonphysical: bool = False) -> Model:
        """Parse URDF text. `source` names it in error messages."""
    @staticmethod
    def from_yaml_string(text: str, source: str = '<string>') -> Model:
        """Parse the YAML model format (docs/model_format.md)."""
    @property
    def gravity(self) -> Any:
        ...
    @property
    def idx_q(self) -> Any:
        ...
    @property
    def idx_v(self) -> Any:
        ...
    @property
    def joint_axes(self) -> Any:
        """Unit joint axes (nbodies, 3), joint frame."""
    @property
    def joint_axes2(self) -> Any:
        """Second axes of universal joints (nbodies, 3; intermediate frame); z for every other joint."""
    @property
    def joint_names(self) -> list[str]:
        ...
    @property
    def joint_types(self) -> list[str]:
        ...
    def leading_bodies(self, n: ArrayLike) -> Any:
        """A new Model of the first `n` bodies (the last ones, and the frames on them, dropped): the dynamics of the
rest when the dropped tail is massless (the rate-driven wrist of the chapter 8 DDP robot).
        """
    @property
    def limits(self) -> Any:
        """Joint limits as a dict of arrays (lower, upper, velocity, effort), NaN where not given."""
    @property
    def name(self) -> str:
        ...
    @property
    def nbodies(self) -> int:
        ...
    def neutral(self) -> np.ndarray:
        ...
    @property
    def nq(self) -> int:
        ...
    @property
    def nqs(self) -> Any:
        ...
    @property
    def nv(self) -> int:
        ...
    @property
    def nvs(self) -> Any:
        ...
    def parameters(self) -> np.ndarray:
        """Standard inertial parameters, (nbodies, 10): [m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]
about each body-frame origin, body axes.
        """
    @property
    def parents(self) -> Any:
        """Parent body index of each body (-1 for the base)."""
    @property
    def placements(self) -> Any:
        """Rest placement of each joint frame in its parent body, as (nbodies, 4, 4) homogeneous matrices."""
    @property
    def tags(self) -> Any:
        ...
    def to_mjcf_string(self, with_gravity: ArrayLike = False) -> Any:
        """The model as MJCF (MuJoCo XML): free joint on the base, inertias at full precision, no fusing
of static bodies, zero gravity unless `with_gravity`.
        """
    def to_urdf_string(self) -> str:
        ...
    @property
    def total_mass(self) -> float:
        ...
    def with_fixed_leaves_merged(self) -> Any:
        """A new Model with every welded (fixed-joint) leaf merged into its parent, a frame of the leaf's name left
in its place: the same dynamics with fewer bodies.
        """
    def with_gravity(self, g: ArrayLike) -> Model:
        ...
    def with_parameters(self, params: ArrayLike) -> Model:
        """A new Model with other standard parameters (nbodies, 10); checked for physical consistency."""

class ModelError(ValueError):
    """A model file or model description is malformed or non-physical."""

class ModifiedRLS:
    """The modified RLS of Zhang, Yue, Yuan 2020 (Rust `estimation::ModifiedRls`), coupling "spatial" or "planar"."""
    def __init__(self, coupling: str, mu0: ArrayLike, p_mu0: ArrayLike, theta0: ArrayLike, p_theta0: ArrayLike) -> None: ...
    @property
    def mu(self) -> Any:
        ...
    def run(self, t: ArrayLike, a: ArrayLike, b: ArrayLike, phi: ArrayLike, y: ArrayLike, psi: ArrayLike) -> Any:
        """Many samples (leading axis N). Returns (mu history (N, nμ), theta history (N, nθ))."""
    @property
    def samples(self) -> Any:
        ...
    @property
    def theta(self) -> Any:
        ...
    def update(self, t: ArrayLike, a: ArrayLike, b: ArrayLike, phi: ArrayLike, y: ArrayLike, psi: ArrayLike) -> Any:
        """One sample: a (rμ, nμ), b (rμ,), phi (rθ, nθ), y (rθ,), psi (rθ, nD)."""

class NumericalError(ArithmeticError):
    """The numbers defeat the algorithm (singular matrix, diverging step...)."""

class RecursiveLS:
    """Ordinary recursive least squares with forgetting factor (Rust `estimation::Rls`)."""
    def __init__(self, theta0: ArrayLike, p0: ArrayLike, forgetting: float = 1.0) -> None: ...
    @property
    def covariance(self) -> Any:
        ...
    @property
    def estimate(self) -> Any:
        ...
    def run(self, t: ArrayLike, phi: ArrayLike, y: ArrayLike) -> Any:
        """Many samples: t (N,), phi (N, r, n), y (N, r). Returns the estimate after each sample (N, n)."""
    @property
    def samples(self) -> Any:
        ...
    def update(self, t: ArrayLike, phi: ArrayLike, y: ArrayLike) -> Any:
        """One sample: phi (r, n), y (r,)."""

def _time_kernel(model: Model, kernel: ArrayLike, q: ArrayLike, v: ArrayLike, tau: ArrayLike, calls: ArrayLike) -> Any:
    """`calls` calls of `kernel` ("aba", "rnea" or "crba") cycling through the rows of q, v, tau (tau is the
acceleration for rnea; v and tau are ignored by crba), each through the checked public function as a user calls
it. Returns (wall seconds of the loop, this thread's CPU seconds over the same loop, a checksum of the outputs
that keeps the loop from being optimised away). Both clocks are read around the loop alone, as the C++ peer
reads its own: the argument copies before it (page faults of a fresh 7 MB batch) are not the kernel's time.
    """

def aba(model: Model, q: ArrayLike, v: ArrayLike, tau: ArrayLike, fext: ArrayLike | None = None) -> np.ndarray:
    """Forward dynamics (articulated-body algorithm): accelerations for generalized forces `tau`."""

def aba_derivatives(model: Model, q: ArrayLike, v: ArrayLike, tau: ArrayLike, fext: ArrayLike | None = None) -> Any:
    """Derivatives of forward dynamics a = FD(q, v, tau, fext): (da_dq, da_dv, da_dtau), each (nv, nv).
Derivatives with respect to q are taken along the local tangent of q (nv columns): for a free base,
a base-frame displacement and a base-frame rotation vector, the axes of the base twist in v
(Pinocchio's convention, so they compare with pin.computeABADerivatives). da_dtau = M⁻¹.
    """

def actuator_fields() -> Any:
    """`actuator_fields()`: `{"actuators": [keys], "limits"/"wheels"/"thrusters"/"tanks": {"keys": [...],
"defaults": {...}}}`: the keys `parse_actuators` accepts and, for wheels, the engine's defaults
(`Wheel::new`; `None`: no limit). The one source the Python classes and the scenario schema read.
    """

def adaptive_simulate(truth: ArrayLike, q0: ArrayLike, w0: ArrayLike, estimate0: ArrayLike, k_r: ArrayLike, k_q: ArrayLike, k_v: ArrayLike, k_w: ArrayLike, k_i: ArrayLike, alpha: float, t_final: float, learning: ArrayLike = 'continuous', n_s: ArrayLike = 50, sigma_stop: ArrayLike = Ellipsis, selection: ArrayLike = 'elementwise', seed: ArrayLike = 0, law_form: ArrayLike = 'corrected', reference_angular: ArrayLike | None = None, reference_linear: ArrayLike | None = None, reference_times: ArrayLike | None = None, reference_twists: ArrayLike | None = None, method: str = 'dopri5', dt: float = 0.01, rtol: float = 1e-10, atol: float = 1e-10, max_step: float | None = Ellipsis, output_dt: ArrayLike = 0.01, max_steps: int = 50000000, rank_tol: ArrayLike = 1e-08, alpha_off_after: ArrayLike | None = None, progress: Callable[[float], Any] | None = None) -> Any:
    """Simulate the closed loop of Valverde 2018 ch. 4 (relative pose-error dynamics (2.58) of a spacecraft with
mass properties `truth`, adaptive law (4.9) corrected, update law (4.13) or (4.29)) in the engine, and
return the recorded histories: `t`, `q`, `w`, `estimate`, `force`, `singular_values`, `lyapunov`,
`position_error`, `attitude_error`, `stack_len`, `alpha_in_effect` (the CL weight in effect over the step from each
recorded time), plus `steps`, `rejected`, `evaluations`, `rank7_time`, `alpha_off_time`, `stack_changes`,
`left_admissible_at`, `admissible_since`, `interrupted`. `alpha_off_after` (seconds, ≥ 0; None = never):
Valverde 2018 Remark 6, α is set to 0 that long after the CL matrix first has rank 7 (σ_min > `rank_tol`). `progress(t)` is called with the
simulated time every 200 steps; returning False (or Ctrl-C) stops the run and keeps what was done.
    """

def base_twist_for_momentum(model: Model, q: ArrayLike, joint_rates: ArrayLike, momentum: ArrayLike | None = None) -> Any:
    """Base velocity (…, nb) — a free base's twist [v; ω] in the base frame, a planar base's [vx, vy, yaw
rate] — that gives the total momentum `momentum` (6: [p; L about the inertial origin], inertial frame;
default zero) when the other joints move with `joint_rates` (…, nv − nb) at `q` (…, nq).
    """

def body_accelerations(model: Model, q: ArrayLike, v: ArrayLike, a: ArrayLike, classical: bool = False) -> np.ndarray:
    """Body accelerations (nbodies, 6) in body frames: spatial (d/dt of the body-frame twist
components, Pinocchio LOCAL) or, with `classical`, the acceleration of each body origin.
Gravity is not included.
    """

def body_velocities(model: Model, q: ArrayLike, v: ArrayLike) -> np.ndarray:
    """Body twists (nbodies, 6) [linear; angular], each in its own body frame (Pinocchio LOCAL)."""

def capture_impact(model: Model, target: ArrayLike, q: ArrayLike, v: ArrayLike, target_twist: ArrayLike) -> Any:
    """The grasp of a drifting target as an inelastic impact (`postcapture::capture_impact`): `model` is the combined
model whose leaf body `target` (a fixed joint) is the target, `q` the configuration at contact, `v` the
servicer's velocity just before, `target_twist` the target's twist just before (its own axes, [v; ω]).
Returns a dict: v_post (nv), impulse_local / impulse_world (6, [linear; angular], about the target frame origin),
momentum_before / momentum_after (6, inertial, about the origin), energy_before / energy_after.
    """

def center_of_mass(model: Model, q: ArrayLike) -> np.ndarray:
    ...

def centroidal_momentum_matrix(model: Model, q: ArrayLike) -> np.ndarray:
    """Centroidal momentum matrix about the inertial origin (6, nv): momentum == A @ v."""

def check_sensors(sensors: ArrayLike) -> Any:
    """Check a sensor set (YAML or JSON text) without running it; returns the sensors' names in order."""

def cl_estimate(r: ArrayLike, f: ArrayLike, dt: float, m0: ArrayLike, ns: ArrayLike = 10, sigma_th: ArrayLike = 0.001, t_th: ArrayLike = 5.0, aggressive: ArrayLike = True, t_th2: ArrayLike = 4.9, sigma_th2: ArrayLike = 0.5, sigma_new: ArrayLike = 100.0, gain: ArrayLike = 'thesis', kappa: ArrayLike = 6.0, seed: ArrayLike = 1) -> Any:
    """The ch. 9 estimator alone over recorded data points: R (n, B, 8, 7), F (n, B, 8) taken every `dt` from
t = 0; the same sequence as `cl_run` (offer, record, step) without the robot (`gain`, `kappa` as there).
Returns the estimates (n, 7B).
Ctrl-C stops it within ~20 ms: `Interrupted.partial` holds the estimates finished, (k, 7B), equal to the
first k rows of an uninterrupted call.
    """

def cl_run(model: Model, q0: ArrayLike, v0: ArrayLike, m0: ArrayLike, ns: ArrayLike = 10, sigma_th: ArrayLike = 0.001, t_th: ArrayLike = 5.0, aggressive: ArrayLike = True, t_th2: ArrayLike = 4.9, sigma_th2: ArrayLike = 0.5, sigma_new: ArrayLike = 100.0, gain: ArrayLike = 'thesis', kappa: ArrayLike = 6.0, seed: ArrayLike = 1, dt: float = 0.01, t_final: float = 10.0, amplitude: ArrayLike = 0.5, frequency: ArrayLike = 1.0, phase: ArrayLike = 0.0, t_start: ArrayLike = 2.0, t_end: ArrayLike = 3.0, wrench_noise: ArrayLike = 0.0, rate_noise: ArrayLike = 0.0, noise_seed: ArrayLike = 7, progress: Callable[[float], Any] | None = None) -> Any:
    """Run Valverde 2018 ch. 9 on `model` (free base, no gravity) from (q0, v0): the robot under the joint
actuation `amplitude·sin(frequency·t + phase)` on every joint DOF for t_start ≤ t ≤ t_end, integrated with
RK4 at `dt` to `t_final`, and the concurrent-learning estimator (Algorithms 3-4, law (9.15), SVD gain
(9.22-9.27)) fed one data point per step. `m0`: initial estimate, 7 per body ([I11, I12, I13, I22, I23, I33,
m], model order). `gain`: "thesis" (9.27, the default) or "truncated" (a direction is accelerated only when
the current estimate's residual along it is at least `kappa` times the stored data's noise estimate).
`wrench_noise`, `rate_noise`: standard deviations of the joint force/torque sensors and of the measured body
twists and twist rates. `progress(t)` is called with the simulated time; returning False
(or Ctrl-C) stops the run, which then returns what it has with `interrupted = True`. Returns a dict of numpy
arrays: t, estimates (n, 7B), singular_values (n, 7B, descending), block_singular_values (n, B, 7), offers
(n,), truth, final_estimate, realisable (B,), max_residual, noise_sigma (B,), gain_withheld (B,),
stack_changes, stack_trials, interrupted.
    """

def cl_sample(model: Model, q: ArrayLike, v: ArrayLike, tau: ArrayLike, wrench_noise: ArrayLike = 0.0, rate_noise: ArrayLike = 0.0, noise_seed: ArrayLike = 7) -> Any:
    """One data point of ch. 9 from a multibody state: the dual-quaternion dynamics at (q, v, tau) give every
body's CoM twist and twist rate and every joint's transmitted wrench; returns (R, F, twists, rates) with
R (B, 8, 7) the per-body regressors R̂ (9.7), F (B, 8) the wrenches on the bodies about their CoMs (from the
joint wrenches, not from the mass properties), twists and rates (B, 8) as dual quaternions (ω + ε v).
`wrench_noise`, `rate_noise` as in `cl_run`, drawn with `noise_seed`.
    """

def crba(model: Model, q: ArrayLike) -> np.ndarray:
    """Joint-space inertia matrix (nv, nv), full symmetric."""

def ddp_frame_dual_quats(model: Model, qs: ArrayLike, frame_name: ArrayLike) -> Any:
    """The frame's pose as a dual quaternion (thesis layout), composed along the chain so that it is continuous
along a trajectory (never properised), for each row of `qs` (M, nq). Returns (M, 8).
    """

def ddp_screw_reference(start: ArrayLike, axis: ArrayLike, moment: ArrayLike, angle: ArrayLike, advance: ArrayLike, t_hold: ArrayLike, t_move: ArrayLike, dt: float, n: ArrayLike) -> Any:
    """Three-phase screw reference (Valverde 2018, §8.7): hold `start` (8, thesis layout [real w x y z, dual
w x y z]) for `t_hold`, then `start · exp(½ θ̂ ŝ)` with `ŝ = axis + ε moment` (start-frame coordinates),
`θ = angle·τ/t_move`, `d = advance·τ/t_move` for `t_move` seconds, then hold; sampled at k·dt,
k = 0..=n. Returns (n + 1, 8); never properised.
    """

def ddp_solve(model: Model, x0: ArrayLike, dt: float, horizon: ArrayLike, running: ArrayLike, terminal: ArrayLike, us0: ArrayLike, keep_out: ArrayLike | None = None, xs0: ArrayLike | None = None, options: ArrayLike | None = None, callback: ArrayLike | None = None, rate_joints: ArrayLike | None = None) -> Any:
    """Solve a floating-robot optimal-control problem by DDP (Valverde 2018, ch. 8).

State `x = [q; v]` (nq + nv), control `u = τ` (nv: base force and torque in the base frame, then joint
torques), semi-implicit Euler steps of `dt` over `horizon` nodes. `running` / `terminal`: lists of cost
dicts with keys `name`, `kind` ('frame_placement' with `frame` and `reference` (M, 7) [p, quat xyzw];
'frame_dq' with `frame`, `reference` (M, 8) thesis-layout dual quaternions and optional `sign` ('literal',
the thesis' q_G − q_D, or 'nearest': q_G − s q_D with s the sign of q_G,r · q_D,r); 'state' with optional
`reference` (M, nx); 'control' with optional `reference` (M, nu)), and `weights` (one per residual
entry) or `weights_start`/`weights_medium`/`weights_end` + `breakpoints` [i1, i2, i3, i4] (Table 8.2
schedule). M is 1 or one per node. Cost = Σ w r² (no ½, no Δt). `keep_out`: dicts with `joint`,
`center`, `width`, `height` (rad). `us0`: (horizon, nu); `xs0`: optional (horizon + 1, nx) initial
states (feasibility-driven variant). `options`: variant ('ddp'/'fddp'), second_order, max_iter, alphas,
best_alpha, accept_ratio, reg_init, reg_min, reg_max, reg_factor, tol_expected, tol_cost.
`callback(info: dict)` is called after every iteration; returning False stops (so does Ctrl-C), keeping
the best iterate. Returns a dict: xs, us, gains (horizon, nu, ndx), cost, initial_cost, iterations, stop,
stop_message, history (list of dicts), gap, timings (seconds and calls of the derivative, backward-pass
and rollout blocks). Option `refresh_gains` (default False): recompute the gains at the returned iterate
(one more derivative evaluation and backward pass), as closed-loop use of the policy needs.
`rate_joints`: names of the model's last joints to drive by their rates (a massless tail, the thesis' wrist of
eq. (8.51)): their bodies' inertia is ignored and their controls are joint rates, not torques.
    """

def difference(model: Model, q0: ArrayLike, q1: ArrayLike) -> Any:
    """q1 ⊖ q0 (nv): the tangent displacement dq with integrate(q0, dq) == q1."""

def difference_jacobians(model: Model, q0: ArrayLike, q1: ArrayLike) -> Any:
    """Jacobians of difference(q0, q1), local tangents: (d/dq0, d/dq1), each (nv, nv)."""

def dq_approach_slope(q_ga: ArrayLike, z_a: ArrayLike, half_angle: float) -> Any:
    ...

def dq_attitude(q_bi: ArrayLike, n_i: ArrayLike, n_b: ArrayLike, max_angle: float) -> Any:
    ...

def dq_body_poses(model: Model, q: ArrayLike, method: str = 'chain') -> Any:
    """Body poses of a model as dual quaternions, (nbodies, 8): `method` "chain" (the product of relative poses
(3.43)) or "poe" (product of exponentials (3.19)).
    """

def dq_body_regressor(twist: ArrayLike, twist_dot: ArrayLike) -> Any:
    """`R̂(ω̇, ω)` (8×7), eq. (9.7)."""

def dq_condition_number(model: Model, q: ArrayLike) -> Any:
    """2-norm condition number of Valverde 2018's system matrix S (6.17) at each configuration (one q or (T, nq))."""

def dq_dh(d: float, theta: float, a: ArrayLike, alpha: float) -> Any:
    """Standard DH transform (3.26); with `rows` (n × 4 of d, θ, a, α) the chain product."""

def dq_dh_chain(rows: ArrayLike) -> Any:
    ...

def dq_distance_bound(q: ArrayLike, delta: float) -> Any:
    ...

def dq_dynamics(model: Model, q: ArrayLike, v: ArrayLike, tau: ArrayLike, fext: ArrayLike | None = None, locked: ArrayLike | None = None, formulation: str = 'dq') -> tuple[np.ndarray, np.ndarray]:
    """Returns `(ddq, W)`: accelerations (nv) and, per joint, the wrench it transmits onto its child body
(nbodies × 6, [force; torque about the child body origin], child body axes; row 0 is the base joint).
Joints named in `locked` are held at zero acceleration and their `tau` entries are ignored.
`formulation`: "dq" (chapter 6, default) or "decoupled" (chapter 5's vector formulation, no locking).
    """

def dq_exp(x: Any) -> Any:
    """`exp(x)` of a vector dual quaternion."""

def dq_from_pose(quat_xyzw: ArrayLike, t: ArrayLike) -> Any:
    """Pose from the engine convention: unit quaternion `(x, y, z, w)` (normalised if within 1e-6 of unit,
rejected otherwise, as everywhere in freefloat) and translation `t`.
    """

def dq_h_vector(a: ArrayLike, b: ArrayLike) -> Any:
    """`h(a, b)` (7,), §4.2: `a ∘ (M ⋆ b) = h(a, b) @ v(M)`."""

def dq_inertia_params(mass: ArrayLike, inertia: ArrayLike) -> Any:
    """`v(M) = [I11, I12, I13, I22, I23, I33, m]` of a rigid body (mass, 3×3 inertia about the CoM)."""

def dq_line_of_sight(q_ga: ArrayLike, y_g: ArrayLike, half_angle: float) -> Any:
    """Constraint `(value, gradient)`; `value ≤ 0` is feasible. See `freefloat.dq.line_of_sight`."""

def dq_r_matrix(b: ArrayLike) -> Any:
    """`r(b)` (8×7), eq. (4.2): `r(b) @ v(M) = M ⋆ b` for a vector dual quaternion `b`."""

def dq_relative_regressor(w_bd_dot: ArrayLike, w_bd: ArrayLike, w_di_dot: ArrayLike, w_di: ArrayLike, q_bd: ArrayLike) -> Any:
    """`R(ω̇_B/D, ω_B/D, ω̇_D/I, ω_D/I, q_B/D)` (8×7), eq. (4.3)."""

def dq_screw(theta: float, d: float, l: ArrayLike, m: ArrayLike) -> Any:
    """Screw exponential (3.10) `exp(½(θ + εd)(ℓ + εm))`."""

def dynamics_regressor(model: Model, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> np.ndarray:
    """Inverse-dynamics regressor (nv, 10·nbodies): rnea(q, v, a) == Y @ P.ravel(), gravity included.
Per body Valverde 2018's regressor R (Eqs. 4.3, 9.7), the Newton-Euler counterpart of Naveen, Shah,
Misra's Eq. 10, projected on every joint between the body and the root.
    """

def excitation_objective(model: Model, q0: ArrayLike, iq: ArrayLike, iv: ArrayLike, step: float, q: ArrayLike, qd: ArrayLike, stride: int, offset: int, columns: ArrayLike, weight: float, n_signal: int, threads: int = 2) -> Any:
    """Evaluate Naveen, Shah, Misra's eq. (32) for B joint paths at once (worker threads, GIL released; Ctrl-C
stops them within ~20 ms and raises `Interrupted`, partial None).
q (B, S, n) / qd: driven joints' angles and rates on a grid of `step` seconds; iq, iv: their q and v
indices; q0 (nq,): start configuration (base pose, other joints); rows at grid points offset + k·stride;
columns: minimal-regressor columns (indices into 10·nbodies); n_signal: how many of the driven joints (the
first ones) count in the signal term. Returns a dict of arrays (B,):
objective, condition_number, mean_square, and singular_values (B, len(columns)).
    """

def excitation_rows(model: Model, q0: ArrayLike, iq: ArrayLike, iv: ArrayLike, step: float, q: ArrayLike, qd: ArrayLike, stride: int, offset: int, columns: ArrayLike, n_signal: int) -> Any:
    """Minimal-regressor rows along one joint path: dict with rows (6·points, len(columns)), sumsq, count,
q_end (the configuration at the end, base pose integrated).
    """

def forward_kinematics(model: Model, q: ArrayLike) -> np.ndarray:
    """Placement of every body in the inertial frame: (nbodies, 7) = position, quaternion x y z w."""

def frame_dq_pose_derivatives(model: Model, q: ArrayLike, name: str) -> Any:
    """Dual quaternion of frame `name`'s pose (8: real w x y z, dual w x y z; translation first,
q_r + ε ½ r q_r) and its Jacobian (8, nv) along the local tangent of q. The rotation part has a
non-negative scalar; for the other sign negate both.
    """

def frame_jacobian(model: Model, q: ArrayLike, name: str, reference: str = 'local') -> np.ndarray:
    """Jacobian (6, nv) of a body or frame: its twist [linear; angular] is J @ v."""

def frame_log_error_derivatives(model: Model, q: ArrayLike, name: str, target: ArrayLike) -> Any:
    """Pose error of frame `name` against `target` (7: position, quaternion x y z w; inertial frame):
(e (6,), de_dq (6, nv)) with e = log(T_target⁻¹ T(q)) = [linear; angular] (SE(3) logarithm, the
residual of Crocoddyl's ResidualModelFramePlacement) and de_dq = Jlog(e) J_local(q).
    """

def frame_placement(model: Model, q: ArrayLike, name: str) -> np.ndarray:
    """Placement of a body or frame in the inertial frame: (7,) = position, quaternion x y z w."""

def generalized_jacobian(model: Model, q: ArrayLike, name: str, reference: str = 'world', h0: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Generalized Jacobian of a free-floating robot: with total momentum h0 conserved, the frame's
twist is Jg @ qdot_joints + offset. Returns (Jg (6, nv - nv_base), offset (6,)).
    """

def hybrid_dynamics(model: Model, q: ArrayLike, v: ArrayLike, tau: ArrayLike, ddq: ArrayLike, prescribed: ArrayLike, fext: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Hybrid dynamics: joints in `prescribed` follow accelerations `ddq` (their entries of it), the
rest respond to `tau`. Returns (ddq_all, tau_all), tau_all holding the forces the prescribed
joints needed.
    """

def identify_momentum(model: Model, q: ArrayLike, v: ArrayLike, h: ArrayLike, columns: ArrayLike, known_params: ArrayLike, weights: ArrayLike | None = None, method: str = 'auto') -> Any:
    """Identify the parameters in `columns` (indices into the 10·nbodies standard parameters) from
measured momenta H (T, 6), states Q (T, nq), V (T, nv). `known_params` (10·nbodies,): the known
bodies' momentum K·P over the other columns is subtracted from H. `weights` (6,): inverse
variances of [p; L]. method: "auto" (normal equations + refinement when well conditioned, else
streaming QR) or "qr". Returns a dict: x, std, covariance, rss, dof, condition_number, rank,
rows, method. Raises NumericalError naming the unexcited combinations if rank deficient.
    """

def inertia_com_form(params: ArrayLike) -> Any:
    """`(m, b', I'_c)` from standard parameters (…, 10) about a reference point: masses (…), centres of mass
(…, 3), inertias about the centre of mass (…, 3, 3) (parallel axes; `postcapture::equations::com_form`).
    """

def inertia_project_consistent(params: ArrayLike, eps: ArrayLike = 1e-09) -> Any:
    """Nearest physically consistent standard parameters (…, 10) (pseudo-inertia eigenvalues clipped at
`eps`·max; `postcapture::equations::project_consistent`).
    """

def inertia_realisability(v: ArrayLike) -> Any:
    """Whether `v = [I11, I12, I13, I22, I23, I33, m]` is the mass and inertia of a rigid body: a dict with
`realisable`, `admissible` (m > 0 and Ī > 0, enough for the dual inertia to be invertible), `mass_positive`,
`positive_definite`, `triangle_inequality` (λ_max ≤ sum of the other two principal moments),
`triangle_margin`, `principal_moments` (ascending) and `failures` (the failing conditions in words).
    """

def inertia_standard_form(mass: ArrayLike, com: ArrayLike, inertia: ArrayLike) -> Any:
    """Standard parameters (…, 10) about the reference point from masses (…), centres of mass (…, 3) and
inertias about the centre of mass (…, 3, 3) (`postcapture::equations::standard_form`).
    """

def integrate(model: Model, q: ArrayLike, dq: ArrayLike) -> Any:
    """q ⊕ dq (nq): the configuration reached from q by the tangent displacement dq (nv; for a free base
a base-frame displacement and rotation vector), on R³ × SO(3).
    """

def integrate_base_poses(t: ArrayLike, twists: ArrayLike, pose0: ArrayLike, rates: ArrayLike | None = None) -> Any:
    """Base poses from sampled base twists by the trapezoidal rule on the group (`sim::integrate_base_poses`).
Free base: `twists` (T, 6) = [v; ω] in the base frame, `pose0` (7) = position, quaternion x y z w;
returns (T, 7). Planar base: `twists` (T, 3) = [vx, vy, yaw rate], `pose0` (3) = [x, y, yaw]; returns
(T, 3). `t` (T,) the increasing sample times. `rates` (the twists' shape): their time derivatives, for the
fourth-order (Hermite) correction.
    """

def integrate_jacobians(model: Model, q: ArrayLike, dq: ArrayLike) -> Any:
    """Jacobians of integrate(q, dq), local tangents: (d/dq, d/d(dq)), each (nv, nv)."""

def kinetic_energy(model: Model, q: ArrayLike, v: ArrayLike) -> np.ndarray:
    ...

def matrix_to_quat(rot: ArrayLike) -> Any:
    """Unit quaternions (…, 4), x, y, z, w with w ≥ 0, of rotation matrices (…, 3, 3) (Shepperd's method).
Matrices farther than 1e-6 from a rotation are rejected.
    """

def measure(model: Model, sensors: ArrayLike, t: ArrayLike, q: ArrayLike, v: ArrayLike, ddq: ArrayLike | None = None, seed: ArrayLike = 0) -> Any:
    """Sample a recorded run with a sensor set (`sensors`: YAML or JSON text of a `sensors:` list) from the
random streams of `seed`. t (T,), q (T, nq), v (T, nv), ddq (T, nv) or None. Returns one dict per
sensor: sensor, columns (list of names), t (N,), values (N, len(columns)), white_sigma (per-column
standard deviation of the white part of a rate sensor's errors; empty otherwise), period [s].
    """

def momentum(model: Model, q: ArrayLike, v: ArrayLike) -> np.ndarray:
    """Total momentum [linear; angular about the inertial origin], inertial frame."""

def momentum_regressor(model: Model, q: ArrayLike, v: ArrayLike) -> np.ndarray:
    """Momentum regressor (6, 10·nbodies): momentum(q, v) == K @ P.ravel() with P = m.parameters().
The link kinematic matrix of Naveen, Shah, Misra (Eq. 10) per body, in our parameter order.
    """

def momentum_regressor_stream(model: Model, q: ArrayLike, v: ArrayLike, h: ArrayLike, columns: ArrayLike, known_params: ArrayLike, weights: ArrayLike | None = None) -> Any:
    """For benchmarks: one streaming pass of `identify_momentum` that builds every block of the
regressor and right-hand side and discards it (no solve). Returns the sum of the right-hand
sides. Same arguments as `identify_momentum`.
    """

def postcapture_m_j(mass: ArrayLike, com: ArrayLike) -> Any:
    """`m J(b')` (10) = [m, m b', m mono(b')] (Zhang 2020, eq. (23))."""

def postcapture_momentum_transport(model: Model, t: ArrayLike, q: ArrayLike, v: ArrayLike, at: ArrayLike, point: ArrayLike = 0) -> Any:
    """The transport term `∫ [v_B]× K_lin dτ` of the base-point momentum balance (`postcapture::momentum_point`)
from the dense record `t` (N), `q` (N, nq), `v` (N, nv) at the frame indices `at` (T): an array
(T, 3, 10·nbodies), integrated from `t[at[0]]` (Simpson's rule on an even grid, else trapezoid). B is the
frame origin of body `point`.
    """

def postcapture_rows(model: Model, form: ArrayLike, solver: ArrayLike, t: ArrayLike, q: ArrayLike, v: ArrayLike, ddq: ArrayLike, base_wrench: ArrayLike, impulse_f: ArrayLike, impulse_m: ArrayLike, base: str, target: ArrayLike, transport: ArrayLike | None = None) -> Any:
    """Regression rows of Zhang, Yue, Yuan 2020 over a whole measurement record, computed by the
engine (`postcapture::equations`). `form`: "momentum" (eqs. 11-19; cumulative differences from the first
sample, so one block fewer) or "force" (eqs. 26-33, about the base sensor). `solver`: "paper" (dict with
t, A, b, Phi, y, Psi: `A μ = b`, `Φ θ = y + Ψ D(μ)`) or "standard" (dict with t, Phi, y, standard
parameters about the reference points). Arrays have a leading sample axis. `transport` (T, 3, 10·nbodies,
from `postcapture_momentum_transport`): the momentum rows' angular balance about the moving base point,
`impulse_m` then being ∫ M_B dτ about it.
    """

def postcapture_simulate(model: Model, q0: ArrayLike, v0: ArrayLike, t_final: float, dt: float, f_max: ArrayLike, k_f: ArrayLike, m_max: ArrayLike, k_m: ArrayLike, k_d: ArrayLike, k_p: ArrayLike, jet: ArrayLike, damping: ArrayLike, amp: ArrayLike, freq: ArrayLike, phase: ArrayLike, record_every: int = 1, max_memory: ArrayLike | None = None, actuators: ArrayLike | None = None, environment: ArrayLike | None = None) -> Any:
    """Simulate the post-capture scenario. Returns a dict like `simulate` (t, q, v, ddq, tau, momentum,
kinetic_energy, work) recorded every `record_every` RK4 steps.
    """

def postcapture_thruster_wrench(model: Model, actuators: ArrayLike, t: ArrayLike, propellant: ArrayLike) -> Any:
    """The thrusters' wrench on the base (T × 6, body frame about the base origin, the base entries of the
generalized force) and each tank's propellant flow (T × tanks, kg/s) at the samples `t` of a run with
`propellant` (T × tanks) left: the engine's thruster model, as the stepper evaluates it.
    """

def quat_to_matrix(quat: ArrayLike) -> Any:
    """Rotation matrices (…, 3, 3) (frame → inertial) of quaternions (…, 4) in x, y, z, w order. Norms within
1e-6 of one are normalised, others rejected (ARCHITECTURE.md quaternion policy).
    """

def rnea(model: Model, q: ArrayLike, v: ArrayLike, a: ArrayLike, fext: ArrayLike | None = None) -> np.ndarray:
    """Inverse dynamics: generalized forces for accelerations `a`."""

def rnea_derivatives(model: Model, q: ArrayLike, v: ArrayLike, a: ArrayLike, fext: ArrayLike | None = None) -> Any:
    """Derivatives of inverse dynamics tau = RNEA(q, v, a, fext): (dtau_dq, dtau_dv, dtau_da = M), each
(nv, nv); q along its local tangent (see aba_derivatives).
    """

def simulate(model: Model, q0: ArrayLike, v0: ArrayLike, t_final: float, dt: float, method: str = 'rk4', rtol: float = 1e-09, atol: float = 1e-12, max_step: float | None = None, record_every: int = 1, torques: ArrayLike | Callable[..., ArrayLike] | None = None, torque_times: ArrayLike | None = None, hold: str = 'zoh', controller: Callable[..., ArrayLike] | None = None, controller_period: float | None = None, prescribed: ArrayLike | None = None, prescription: Callable[..., Any] | None = None, max_steps: int = 50000000, progress: Callable[[float], Any] | None = None, formulation: str = 'aba', actuators: ArrayLike | None = None, input_timing: ArrayLike = 'step', max_memory: ArrayLike | None = None, environment: ArrayLike | None = None) -> Any:
    ...

def simulate_many(model: Model, q0: ArrayLike, v0: ArrayLike, t_final: float, dt: float, method: str = 'rk4', rtol: float = 1e-09, atol: float = 1e-12, max_step: float | None = None, record_every: int = 1, torques: ArrayLike | Callable[..., ArrayLike] | None = None, torque_times: ArrayLike | None = None, hold: str = 'zoh', params: ArrayLike | None = None, threads: int = 0, max_steps: int = 50000000) -> Any:
    """Simulate B members at once (RK4 or RK45, table torques): returns (list of B trajectory dicts or None, list of
(index, exception) for the members that failed).
    """

def skew(v: ArrayLike) -> Any:
    """Cross-product matrices (…, 3, 3): `skew(a) @ b == a × b`."""

def smooth_rates(y: ArrayLike, h: ArrayLike, log_ratio: ArrayLike | None = None) -> Any:
    """Accelerations from noisy rates (`freefloat_core::sensors::smooth_rates`): the Rauch-Tung-Striebel smoother
of the white-jerk rate model, per column of `y` (N, k) sampled every `h` seconds. `log_ratio`:
log10(q h³ / r) for every column, or None for each column's ratio by generalised cross-validation. Returns a dict: rate
and accel (N, k), log_ratio and sigma (k,) (the estimated white rate noise per sample).
    """

def step(model: Model, q: ArrayLike, v: ArrayLike, tau: ArrayLike, dt: float, method: str = 'euler') -> Any:
    """One step of the forward dynamics with tau held over it: (q_next (nq), v_next (nv)).
method "euler": semi-implicit Euler v+ = v + a dt, q+ = q ⊕ v+ dt (Crocoddyl's
IntegratedActionModelEuler); "rk4": Runge-Kutta 4 on the Lie group (the simulator's step).
    """

def step_derivatives(model: Model, q: ArrayLike, v: ArrayLike, tau: ArrayLike, dt: float, method: str = 'euler') -> Any:
    """Derivatives of one step (see step) in the tangent error state: (Fx (2nv, 2nv), Fu (2nv, nv)),
rows and columns [tangent of q; v], u = tau (all nv generalized forces). For an under-actuated
robot with tau = B u use Fu @ B; a free-floating robot with an unactuated base keeps Fu[:, 6:].
    """
