"""Does excitation design pay? Identification errors along a designed trajectory, along as many un-designed
intervals and along the un-pruned first step, with the paper's rate noise (Naveen, Shah, Misra, Table 5)."""

from __future__ import annotations

import numpy as np

from .._core import NumericalError
from ..constants import PAPER_RATE_NOISE


def compare(
    true_model, result, seeds=(0,), rate_noise=PAPER_RATE_NOISE, progress: bool = False, extra: dict | None = None
) -> dict:
    """Identify `true_model`'s minimal parameters with the paper's rate noise along (a) the designed trajectory,
    (b) the same number of un-designed intervals — the first K direction combinations with arbitrary seeds
    (mid-range start, half the maximal range, scaled into the limits) — and (c) the un-pruned step-1 trajectory
    over all combinations (the paper's Table 5 argument).  Errors per case: median and max relative error in
    percent (eqs. 38-39) of plain least squares and of the bias-compensated estimate, averaged over `seeds`.
    `extra`: more named trajectories (driving `design.joints`) to compare, e.g. the Fourier baseline."""
    from .identify import identify_minimal, trajectory_data

    d = result.design
    K = len(result.directions)
    first = d.all_directions[:K]
    cases = {
        f"designed ({K} intervals)": result.trajectory(),
        f"un-designed, first {K} combinations": d.cycloid(d.feasible_start(first), first),
        f"un-pruned step 1 ({d.n_intervals} intervals)": d.cycloid(result.step1.x, d.all_directions),
    }
    cases.update(extra or {})  # e.g. {"Fourier baseline": trajectory}
    out = {}
    for name, traj in cases.items():
        rows = []
        for s in seeds:
            telem, _ = trajectory_data(true_model, traj, d.joints, seed=s, progress=progress)
            row = {"duration_s": traj.duration}
            # plain least squares on purpose ('none': no warning that the declared noise is left in)
            for label, kw in (("ls", {"rate_noise": "none"}), ("bias_compensated", {"rate_noise": rate_noise})):
                try:
                    r = identify_minimal(true_model, telem, **kw)
                    e = r.errors(true_model)
                    row.update(
                        {
                            f"{label}_median_pct": e["median_rel_error_pct"],
                            f"{label}_max_pct": e["max_rel_error_pct"],
                            "condition_number": r.fit.condition_number,
                        }
                    )
                except NumericalError as err:  # unexcited parameters: say so instead of a number
                    row.update(
                        {
                            f"{label}_median_pct": float("nan"),
                            f"{label}_max_pct": float("nan"),
                            "error": str(err).splitlines()[0],
                        }
                    )
            rows.append(row)
        out[name] = {
            k: float(np.mean([r[k] for r in rows])) if isinstance(rows[0][k], float) else rows[0][k] for k in rows[0]
        }
    return out


def comparison_table(cmp: dict) -> str:
    lines = [
        f"{'trajectory':40s} {'duration':>9s} {'κ(true)':>9s} {'LS median':>10s} {'LS max':>10s} "
        f"{'BC median':>10s} {'BC max':>10s}"
    ]
    for name, r in cmp.items():
        lines.append(
            f"{name:40s} {r['duration_s']:8.0f}s {r.get('condition_number', float('nan')):9.4g} "
            f"{r['ls_median_pct']:9.4g}% {r['ls_max_pct']:9.4g}% {r['bias_compensated_median_pct']:9.4g}% "
            f"{r['bias_compensated_max_pct']:9.4g}%"
        )
    lines.append(
        "LS: least squares; BC: with the errors-in-variables bias removed (docs/identification.md); "
        "paper Table 5 Case 1: 2.08 % / 174 %"
    )
    return "\n".join(lines)
