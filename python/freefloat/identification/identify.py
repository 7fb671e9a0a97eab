"""Minimal-parameter identification of a free-floating robot from its momentum (Naveen, Shah, Misra,
Secs. III-IV, VI.C).

    res = ff.identify_minimal(model, data)        # data: Trajectory, Telemetry, or a .parquet/.csv telemetry file
    print(res.table(truth=model.parameters()))     # name, true value, estimate, std, relative error
    res.save("out/")                               # results.json + figures

The measured output is the total momentum: taken from the data when it has momentum columns, otherwise the time
integral of its external-wrench columns (thrusters firing, a contact), otherwise the conserved value `h0` (zero for
a robot released at rest). The known bodies (reaction wheels by default) move to
the right-hand side; their momentum is what gives the estimate its scale."""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import scipy.linalg

from .._core import InputError
from ..constants import TABLE3_RANGE_RAD, TABLE3_START_DEG  # noqa: F401  (re-exported)
from ..io.telemetry import Telemetry
from .conventions import ConventionReport, check_conventions
from .estimation import LeastSquaresResult, absolute_columns, known_parameters, least_squares, relative_errors
from .minimal import MinimalParameters, check_known, minimal_parameters


@dataclass
class IdentificationResult:
    """Identified minimal parameters with their statistics; `mp` maps them to standard parameters."""

    mp: MinimalParameters
    fit: LeastSquaresResult
    samples: int
    conventions: ConventionReport | None = None
    #: which estimator ran, in words (printed by the CLI, kept in results.json)
    estimator: str = "least squares"

    @property
    def names(self) -> list[str]:
        return list(self.mp.names)

    @property
    def estimate(self) -> np.ndarray:
        return self.fit.estimate

    @property
    def std(self) -> np.ndarray:
        return self.fit.std

    def truth_values(self, truth) -> np.ndarray:
        """Minimal parameters of `truth`: standard parameters (nbodies, 10) or a Model."""
        P = truth.parameters() if hasattr(truth, "parameters") else np.asarray(truth, dtype=float)
        return self.mp.from_standard(P)

    def errors(self, truth) -> dict:
        """Naveen, Shah, Misra's error figures against `truth` (eqs. 38-39), in percent, over the minimal
        parameters whose true value is not zero; those that are exactly zero (a UR5 has many: symmetric links)
        have no relative error and are reported by their absolute error instead."""
        tv = self.truth_values(truth)
        nz = tv != 0
        out = {}
        if nz.any():
            med, mx = relative_errors(self.estimate[nz], tv[nz])
            out.update({"median_rel_error_pct": med, "max_rel_error_pct": mx})
        else:
            out.update({"median_rel_error_pct": float("nan"), "max_rel_error_pct": float("nan")})
        if not nz.all():
            out["zero_truth"] = {
                "names": [n for n, z in zip(self.names, nz) if not z],
                "abs_error": [float(abs(x)) for x, z in zip(self.estimate, nz) if not z],
            }
        return out

    def table(self, truth=None) -> str:
        """The estimate as a printable table, with true values and relative errors when `truth` is given."""
        tv = None if truth is None else self.truth_values(truth)
        head = f"{'parameter':24s} " + (f"{'true':>14s} " if tv is not None else "") + f"{'estimate':>14s} {'std':>11s}"
        lines = [head + (f" {'rel. error':>11s}" if tv is not None else "")]
        for k, name in enumerate(self.names):
            row = f"{name:24s} "
            if tv is not None:
                row += f"{tv[k]:14.6g} "
            row += f"{self.estimate[k]:14.6g} {self.std[k]:11.3g}"
            if tv is not None and tv[k] != 0:
                row += f" {abs((tv[k] - self.estimate[k]) / tv[k]) * 100:10.3g}%"
            elif tv is not None:  # no relative error of a zero: the absolute one
                row += f"  abs {abs(self.estimate[k]):.3g}"
            lines.append(row)
        lines.append(
            f"{len(self.names)} minimal parameters from {self.samples} samples ({self.fit.rows} rows); "
            f"condition number {self.fit.condition_number:.4g}; residual sigma {self.fit.sigma:.3g}; "
            f"solver: {self.fit.method}"
        )
        if tv is not None:
            e = self.errors(truth)
            z = e.get("zero_truth")
            lines.append(
                f"relative error (Naveen, Shah, Misra eqs. 38-39): median {e['median_rel_error_pct']:.3g} %, "
                f"max {e['max_rel_error_pct']:.3g} %"
                + (
                    f" over the {len(self.names) - len(z['names'])} non-zero true values; {len(z['names'])} "
                    f"true values are exactly 0 (largest absolute error {max(z['abs_error']):.3g})"
                    if z
                    else ""
                )
            )
        return "\n".join(lines)

    def to_dict(self, truth=None) -> dict:
        d = {
            "names": self.names,
            "expressions": self.mp.expressions(),
            "estimate": self.estimate.tolist(),
            "std": self.std.tolist(),
            "condition_number": self.fit.condition_number,
            "rows": self.fit.rows,
            "samples": self.samples,
            "residual_sigma": self.fit.sigma,
            "solver": self.fit.method,
            "estimator": self.estimator,
            "known_bodies": [self.mp.model.body_names[i] for i in self.mp.known],
        }
        if self.conventions is not None:
            d["convention_check"] = self.conventions.to_dict()
        if truth is not None:
            d["truth"] = self.truth_values(truth).tolist()
            d.update(self.errors(truth))
        return d

    def save(self, directory, truth=None) -> Path:
        """Write results.json and, with `truth`, a figure of relative errors and their 1-sigma bars."""
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        (out / "results.json").write_text(json.dumps(self.to_dict(truth), indent=2))
        if truth is not None:
            _plot_errors(self, self.truth_values(truth), out / "minimal_parameters.png")
        return out


def identify_minimal(
    model,
    data,
    known=None,
    method: str = "auto",
    h0=None,
    weights=None,
    rate_noise=None,
    check: str = "error",
) -> IdentificationResult:
    """Identify the minimal parameters of `model` from motion data.

    data: a `Trajectory`, a `Telemetry`, or a telemetry file (.parquet/.csv with columns t, q.<label>, v.<label>,
    optionally momentum.<px..Lz> or wrench.<fx..mz>). known: bodies whose parameters are known (default: those
    tagged known/wheel).
    method: "auto" (default: the closed form where it applies, else numeric — the same default as
        `freefloat params minimal`), "closed-form" (Naveen, Shah, Misra's grouping; revolute trees in modified-DH
        frames) or "numeric" (any tree).
    h0: the total momentum at the start (6,). Without momentum columns it is conserved (zero if not given), or,
    with wrench columns, the start of their integral; given explicitly, it overrides a momentum column.
    weights: (6,) inverse variances of the momentum components, or "auto": solve once unweighted, estimate each
    component's residual variance, and solve again with their inverses (two-step feasible weighted LS).
    rate_noise: standard deviations of the white noise on the measured rates — (nv,) per velocity component, or
    the triple (base linear, base angular, joint) like `telemetry.add_noise` — to remove the errors-in-variables
    bias of least squares (`bias_compensated`), "none" (plain least squares, deliberately), or "data": the levels
    the telemetry declares (`Telemetry.rate_noise`, set by `add_noise` and kept in its files), if any.
    None: plain least squares (a warning says so when the data declare their noise).
    Unweighted only: with `weights`, declared levels are not used (a warning says so).
    check: the convention check before identifying (`conventions.check_conventions`: does the momentum model fit
    the data as written, or only with the quaternion reordered / a velocity rotated?). "error" (default) refuses
    data that a usual convention mistake explains, naming it, and warns when nothing fits; "warn" only warns;
    "off" skips it.  Simulated data (a `Trajectory`) are written by freefloat itself and are not checked."""
    if check not in ("error", "warn", "off"):
        raise InputError(f"argument `check`: expected 'error', 'warn' or 'off', got {check!r}")
    if isinstance(data, (str, Path)):
        data = Telemetry.from_file(data, model)
    declared = getattr(data, "rate_noise", None)
    source = "given"
    if isinstance(rate_noise, str) and rate_noise == "none":  # plain least squares, deliberately: no warning
        rate_noise, declared = None, None
    if isinstance(rate_noise, str):
        if rate_noise != "data":
            raise InputError(f"argument `rate_noise`: expected standard deviations, 'data' or None, got {rate_noise!r}")
        rate_noise, source = declared, "declared by the data"
        if rate_noise is not None and weights is not None:
            warnings.warn(
                f"the data declare rate noise {declared} but the errors-in-variables bias removal is for unweighted "
                "least squares: running weighted least squares without it",
                stacklevel=2,
            )
            rate_noise = None
    elif rate_noise is None and declared is not None and weights is None:
        warnings.warn(
            f"the data declare rate noise {declared} but no errors-in-variables bias removal was asked for: plain "
            "least squares is biased towards zero (pass rate_noise='data', on the command line the default)",
            stacklevel=2,
        )
    if rate_noise is not None:
        _rate_sigmas(model, rate_noise)  # a bad level is named before any work
    t, q, v, h = _read(model, data, h0)
    check_known(model, known)  # before the method choice: an unknown body is not a reason to try another method
    if method == "auto":
        mp = minimal_parameters(model, "auto", known)
    elif method == "closed-form":
        try:
            mp = minimal_parameters(model, "closed-form", known)
        except Exception as e:  # a model outside the closed form's scope
            raise InputError(f"{e} (use method='numeric')") from None
    else:
        mp = minimal_parameters(model, method, known)
    # zero momentum up to round-off (a simulated run's momentum column carries ~1e-10): nothing sets the scale
    if len(mp.known) == 0 and np.allclose(h, 0.0, rtol=0.0, atol=1e-6):
        raise InputError(
            f"model '{model.name}': no body has known parameters and the momentum is zero, so the overall scale of the "
            "parameters is unobservable (every parameter times any factor fits the data equally well; momentum "
            "identification fixes the scale through a known body, such as a reaction wheel). Name one with "
            "known=[...] (on the command line --known BODY), or tag it 'known' in the model file"
        )
    # each sample gives six momentum equations: fewer than the unknowns cannot determine them (say so in samples)
    need = -(-mp.n_min // 6)
    if len(t) < max(need, 2):
        raise InputError(
            f"argument `data`: {len(t)} sample{'s' if len(t) != 1 else ''} of telemetry; the {mp.n_min} unknown "
            f"minimal parameters of model '{model.name}' need at least {max(need, 2)} samples (6 momentum equations "
            "each), and in practice many more along an exciting motion"
        )
    report = None
    if check != "off" and not hasattr(data, "ddq") and len(q) > 0:
        report = check_conventions(mp, q, v, h)
        if report.cause and check == "error":
            raise InputError(
                f"argument `data`: {report.message()} "
                "(to identify anyway: check='off', on the command line --check off)"
            )
        if not report.ok:
            warnings.warn(report.message(), stacklevel=2)
    if isinstance(weights, str):
        if weights != "auto":
            raise InputError(f"argument `weights`: expected six inverse variances or 'auto', got {weights!r}")
        first = least_squares(model, q, v, h, mp)
        weights = 1.0 / np.maximum(component_variances(mp, q, v, h, first.estimate), 1e-300)
    fit = least_squares(model, q, v, h, mp, weights=weights)
    if rate_noise is not None:
        if weights is not None:
            raise InputError(
                "arguments `weights` and `rate_noise`: the bias compensation is for unweighted least squares"
            )
        fit = bias_compensated(mp, q, v, fit, _rate_sigmas(model, rate_noise))
    if rate_noise is not None and "bias compensation" in fit.method and "skipped" not in fit.method:
        levels = ", ".join(f"{x:.3g}" for x in np.atleast_1d(np.asarray(rate_noise, dtype=float)))
        estimator = f"least squares + errors-in-variables bias removal (rate noise {levels}, {source})"
    elif rate_noise is not None:
        estimator = "least squares (errors-in-variables bias removal skipped: noise-dominated direction)"
    else:
        estimator = ("weighted least squares" if weights is not None else "least squares") + " (no rate-noise removal)"
    return IdentificationResult(
        mp=mp, fit=fit, samples=len(t), conventions=report, estimator=f"{estimator}; minimal set: {mp.method}"
    )


#: bias compensation is refused when the rate noise makes up more than this share of the regressor's energy in
#: some direction: the correction is first order in that share (spread excitation gives ~5e-4)
MAX_NOISE_SHARE = 0.05


def bias_compensated(mp, q, v, fit, sigma, stride: int = 10, chunk: int = 512):
    """Remove the errors-in-variables bias from a least-squares fit of the momentum model.

    The regressor is built from *measured* rates v + δv, and K is linear in v, so with white rate noise
    (standard deviations `sigma`, (nv,)) the normal equations are biased:
        E[GᵀG] = G₀ᵀG₀ + N_G,   E[Gᵀy] = G₀ᵀy₀ − N_y,
        N_G = Σ_t Σ_j σ_j² A_jᵀA_j,   N_y = Σ_t Σ_j σ_j² A_jᵀ b_j,
    with A_j = K_u(q_t, e_j) (unknown bodies' minimal columns at a unit rate j) and b_j = K_k(q_t, e_j) P_k (the
    known bodies' momentum at that rate).  Least squares therefore shrinks the estimate towards zero along the
    directions whose signal is weak next to that noise — for the Naveen, Shah, Misra robot the overall scale, which only
    the wheels' momentum anchors (about −0.05 % with the paper's noise).  Solving (GᵀG − N_G) φ = Gᵀy + N_y
    removes the bias (bias-compensated least squares).  GᵀG is recovered from the fit's covariance
    (σ̂² (GᵀG)⁻¹), and the N terms are expectations over smooth functions of q, so every `stride`-th sample
    suffices (scaled up by the stride)."""
    sigma = np.asarray(sigma, dtype=float)
    n, nv = fit.estimate.size, mp.model.nv
    if sigma.shape != (nv,) or np.any(sigma < 0) or not np.all(np.isfinite(sigma)):
        raise InputError(
            f"argument `rate_noise`: expected {nv} non-negative standard deviations, got shape {sigma.shape}"
        )
    active = np.flatnonzero(sigma > 0)
    N_G, N_y = np.zeros((n, n)), np.zeros(n)
    idx = np.arange(0, len(q), stride)
    kept = absolute_columns(mp)
    known_P = known_parameters(mp)
    for k in range(0, len(idx), chunk):
        qs = q[idx[k : k + chunk]]
        E = np.zeros((len(qs), len(active), nv))
        E[:, np.arange(len(active)), active] = 1.0
        from ..algorithms import momentum_regressor

        K = momentum_regressor(mp.model, np.repeat(qs, len(active), axis=0), E.reshape(-1, nv))  # (T·J, 6, 10·nb)
        A, b = K[..., kept], K @ known_P  # (T·J, 6, n), (T·J, 6)
        w = np.tile(sigma[active] ** 2, len(qs))[:, None, None]
        N_G += np.einsum("rki,rkj->ij", w * A, A)
        N_y += np.einsum("rki,rk->i", w * A, b)
    N_G *= len(q) / len(idx)
    N_y *= len(q) / len(idx)
    GtG = fit.sigma**2 * np.linalg.inv(fit.covariance)
    share = _noise_share(N_G, GtG)
    if share > MAX_NOISE_SHARE:
        what = "is numerically singular" if not np.isfinite(share) else f"is {share:.2g} rate noise by energy"
        warnings.warn(
            f"rate_noise: the regressor's least-excited direction {what} (limit {MAX_NOISE_SHARE}); "
            f"the first-order bias compensation would be unreliable there, so "
            "the plain least-squares estimate is returned. Excite the robot more (more or designed intervals).",
            stacklevel=3,
        )
        return replace(fit, method=fit.method + " (bias compensation skipped: noise-dominated direction)")
    M = GtG - N_G
    delta = np.linalg.solve(M, N_G @ fit.estimate + N_y)
    est = fit.estimate + delta
    cov = fit.sigma**2 * np.linalg.inv(M)
    return replace(
        fit,
        estimate=est,
        covariance=cov,
        std=np.sqrt(np.abs(np.diag(cov))),
        method=fit.method + " + errors-in-variables bias compensation",
    )


def _noise_share(N_G, GtG) -> float:
    """Largest generalized eigenvalue of (N_G, GᵀG): the share of the regressor's energy that the rate noise
    makes up in the worst direction (inf if GᵀG is numerically singular).  Column-scaled for accuracy."""
    d = 1.0 / np.sqrt(np.maximum(np.diag(GtG), 1e-300))
    try:
        L = np.linalg.cholesky(GtG * d[:, None] * d[None, :])
    except np.linalg.LinAlgError:
        return float("inf")
    Li = scipy.linalg.solve_triangular(L, np.eye(len(d)), lower=True)
    C = Li @ (N_G * d[:, None] * d[None, :]) @ Li.T
    return float(np.linalg.eigvalsh(0.5 * (C + C.T))[-1])


def _rate_sigmas(model, rate_noise) -> np.ndarray:
    """(nv,) rate-noise standard deviations from a per-component vector or a (lin, ang, joint) triple."""
    r = np.atleast_1d(np.asarray(rate_noise, dtype=float))
    bad = np.flatnonzero(~(r >= 0))  # negative or NaN: a standard deviation is a non-negative number
    if bad.size:
        k = int(bad[0])
        raise InputError(
            f"argument `rate_noise`: entry {k} is {r.flat[k]:g}; standard deviations must be zero or positive"
        )
    if r.shape == (model.nv,):
        return r
    if r.shape == (3,) and model.joint_types[0] == "free":
        return np.concatenate([np.full(3, r[0]), np.full(3, r[1]), np.full(model.nv - 6, r[2])])
    raise InputError(
        f"argument `rate_noise`: expected {model.nv} standard deviations or "
        f"(base linear, base angular, joint), got shape {r.shape}"
    )


def component_variances(mp, q, v, h, phi, chunk: int = 4096) -> np.ndarray:
    """(6,) mean square residual of each momentum component, h − K_min φ − known momentum, over the samples
    (computed in chunks so the stacked regressor is never formed whole)."""
    ss = np.zeros(6)
    for k in range(0, len(q), chunk):
        qs, vs = q[k : k + chunk], v[k : k + chunk]
        K, h_known = mp.regressor_and_known_momentum(qs, vs)
        r = h[k : k + chunk] - K @ phi - h_known
        ss += np.sum(r * r, axis=0)
    return ss / max(len(q), 1)


def _read(model, data, h0):
    if isinstance(data, (str, Path)):
        data = Telemetry.from_file(data, model)
    if not hasattr(data, "q") or not hasattr(data, "v"):
        raise InputError(
            f"argument `data`: expected a Trajectory, a Telemetry or a file path, got {type(data).__name__}"
        )
    q, v = np.asarray(data.q, dtype=float), np.asarray(data.v, dtype=float)
    if q.ndim != 2 or q.shape[1] != model.nq or v.shape != (len(q), model.nv):
        raise InputError(
            f"argument `data`: q/v have shapes {q.shape}/{v.shape}, "
            f"model '{model.name}' needs (T, {model.nq})/(T, {model.nv})"
        )
    h = getattr(data, "momentum", None)
    if h0 is not None:
        h0 = np.asarray(h0, dtype=float)
        if h0.shape != (6,):
            raise InputError(f"argument `h0`: expected 6 numbers [p; L], got shape {h0.shape}")
    if getattr(data, "wrench", None) is not None and (h is None or h0 is not None):
        h = data.integrated_momentum(h0)  # external impulses integrated from h0 (zero: released at rest)
    elif h is None or h0 is not None:
        h = np.tile(np.zeros(6) if h0 is None else h0, (len(q), 1))
    return np.asarray(data.t, dtype=float), q, v, np.asarray(h, dtype=float)


def _plot_errors(res: IdentificationResult, truth: np.ndarray, path: Path) -> None:
    from ..viz import pyplot

    plt = pyplot()

    k = np.arange(len(truth))
    scale = np.where(truth != 0, np.abs(truth), 1.0)
    rel = (res.estimate - truth) / scale * 100
    bar = res.std / scale * 100
    fig, ax = plt.subplots(figsize=(12, 4.5), constrained_layout=True)
    ax.errorbar(k + 1, rel, yerr=bar, fmt="o", ms=3, capsize=2, label="estimate − truth (± 1 std), % of |truth|")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_yscale("symlog", linthresh=0.1)
    ax.set_xlabel("minimal parameter index (Naveen, Shah, Misra Table 4 order for the closed form)")
    ax.set_ylabel("relative error [%]")
    ax.set_title(f"{res.mp.model.name}: identified minimal parameters")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def excitation_data(
    model,
    n_intervals: int = 64,
    dt: float = 1e-3,
    record_every: int = 1,
    noise: bool = True,
    seed: int = 0,
    progress: bool = False,
    spread: bool = True,
):
    """Simulated identification data for the Naveen, Shah, Misra robot, as the paper produces it (Sec. VI.A-C).

    The six arm joints and three wheels follow multi-interval cycloids (eqs. 28-31) from Table 3's seeds (wheels:
    start 0, range 3π), one 1-s interval per direction combination, the first `n_intervals` of the 256 (an
    un-designed trajectory: the excitation-design issue chooses and prunes them). The base floats from rest, so
    the total momentum stays zero. With `noise`, the paper's rate noise is added and poses are rebuilt from the
    noisy rates (Appendix C). Sampling every step (1 kHz by default) matters: rebuilding the poses from rates
    sampled at 100 Hz alone biases the estimate (0.012 % median, 0.9 % max relative error without any noise),
    at 1 kHz it does not. Returns (telemetry, trajectory)."""
    from .. import trajectories as tr

    arm, wheels = model.joints_tagged("arm_"), model.joints_tagged("wheel")
    if len(arm) != 6 or len(wheels) != 3:
        raise InputError(
            f"excitation_data needs the Naveen, Shah, Misra robot (6 arm joints tagged arm_*, 3 wheels); "
            f"'{model.name}' has {len(arm)} and {len(wheels)}"
        )
    start, range_ = tr.with_wheels(np.deg2rad(TABLE3_START_DEG), TABLE3_RANGE_RAD)
    all_dirs = tr.direction_combinations(9)
    if not 1 <= n_intervals <= len(all_dirs):
        raise InputError(f"n_intervals must be between 1 and {len(all_dirs)}, got {n_intervals}")
    pick = np.linspace(0, len(all_dirs) - 1, n_intervals).round().astype(int) if spread else np.arange(n_intervals)
    cyc = tr.Cycloidal(start, range_, all_dirs[pick])
    return trajectory_data(
        model, cyc, arm + wheels, dt=dt, record_every=record_every, noise=noise, seed=seed, progress=progress
    )


def trajectory_data(
    model,
    trajectory,
    joints,
    dt: float = 1e-3,
    record_every: int = 1,
    noise: bool = True,
    seed: int = 0,
    progress: bool = False,
):
    """Simulated identification data along any joint trajectory (e.g. a designed one, `freefloat excite`): the
    named joints follow it, the base floats with zero total momentum (its initial twist solved from the
    momentum model when the trajectory starts moving), the other joints rest.  With `noise`, Naveen, Shah, Misra's rate
    noise and pose rebuild (Appendix C).  Returns (telemetry, trajectory)."""
    from ..io import telemetry as tm
    from ..simulation import simulate_driven

    traj = simulate_driven(model, trajectory, joints, dt, record_every=record_every, progress=progress)
    telem = tm.from_trajectory(traj)
    if noise:
        telem = tm.add_noise(telem, model, np.random.default_rng(seed))
    return telem, traj
