"""Studies around the Valverde 2018 ch. 9 reproduction: accuracy and run time against N_s (Figs. 9.5-9.6),
measurement noise (Remark 16: the reaction wrenches must be measured), and the same robot and motion identified by
freefloat's momentum least squares (the minimal-parameter route, `identify_minimal`) for comparison."""

from __future__ import annotations

import time

import numpy as np

from .._core import InputError
from .concurrent import ClScenario, load_scenario, parameter_scales, run

__all__ = ["NOISE_GAINS", "compare_ls", "noise_study", "ns_sweep"]


def _scenario(sc) -> ClScenario:
    return sc if isinstance(sc, ClScenario) else load_scenario(sc)


def ns_sweep(scenario, ns_values=(10, 50, 100, 200, 300), repeats: int = 3, progress=None) -> list[dict]:
    """Fig. 9.5 (sup over 9.7-10 s of the largest relative error) and Fig. 9.6 (wall-clock time of the whole
    10 s run, median/min/max of `repeats` runs interleaved over the N_s values)."""
    sc = _scenario(scenario)
    times = {ns: [] for ns in ns_values}
    last = {}
    for _ in range(max(1, repeats)):
        for ns in ns_values:
            t0 = time.perf_counter()
            r = run(sc, ns=ns)
            times[ns].append(time.perf_counter() - t0)
            last[ns] = r
            if progress is not None:
                progress()
    out = []
    for ns in ns_values:
        r = last[ns]
        d = r.to_dict()
        out.append(
            {
                "ns": ns,
                "sup_error_9p7_to_10s": d["sup_error_9p7_to_10s"],
                "tail_decay_rate_per_s": d["error_decay_rate_last_3s"],
                "max_final_relative_error": d["max_final_relative_error"],
                "time_within_1pct_s": d["time_within_1pct_s"],
                "rank_final": d["rank_final"],
                "singular_values_constant_after_s": d["singular_values_constant_after_s"],
                "stack_trials": d["stack_trials"],
                "run_time_s_median": float(np.median(times[ns])),
                "run_time_s_min": float(np.min(times[ns])),
                "run_time_s_max": float(np.max(times[ns])),
                "repeats": len(times[ns]),
            }
        )
    return out


#: the three estimation laws the noise study compares: the plain law (9.15) throughout, the thesis' SVD gain
#: (9.27) from T_th,2, and the truncated SVD gain (9.27')
NOISE_GAINS = ("plain", "thesis", "truncated")


def noise_study(
    scenario,
    wrench_levels=(),
    rate_levels=(),
    seed: int | None = None,
    progress=None,
    *,
    seeds=None,
    gains=NOISE_GAINS,
    kappa: float | None = None,
) -> list[dict]:
    """Final accuracy with joint force/torque noise and with body-rate noise, for the plain law (9.15), the thesis'
    SVD gain (9.27) and the truncated gain (9.27') side by side: where the thesis gain helps (it makes the weak modes
    converge), where it hurts (it drives them to a least-squares value whose noise is σ/s_i) and what the truncated
    gain keeps of each.

    `seeds`: noise seeds to repeat every run with (default: `seed`, else the scenario's `noise_seed`). Per
    (kind, level, gain) row: the largest relative error over the seeds and the 77 parameters, the median over them,
    the median over the seeds of each run's largest error, the largest mass error, the fewest realisable bodies and
    (truncated gain) the weak directions withheld, summed over the bodies, largest over the seeds."""
    import warnings

    sc = _scenario(scenario)
    if seeds is None:
        seeds = [sc.noise_seed if seed is None else seed]
    seeds = [int(s) for s in seeds]
    if not seeds:
        raise InputError("argument `seeds`: at least one noise seed")
    for g in gains:
        if g not in NOISE_GAINS:
            raise InputError(f"argument `gains`: unknown gain {g!r} (one of {', '.join(NOISE_GAINS)})")
    rows = []
    for kind, levels in (("wrench", wrench_levels), ("rate", rate_levels)):
        for lvl in levels:
            for g in gains:
                kw = {"wrench_noise": lvl} if kind == "wrench" else {"rate_noise": lvl}
                if g == "plain":
                    kw["aggressive"] = False
                else:
                    kw.update(aggressive=True, gain=g)
                    if g == "truncated" and kappa is not None:
                        kw["kappa"] = kappa
                rels, maxima, masses, real, withheld = [], [], [], [], []
                for s in seeds:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        r = run(sc, noise_seed=s, **kw)
                    rel = np.abs(r.final_estimate - r.truth) / parameter_scales(r.truth)
                    rels.append(rel)
                    maxima.append(float(rel.max()))
                    masses.append(float(rel.reshape(-1, 7)[:, 6].max()))
                    real.append(int(sum(r.realisable)))
                    withheld.append(int(sum(r.gain_withheld)))
                    if progress is not None:
                        progress()
                rows.append(
                    {
                        "kind": kind,
                        "level": lvl,
                        "gain": g,
                        "aggressive": g != "plain",
                        "seeds": seeds,
                        "max_final_relative_error": float(np.max(maxima)),
                        "median_final_relative_error": float(np.median(np.concatenate(rels))),
                        "median_max_final_relative_error": float(np.median(maxima)),
                        "max_mass_relative_error": float(np.max(masses)),
                        "all_within_1pct": bool(np.max(maxima) <= 0.01),
                        "realisable_bodies": int(min(real)),
                        "withheld_directions": int(max(withheld)),
                    }
                )
    return rows


def compare_ls(scenario, rate_levels=(0.0,), seed: int = 7, known=("base",)) -> dict:
    """The same robot and motion identified by freefloat's momentum least squares (`identify_minimal`, numeric
    minimal parameters), side by side with concurrent learning.

    With the robot released at rest and no external wrench the total momentum is zero throughout, so momentum
    LS only sees the parameters up to a common scale: one body must be known (`known`, the base by default)
    to fix it. LS then identifies the identifiable combinations of the other bodies' standard parameters; the CL
    estimate (77 parameters with known CoMs) is mapped to the same combinations to compare accuracy. Rate noise
    goes on the joint rates and base twist LS reads (CL gets the same σ on its body twists and rates)."""
    import warnings

    from .. import simulation
    from .._core import inertia_standard_form
    from ..io import telemetry as tm
    from .identify import identify_minimal

    sc = _scenario(scenario)
    m = sc.model
    exc = {"amplitude": 0.5, "frequency": 1.0, "phase": 0.0, "t_start": 2.0, "t_end": 3.0, **sc.excitation}
    nb = m.nvs[0]

    def tau(t, q, v):
        u = np.zeros(m.nv)
        if exc["t_start"] <= t <= exc["t_end"]:
            u[nb:] = exc["amplitude"] * np.sin(exc["frequency"] * t + exc["phase"])
        return u

    traj = simulation.simulate(m, sc.q0, sc.v0, sc.duration, sc.dt, torques=tau, formulation="dq")
    P = m.parameters()
    coms = P[:, 1:4] / P[:, [0]]
    levels = []
    for lvl in rate_levels:
        telem = tm.from_trajectory(traj)
        if lvl > 0:
            telem = tm.add_noise(
                telem,
                m,
                np.random.default_rng(seed),
                sigma_lin=lvl,
                sigma_ang=lvl,
                sigma_joint=lvl,
                reconstruct_poses=False,
            )
        ls = identify_minimal(m, telem, known=list(known), method="numeric")
        truth_min = ls.truth_values(m)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cl = run(sc, rate_noise=lvl, noise_seed=seed)
        v = cl.final_estimate.reshape(-1, 7)
        inertia = np.array([[[a[0], a[1], a[2]], [a[1], a[3], a[4]], [a[2], a[4], a[5]]] for a in v])
        p_cl = inertia_standard_form(np.ascontiguousarray(v[:, 6]), np.ascontiguousarray(coms), inertia)
        cl_min = ls.mp.from_standard(p_cl)
        scale = np.where(
            np.abs(truth_min) > 1e-9 * np.max(np.abs(truth_min)), np.abs(truth_min), np.max(np.abs(truth_min))
        )
        levels.append(
            {
                "rate_noise": lvl,
                "ls_rel_errors": ((ls.estimate - truth_min) / scale).tolist(),
                "cl_rel_errors": ((cl_min - truth_min) / scale).tolist(),
                "ls_max_rel_error": float(np.max(np.abs(ls.estimate - truth_min) / scale)),
                "cl_max_rel_error_on_combinations": float(np.max(np.abs(cl_min - truth_min) / scale)),
                "cl_max_rel_error_77": cl.to_dict()["max_final_relative_error"],
                "ls_condition_number": float(ls.fit.condition_number),
            }
        )
    return {
        "ls_known_bodies": list(known),
        "ls_identifiable_combinations": len(ls.names),
        "ls_combination_names": list(ls.names),
        "cl_parameters": int(7 * m.nbodies),
        "needs": {
            "concurrent_learning": "every body's twist and twist rate (accelerations), every joint's 6-axis "
            "force/torque (reaction + actuation), the CoM locations; identifies all 7 mass properties of every body",
            "momentum_least_squares": "joint rates and base twist only (no accelerations, no force sensors), one known "
            "body or a known external impulse for the scale; identifies the identifiable combinations of the "
            "standard parameters (mass, first moments, inertias about the joints)",
        },
        "levels": levels,
    }
