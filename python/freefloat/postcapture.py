"""Seed 000 post-capture identification: scenario files, simulation, both identification forms
(momentum-based and force-based) with both solvers (the paper's modified RLS and the ordinary RLS
on standard parameters), results, tables beside the paper's, figures.

    import freefloat.postcapture as pc
    sc = pc.load_scenario("seed000_2d_medium")        # built-in (freefloat/data/scenarios/) or a file path
    res = pc.run(sc)                                    # simulate + identify (4 estimators)
    print(res.table()); res.save("out/")

Where the paper is silent the scenario files carry the digest's documented choices (docs/postcapture.md).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from . import _core, data
from . import algorithms as alg
from . import models
from . import online
from . import postcapture_equations as eq
from .algorithms import quat_to_matrix
from ._core import InputError

METHODS = ("momentum", "force")
SOLVERS = ("modified_rls", "standard_rls")
# Noise study levels (the paper has no noise): white, per sample. Velocities [m/s, rad/s] and accelerations
# [m/s², rad/s²] at the 10 Hz samples; thrust [N, N·m] at the 1 kHz step rate before integration.
DEFAULT_NOISE = {"velocity": 1e-4, "acceleration": 1e-4, "force": 0.01}
SOLVER_TITLES = {"modified_rls": "paper (modified RLS)", "standard_rls": "standard params (RLS)"}


# -- scenarios -----------------------------------------------------------------------------------------
@dataclass
class Scenario:
    name: str
    description: str
    model: str
    duration: float
    dt: float
    sample_period: float
    q0: np.ndarray
    v0: np.ndarray
    control: dict
    excitation: dict
    tolerance: float
    P0: float
    forgetting: float
    guess: dict
    project: bool = False
    measurement: dict = field(default_factory=dict)
    noise: dict | None = None
    paper: dict = field(default_factory=dict)
    sweep: dict | None = None
    paper_sweep: dict | None = None
    source: str = ""

    def with_base_velocity(self, vel) -> "Scenario":
        """Copy with the initial base (sensor) linear velocity replaced (inertial frame)."""
        import copy

        s = copy.deepcopy(self)
        vel = np.asarray(vel, float)
        A = _base_attitude(models.load(self.model) if isinstance(self.model, str) else self.model, s.q0)
        s.v0[: len(vel)] = (A.T @ np.pad(vel, (0, 3 - len(vel))))[: len(vel)]
        return s


def list_scenarios() -> list[tuple[str, str]]:
    """Built-in scenarios (name, description), shipped inside the package (`freefloat.data`)."""
    out = []
    for name in data.names("scenarios"):
        d = yaml.safe_load(data.read_text("scenarios", name))
        out.append((name, str(d.get("description", "")).strip()))
    return out


def load_scenario(spec: str | Path) -> Scenario:
    """A scenario by built-in name or file path."""
    p = Path(spec)
    if not p.suffix and data.exists("scenarios", str(spec)):
        text, source = data.read_text("scenarios", str(spec)), f"built-in scenario '{spec}'"
    elif p.suffix and p.is_file():
        text, source = p.read_text(), str(p)
    else:
        names = ", ".join(data.names("scenarios"))
        raise InputError(f"scenario '{spec}' not found (built-in scenarios: {names})")
    d = yaml.safe_load(text)
    try:
        return _parse(d, source)
    except KeyError as e:
        raise InputError(f"{source}: missing key {e}") from None


def _parse(d: dict, source: str) -> Scenario:
    m = models.load(d["model"])
    planar = m.joint_types[0] == "planar"
    ini = d["initial"]
    deg = np.pi / 180
    joints = np.asarray(ini["joints_deg"], float) * deg
    nj = m.nv - (3 if planar else 6)
    if len(joints) != nj:
        raise InputError(f"{source}: initial.joints_deg needs {nj} entries, got {len(joints)}")
    if planar:
        q0 = np.concatenate([[*ini.get("base_position", [0, 0]), ini.get("base_yaw_deg", 0.0) * deg], joints])
        vel = np.asarray(ini["base_velocity"], float)
        rate = float(ini["base_rate"])
        A = _base_attitude(m, q0)[:2, :2]
        v0 = np.concatenate([A.T @ vel, [rate], np.zeros(nj)])
    else:
        q0 = np.concatenate([ini.get("base_position", [0, 0, 0]), [0, 0, 0, 1], joints])
        vel, rate = np.asarray(ini["base_velocity"], float), np.asarray(ini["base_rate"], float)
        v0 = np.concatenate([vel, rate, np.zeros(nj)])  # attitude identity: body = inertial
    ex = d["excitation"]
    exc = {"damping": float(ex.get("damping", 0.0)), "amp": list(map(float, ex["amplitude"])),
           "freq": list(map(float, ex["frequency"])), "phase": [float(x) * deg for x in ex.get("phase_deg", [0] * nj)]}
    ident = d["identification"]
    return Scenario(
        name=d["name"], description=str(d.get("description", "")).strip(), model=d["model"],
        duration=float(d["duration"]), dt=float(d.get("dt", 1e-3)), sample_period=float(d.get("sample_period", 0.1)),
        q0=q0, v0=v0, control=dict(d["control"]), excitation=exc, tolerance=float(ident["transit_tolerance"]),
        P0=float(ident.get("P0", 1e6)), forgetting=float(ident.get("forgetting", 1.0)), guess=ident["guess"],
        project=bool(ident.get("project", False)), measurement=dict(d.get("measurement") or {}),
        noise=d.get("noise"), paper=d.get("paper", {}) or {}, sweep=d.get("sweep"), paper_sweep=d.get("paper_sweep"),
        source=source)


def _base_attitude(m, q) -> np.ndarray:
    fk = np.asarray(alg.forward_kinematics(m, q))[0]
    return quat_to_matrix(fk[None, 3:])[0]


# -- simulation and measurements ------------------------------------------------------------------------
def simulate(sc: Scenario, model=None) -> dict:
    """RK4 at sc.dt with the paper's controllers (eqs. 39-40), every step recorded."""
    m = model or models.load(sc.model)
    c, e = sc.control, sc.excitation
    return _core.postcapture_simulate(
        m._core, np.asarray(sc.q0, float), np.asarray(sc.v0, float), sc.duration, sc.dt,
        float(c["F_max"]), float(c["K_F"]), float(c["M_max"]), float(c["K_M"]), list(np.atleast_1d(np.asarray(c["K_D"], float))), list(np.atleast_1d(np.asarray(c["K_P"], float))),
        list(map(float, c.get("jet", [0, 0, 0]))), e["damping"], e["amp"], e["freq"], e["phase"], 1)


def measure(model, sim: dict, sc: Scenario, rng: np.random.Generator | None = None) -> eq.Measurements:
    """Samples every `sample_period`: state, exact accelerations, thruster wrench, and the impulses
    ∫F and ∫(M + x_F × F) integrated from the step-rate thrust by Simpson's rule. With `sc.noise`
    (and rng) white noise is added: `velocity` to v, `acceleration` to ddq at the samples, `force`
    (N, and N·m) to the thrust at the step rate before integration."""
    planar = model.joint_types[0] == "planar"
    nb = 3 if planar else 6
    step = int(round(sc.sample_period / sc.dt))
    if step % 2:
        raise InputError("sample_period / dt must be even (Simpson's rule between samples)")
    t, q, v, ddq = sim["t"], sim["q"], sim["v"].copy(), sim["ddq"].copy()
    wrench = sim["tau"][:, :nb].copy()
    noise = sc.noise or {}
    if noise and rng is not None:
        wrench += rng.normal(0.0, float(noise.get("force", 0.0)), wrench.shape)
    fk = np.asarray(alg.forward_kinematics(model, q))[:, 0]
    A, rb = quat_to_matrix(fk[:, 3:]), fk[:, :3]
    if planar:
        z = np.zeros(len(t))
        fb, tb = np.stack([wrench[:, 0], wrench[:, 1], z], -1), np.stack([z, z, wrench[:, 2]], -1)
    else:
        fb, tb = wrench[:, :3], wrench[:, 3:]
    F = eq.mv(A, fb)
    M = eq.mv(A, tb) + np.cross(rb, F)  # tb holds M + r'_jet × f about the sensor; add r_b × F
    idx = np.arange(0, len(t), step)
    h = sc.dt

    def simpson(f):
        pair = h / 3.0 * (f[:-2:2] + 4 * f[1:-1:2] + f[2::2])
        cum = np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(pair, 0)])
        return cum[idx // 2]

    def trapezoid(f):
        # only the sampled thrust (the digest's alternative): trapezoid between the 10 Hz samples
        fs = f[idx]
        return np.concatenate([np.zeros((1,) + f.shape[1:]), np.cumsum(0.5 * (fs[1:] + fs[:-1]) * sc.sample_period, 0)])

    mode = sc.measurement
    vs, as_ = v[idx], ddq[idx]
    if noise and rng is not None:
        vs = vs + rng.normal(0.0, float(noise.get("velocity", 0.0)), vs.shape)
        as_ = as_ + rng.normal(0.0, float(noise.get("acceleration", 0.0)), as_.shape)
    keep = slice(None)
    if mode.get("accelerations", "exact") == "central_difference":
        # v̇ from the sampled (possibly noisy) velocities by central differences. For the base, v holds body-frame
        # components and ddq is their time derivative, so this approximates ddq itself. The first and last
        # samples have no central difference and are dropped (an online estimator runs one sample behind).
        as_ = np.gradient(vs, sc.sample_period, axis=0)
        keep = slice(1, -1)
    elif mode.get("accelerations", "exact") != "exact":
        raise InputError(f"measurement.accelerations: expected 'exact' or 'central_difference', got {mode['accelerations']!r}")
    integ = {"simpson": simpson, "trapezoid": trapezoid}.get(mode.get("impulses", "simpson"))
    if integ is None:
        raise InputError(f"measurement.impulses: expected 'simpson' or 'trapezoid', got {mode['impulses']!r}")
    return eq.Measurements(t[idx][keep], q[idx][keep], vs[keep], as_[keep], wrench[idx][keep], integ(F)[keep],
                           integ(M)[keep])


# -- identification -------------------------------------------------------------------------------------
def parameter_names(planar: bool) -> list[str]:
    if planar:
        return ["m1", "b1x", "b1y", "I1", "mn", "bnx", "bny", "In"]
    body = lambda s: [f"m{s}", f"b{s}x", f"b{s}y", f"b{s}z", f"I{s}xx", f"I{s}xy", f"I{s}xz", f"I{s}yy", f"I{s}yz", f"I{s}zz"]  # noqa: E731
    return body("1") + body("n")


def _physical(planar, m1, b1, I1, mn, bn, In) -> np.ndarray:
    """Histories → (N, P) in parameter_names order. b: (N, 3); I: (N, 3, 3)."""
    if planar:
        return np.stack([m1, b1[:, 0], b1[:, 1], I1[:, 2, 2], mn, bn[:, 0], bn[:, 1], In[:, 2, 2]], -1)
    f = lambda m, b, I: [m, b[:, 0], b[:, 1], b[:, 2], I[:, 0, 0], I[:, 0, 1], I[:, 0, 2], I[:, 1, 1], I[:, 1, 2], I[:, 2, 2]]  # noqa: E731
    return np.stack(f(m1, b1, I1) + f(mn, bn, In), -1)


def _sharp_to_matrix(s):
    return np.stack([np.stack([s[:, 0], s[:, 1], s[:, 2]], -1), np.stack([s[:, 1], s[:, 3], s[:, 4]], -1),
                     np.stack([s[:, 2], s[:, 4], s[:, 5]], -1)], -2)


def _guess(sc: Scenario, planar: bool):
    """Initial guesses (m, b', I'_c) of base and target from the scenario (the paper's §V values)."""
    out = []
    for key in ("base", "target"):
        g = sc.guess[key]
        b = np.zeros(3)
        b[: len(g["com"])] = g["com"]
        I = np.asarray(g["inertia"], float)
        Ic = np.diag(np.full(3, float(I))) if I.ndim == 0 else (np.diag(I) if I.ndim == 1 else I)
        out.append((float(g["mass"]), b, Ic))
    return out


def identify_modified(model, rows: eq.PaperRows, sc: Scenario, planar: bool) -> np.ndarray:
    """The paper's modified RLS (eqs. 34-38) over the rows; returns (N, P) physical parameters."""
    L = eq.Layout(planar)
    (m1, b1, I1), (mn, bn, In) = _guess(sc, planar)
    mu0 = np.concatenate([np.concatenate([[m], m * b])[L.mu_cols] for m, b in ((m1, b1), (mn, bn))])
    th0 = np.concatenate([eq.inertia_sharp(I)[L.th_cols] for I in (I1, In)])
    est = online.ModifiedRLS(L.coupling, mu0, np.full(len(mu0), sc.P0), th0, np.full(len(th0), sc.P0))
    mu, th = est.run(rows.t, rows.A, rows.b, rows.Phi, rows.y, rows.Psi)
    k = len(L.mu_cols)
    hist = []
    for body in range(2):
        m = mu[:, body * k]
        b = np.zeros((len(m), 3))
        b[:, : k - 1] = mu[:, body * k + 1:(body + 1) * k] / m[:, None]
        if planar:
            I = np.zeros((len(m), 3, 3))
            I[:, 2, 2] = th[:, body]
        else:
            I = _sharp_to_matrix(th[:, 6 * body:6 * body + 6])
        hist += [m, b, I]
    return _physical(planar, *hist)


def identify_standard(model, rows: eq.StandardRows, sc: Scenario, planar: bool, forgetting: float | None = None,
                      project: bool = False) -> np.ndarray:
    """Ordinary RLS on the standard parameters (digest §7); returns (N, P) physical parameters."""
    L = eq.Layout(planar)
    x0 = np.concatenate([eq.standard_vector(*g)[L.std_cols] for g in _guess(sc, planar)])
    est = online.RecursiveLS(x0, np.full(len(x0), sc.P0), sc.forgetting if forgetting is None else forgetting)
    x = est.run(rows.t, rows.Phi, rows.y)
    k = len(L.std_cols)
    hist = []
    for body in range(2):
        full = np.zeros((len(x), 10))
        full[:, L.std_cols] = x[:, body * k:(body + 1) * k]
        if planar:
            # Out-of-plane inertia is not identifiable in planar motion. Complete it as an isotropic CoM
            # inertia (as the model files do) so the projection sees a body: I_ref = I_czz 1 + (|h|²1 − hhᵀ)/m,
            # which keeps the identified I_ref,zz.
            m_, h = full[:, 0], full[:, 1:4]
            iczz = full[:, 9] - (h[:, 0] ** 2 + h[:, 1] ** 2) / m_
            Io = iczz[:, None, None] * np.eye(3) + (np.einsum("ti,ti->t", h, h)[:, None, None] * np.eye(3)
                                                    - np.einsum("ti,tj->tij", h, h)) / m_[:, None, None]
            full[:, 4:] = np.stack([Io[:, 0, 0], Io[:, 0, 1], Io[:, 1, 1], Io[:, 0, 2], Io[:, 1, 2], Io[:, 2, 2]], -1)
        if project:
            full = eq.project_consistent(full)
        m, b, I = eq.from_standard(full)
        hist += [m, b, I]
    return _physical(planar, *hist)


def truth_vector(model, planar: bool) -> np.ndarray:
    base, target = 0, _target_index(model)
    (m1, b1, I1), (mn, bn, In) = eq.body_truth(model, base), eq.body_truth(model, target)
    one = lambda x: x[None]  # noqa: E731
    return _physical(planar, np.array([m1]), one(b1), one(I1), np.array([mn]), one(bn), one(In))[0]


def _target_index(model) -> int:
    idx = [i for i, tags in enumerate(model.tags) if "target" in tags]
    if len(idx) != 1:
        raise InputError(f"model '{model.name}' must have exactly one body tagged 'target' (found {len(idx)})")
    i = idx[0]
    # The paper's target is rigidly grasped: a fixed joint on the end-effector link.
    if model.joint_types[i] != "fixed" or any(model.parents[j] == i for j in range(model.nbodies)):
        raise InputError(f"the target '{model.body_names[i]}' must be welded to the end effector "
                         "(a leaf body on a fixed joint)")
    return i


def transit_times(t, hist, truth, tol, zero_abs=1e-8):
    """Per parameter: (first time within tolerance, time after which it stays within). Relative
    tolerance; for a zero true value the paper's absolute 1e-8 (Table 6 note)."""
    out = []
    for j in range(hist.shape[1]):
        err = np.abs(hist[:, j] - truth[j])
        ok = err <= (tol * abs(truth[j]) if truth[j] != 0 else zero_abs)
        first = float(t[np.argmax(ok)]) if ok.any() else None
        bad = np.nonzero(~ok)[0]
        stays = None if not ok[-1] else (float(t[0]) if len(bad) == 0 else float(t[bad[-1] + 1]))
        out.append((first, stays))
    return out


@dataclass
class PostcaptureResult:
    scenario: Scenario
    names: list
    truth: np.ndarray
    histories: dict          # (method, solver) -> (t (N,), params (N, P))
    timings: dict
    residuals: dict = field(default_factory=dict)

    def final(self, method, solver):
        return self.histories[(method, solver)][1][-1]

    def rel_error(self, method, solver):
        tr = self.truth
        est = self.final(method, solver)
        return np.where(tr != 0, np.abs(est - tr) / np.where(tr != 0, np.abs(tr), 1), np.abs(est - tr))

    def transits(self, method, solver):
        t, h = self.histories[(method, solver)]
        return transit_times(t, h, self.truth, self.scenario.tolerance)

    def to_dict(self) -> dict:
        out = {"scenario": self.scenario.name, "model": self.scenario.model, "tolerance": self.scenario.tolerance,
               "P0": self.scenario.P0, "forgetting": self.scenario.forgetting, "projected": self.scenario.project,
               "duration": self.scenario.duration, "timings_s": self.timings, "equation_residuals_at_truth": self.residuals,
               "noise": self.scenario.noise, "measurement": self.scenario.measurement, "methods": {}}
        for (method, solver), (t, h) in self.histories.items():
            tt = self.transits(method, solver)
            err = self.rel_error(method, solver)
            out["methods"].setdefault(method, {})[solver] = {
                n: {"truth": float(self.truth[j]), "estimate": float(h[-1, j]),
                    "error": float(err[j]), "error_kind": "relative" if self.truth[j] != 0 else "absolute",
                    "transit_time": tt[j][1], "first_within": tt[j][0],
                    "paper": self.scenario.paper.get(method, {}).get(n)}
                for j, n in enumerate(self.names)}
        return out

    def table(self) -> str:
        """Our final estimates (transit time to the scenario's tolerance, 'stays' reading) beside the paper's."""
        tol = self.scenario.tolerance
        lines = [f"{self.scenario.name}: final estimates at t = {self.scenario.duration:g} s, "
                 f"(transit time to {tol * 100:g} %, after which the estimate stays within)"]
        for method in METHODS:
            if (method, "modified_rls") not in self.histories:
                continue
            paper = self.scenario.paper.get(method, {})
            hdr = f"{'param':>6} {'truth':>12} | {'paper ' + method:>22} | " + " | ".join(
                f"{SOLVER_TITLES[s]:>30}" for s in SOLVERS)
            lines += ["", f"{method}-based", hdr, "-" * len(hdr)]
            tr = {s: self.transits(method, s) for s in SOLVERS}
            err = {s: self.rel_error(method, s) for s in SOLVERS}
            for j, n in enumerate(self.names):
                if n not in paper and paper and _is_product(n):
                    continue
                p = paper.get(n)
                ptxt = "" if p is None or p[0] is None else (f"{p[0]:.6g}" + (f" ({p[1]:g} s)" if len(p) > 1 and p[1] is not None else " (-)"))
                cells = []
                for s in SOLVERS:
                    e = self.final(method, s)[j]
                    tt = tr[s][j][1]
                    cells.append(f"{e:>13.6g} ({'-' if tt is None else f'{tt:.1f}'} s, {err[s][j]:.1e})")
                lines.append(f"{n:>6} {self.truth[j]:>12.6g} | {ptxt:>22} | " + " | ".join(f"{c:>30}" for c in cells))
        lines.append("")
        lines.append("(error in brackets: relative, absolute for a zero true value; '-' = not within tolerance at the end)")
        return "\n".join(lines)

    def save(self, out) -> Path:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "results.json").write_text(json.dumps(self.to_dict(), indent=1))
        (out / "table.txt").write_text(self.table() + "\n")
        plot_histories(self, out)
        return out / "results.json"


def _is_product(n):
    return n[-2:] in ("xy", "xz", "yz") and n[0] == "I"


def identify(model, meas: eq.Measurements, sc: Scenario, methods=METHODS, timings=None) -> PostcaptureResult:
    planar = model.joint_types[0] == "planar"
    base, target = 0, _target_index(model)
    truth = truth_vector(model, planar)
    hist, res, timings = {}, {}, dict(timings or {})
    for method in methods:
        t0 = time.perf_counter()
        if method == "momentum":
            paper_rows = eq.paper_momentum_rows(model, meas, base, target)
            std_rows = eq.standard_momentum_rows(model, meas, base, target)
        else:
            paper_rows = eq.paper_force_rows(model, meas, base, target)
            std_rows = eq.standard_force_rows(model, meas, base, target)
        timings[f"{method}_rows"] = time.perf_counter() - t0
        res[method] = equation_residuals(model, paper_rows, std_rows, planar, base, target)
        t0 = time.perf_counter()
        hist[(method, "modified_rls")] = (paper_rows.t, identify_modified(model, paper_rows, sc, planar))
        hist[(method, "standard_rls")] = (std_rows.t, identify_standard(model, std_rows, sc, planar, project=sc.project))
        timings[f"{method}_estimators"] = time.perf_counter() - t0
    return PostcaptureResult(sc, parameter_names(planar), truth, hist, timings, res)


def equation_residuals(model, pr: eq.PaperRows, sr: eq.StandardRows, planar, base, target) -> dict:
    """Largest residual of each regression at the model file's true parameters, and the size of the
    right-hand side, so that a reader can see the equations hold (noise-free data)."""
    L = eq.Layout(planar)
    (m1, b1, I1), (mn, bn, In) = eq.body_truth(model, base), eq.body_truth(model, target)
    mu = np.concatenate([np.concatenate([[m], m * b])[L.mu_cols] for m, b in ((m1, b1), (mn, bn))])
    th = np.concatenate([eq.inertia_sharp(I)[L.th_cols] for I in (I1, In)])
    D = np.concatenate([eq.mJ(m1, b1)[L.d_cols], eq.mJ(mn, bn)[L.d_cols]])
    if planar:
        D[3] = m1 * (b1 @ b1)
        D[7] = mn * (bn @ bn)
    P = np.array(model.parameters(), float)
    x = np.concatenate([P[base][L.std_cols], P[target][L.std_cols]])
    lin = np.abs(eq.mv(pr.A, mu) - pr.b).max()
    ang = np.abs(eq.mv(pr.Phi, th) - pr.y - eq.mv(pr.Psi, D)).max()
    std = np.abs(eq.mv(sr.Phi, x) - sr.y).max()
    return {"paper_linear": float(lin), "paper_linear_scale": float(np.abs(pr.b).max()),
            "paper_angular": float(ang), "paper_angular_scale": float(np.abs(pr.y).max()),
            "standard": float(std), "standard_scale": float(np.abs(sr.y).max())}


def run(sc: Scenario | str, methods=METHODS, seed: int | None = 0, progress=None) -> PostcaptureResult:
    """Simulate the scenario and identify with both forms and both solvers."""
    if not isinstance(sc, Scenario):
        sc = load_scenario(sc)
    m = models.load(sc.model)
    _target_index(m)
    t0 = time.perf_counter()
    sim = simulate(sc, m)
    t_sim = time.perf_counter() - t0
    if progress:
        progress("simulated")
    rng = np.random.default_rng(seed) if sc.noise else None
    t0 = time.perf_counter()
    meas = measure(m, sim, sc, rng)
    t_meas = time.perf_counter() - t0
    res = identify(m, meas, sc, methods, timings={"simulation": t_sim, "measurements": t_meas})
    if progress:
        progress("identified")
    return res


# -- initial-velocity sweep (Figs. 6-9) ----------------------------------------------------------------
def sweep(sc: Scenario, velocities=None, progress=None) -> dict:
    """Relative error of every parameter at the end of the run (the paper: 60 s) for each initial base
    velocity; both methods, both solvers."""
    vels = np.asarray(velocities if velocities is not None else sc.sweep["velocities"], float)
    out = {"velocities": vels.tolist(), "errors": {}}
    names = None
    for k, vel in enumerate(vels):
        res = run(sc.with_base_velocity(vel))
        names = res.names
        for method in METHODS:
            for solver in SOLVERS:
                out["errors"].setdefault(f"{method}/{solver}", []).append(res.rel_error(method, solver).tolist())
        if progress:
            progress(k + 1, len(vels))
    out["names"] = names
    return out


def sweep_table(sw: dict, params=("In", "I1", "mn", "bnx"), paper: dict | None = None) -> str:
    names = sw["names"]
    cols = [names.index(p) for p in params]
    lines = ["relative error (%) at the end of the run vs initial base velocity [m/s]",
             f"{'velocity':>14} {'method/solver':>26} " + " ".join(f"{p:>10}" for p in params)]
    for k, v in enumerate(sw["velocities"]):
        for key, errs in sw["errors"].items():
            lines.append(f"{str([round(x, 1) for x in v]):>14} {key:>26} " + " ".join(f"{100 * errs[k][c]:>10.4f}" for c in cols))
    if paper:
        lines.append("paper (text of Sec. V-A-3): momentum-based I'n " + ", ".join(
            f"{p['error_percent']} % at {p['velocity']}" for p in paper.get("momentum_In", []))
            + f"; force-based: {paper.get('force_In', '')}")
    return "\n".join(lines)


# -- noise study --------------------------------------------------------------------------------------
def noise_study(sc: Scenario, scales=(0.0, 0.01, 0.1, 1.0), seeds=(0, 1, 2)) -> dict:
    """Relative error at the end of the run for DEFAULT_NOISE × scale (the paper has no noise), the
    median over seeds, per method/solver and parameter."""
    import copy

    out = {"levels": [], "names": None}
    for scale in scales:
        s = copy.deepcopy(sc)
        s.noise = {k: v * scale for k, v in DEFAULT_NOISE.items()} if scale > 0 else None
        errs = {}
        for seed in (seeds if scale > 0 else seeds[:1]):
            res = run(s, seed=seed)
            out["names"] = res.names
            for method in METHODS:
                for solver in SOLVERS:
                    errs.setdefault(f"{method}/{solver}", []).append(res.rel_error(method, solver))
        out["levels"].append({"scale": scale, "noise": s.noise,
                              "median_error": {k: np.median(v, 0).tolist() for k, v in errs.items()}})
    return out


def noise_table(ns: dict) -> str:
    names = ns["names"]
    lines = ["median relative error (%) at the end of the run; noise = DEFAULT_NOISE × scale"]
    lines.append(f"{'scale':>6} {'method/solver':>24} " + " ".join(f"{n:>9}" for n in names))
    for lv in ns["levels"]:
        for key, e in lv["median_error"].items():
            lines.append(f"{lv['scale']:>6g} {key:>24} " + " ".join(f"{100 * x:>9.4f}" for x in e))
    return "\n".join(lines)


# -- figures --------------------------------------------------------------------------------------------
def plot_histories(res: PostcaptureResult, out: Path) -> list[Path]:
    """Figs. 4-5 style: estimate / truth versus time, one figure per method (both solvers)."""
    from .plots import _plt

    plt = _plt()
    paths = []
    for method in METHODS:
        if (method, "modified_rls") not in res.histories:
            continue
        show = [j for j, n in enumerate(res.names) if not _is_product(n)]
        ncol = 4
        nrow = int(np.ceil(len(show) / ncol))
        fig, axes = plt.subplots(nrow, ncol, figsize=(3.2 * ncol, 2.4 * nrow), constrained_layout=True, squeeze=False)
        for ax, j in zip(axes.ravel(), show):
            for solver, style in zip(SOLVERS, ("-", "--")):
                t, h = res.histories[(method, solver)]
                tr = res.truth[j]
                y = h[:, j] / tr if tr != 0 else h[:, j]
                ax.plot(t, y, style, label=SOLVER_TITLES[solver])
            ax.set_title(res.names[j] + (" / truth" if res.truth[j] != 0 else " (truth 0)"))
            if res.truth[j] != 0:
                ax.set_ylim(0.9, 1.1)
            ax.grid(alpha=0.3)
        for ax in axes[-1]:
            ax.set_xlabel("t [s]")
        for ax in axes.ravel()[len(show):]:
            ax.axis("off")
        axes[0, 0].legend(fontsize=7)
        fig.suptitle(f"{res.scenario.name}: {method}-based identification (estimate / truth)")
        p = out / f"{method}_estimates.png"
        fig.savefig(p, dpi=110)
        plt.close(fig)
        paths.append(p)
    return paths


def plot_sweep(sw: dict, out: Path, params=("In", "I1", "mn", "bnx")) -> Path:
    """Figs. 6-9 style: relative error vs |initial base velocity|, one panel per parameter."""
    from .plots import _plt

    plt = _plt()
    names = sw["names"]
    speed = np.linalg.norm(np.asarray(sw["velocities"]), axis=1)
    order = np.argsort(speed, kind="stable")
    fig, axes = plt.subplots(1, len(params), figsize=(4 * len(params), 3.4), constrained_layout=True)
    for ax, p in zip(axes, params):
        j = names.index(p)
        for key, errs in sw["errors"].items():
            e = np.asarray(errs)[:, j] * 100
            ax.semilogy(speed[order], np.maximum(e[order], 1e-12), "o", label=key, ms=4, alpha=0.8)
        ax.set_xlabel("|v_base(0)| [m/s]")
        ax.set_ylabel("relative error [%]")
        ax.set_title(p)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    p = Path(out) / "velocity_sweep.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p
