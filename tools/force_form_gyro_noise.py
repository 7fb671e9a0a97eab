"""Force-form identification with a noisy gyro: the parameter error of the post-capture force form against the
gyro's noise density, with the angular accelerations from central differences or a Savitzky-Golay derivative of
the measured rates, and the momentum form (which needs no accelerations) beside them.

The built-in scenario `zhang2020_3d_thrusters` (the Zhang 2020 3-D capture with six thrusters draining a tank,
100 Hz telemetry) is simulated once; its gyro's noise density is then set to each level (1e-6 rad/s/√Hz: a
fibre-optic gyro; 1e-4 and 1e-3: MEMS-class) and the same run is measured (seeded) and identified by the
standard RLS of each form. The error is the RMS, over the base's mass, the target's mass and the target's
principal moments (m1, mn, Inxx, Inyy, Inzz), of the relative error of the final estimate against the truth at
that instant.

    python tools/force_form_gyro_noise.py [--duration 100] [--seeds 3] [--markdown]

prints the table docs/postcapture.md shows (median over the seeds, and the spread min-max).
"""

from __future__ import annotations

import argparse
import copy
import dataclasses
import re
import time

import numpy as np

import freefloat.postcapture as pc
from freefloat import models
from freefloat.io import data
from freefloat.postcapture.estimators import _target_index
from freefloat.postcapture.spacecraft import truth_history

COLS = ["m1", "mn", "Inxx", "Inyy", "Inzz"]
LEVELS = [1e-6, 1e-5, 1e-4, 1e-3]


def _sg(w: int, p: int) -> tuple:
    return (
        f"force, Savitzky-Golay w={w} p={p}",
        "force",
        {"accelerations": "savgol", "savgol_window": w, "savgol_polyorder": p},
    )


VARIANTS = [
    ("force, central differences", "force", {"accelerations": "central_difference"}),
    _sg(5, 2),
    _sg(11, 4),
    _sg(21, 4),
    _sg(21, 2),
    _sg(51, 2),
    ("momentum (no accelerations)", "momentum", {"accelerations": "central_difference"}),
]


def scenario(duration: float):
    text = data.read_text("scenarios", "zhang2020_3d_thrusters")
    text = re.sub(r"^duration: [\d.]+", f"duration: {duration}", text, count=1, flags=re.M)
    import tempfile
    from pathlib import Path

    p = Path(tempfile.mkdtemp()) / "zhang2020_3d_thrusters.yaml"
    p.write_text(text)
    return pc.load_scenario(p)


def error(m, sim, sc, level: float, method: str, measurement: dict, seed: int) -> float:
    sens = copy.deepcopy(sc.sensors)
    sens.sensors = [dict(s) for s in sens.sensors]
    for s in sens.sensors:
        if s["type"] == "gyro":
            s["noise_density"] = level
    s2 = dataclasses.replace(sc, sensors=sens, measurement={**sc.measurement, **measurement}, sensor_seed=seed)
    meas = pc.measure(m, sim, s2)
    res = pc.identify(m, meas, s2, methods=(method,))
    res.truth_history = truth_history(m, sim, False, _target_index(m))
    e = res.rel_error(method, "standard_rls")
    return float(np.sqrt(np.mean([e[res.names.index(c)] ** 2 for c in COLS])))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--duration", type=float, default=100.0)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--markdown", action="store_true")
    a = ap.parse_args()
    sc = scenario(a.duration)
    m = models.load(sc.model)
    t0 = time.perf_counter()
    sim = pc.simulate(sc, m)
    print(f"# simulated {a.duration:g} s in {time.perf_counter() - t0:.1f} s; seeds 0..{a.seeds - 1}")
    rows = []
    for name, method, meas in VARIANTS:
        cells = []
        for lvl in LEVELS:
            errs = [error(m, sim, sc, lvl, method, meas, seed) for seed in range(a.seeds)]
            cells.append((float(np.median(errs)), min(errs), max(errs)))
        rows.append((name, cells))
        if not a.markdown:
            print(name, " ".join(f"{c[0]:.3g} [{c[1]:.3g}, {c[2]:.3g}]" for c in cells), flush=True)
    if a.markdown:
        head = "| accelerations (gyro noise density, rad/s/√Hz →) | " + " | ".join(f"{x:.0e}" for x in LEVELS) + " |"
        print(head)
        print("|---|" + "---|" * len(LEVELS))
        for name, cells in rows:
            print(f"| {name} | " + " | ".join(f"{c[0]:.2%} ({c[1]:.2%}–{c[2]:.2%})" for c in cells) + " |")


if __name__ == "__main__":
    main()
