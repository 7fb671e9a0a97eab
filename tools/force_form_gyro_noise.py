"""Force-form identification with a noisy gyro: the parameter error of the post-capture force form against the
gyro's noise density, with the angular accelerations from central differences, a Savitzky-Golay derivative of
the measured rates or their RTS smoother, and the momentum form (which needs no accelerations) beside them,
about the inertial origin (the paper's eqs. 9-10) and about the moving base point (the default); the poses
integrated from the rates by the trapezoid (the default) or the fourth-order Hermite rule.

Two built-in scenarios, each simulated once: `zhang2020_3d` (the paper's 3-D capture, its ideal jets: the momentum
form holds) given the 100 Hz gyro, base-velocity and tachometer telemetry of `zhang2020_3d_thrusters`, and
`zhang2020_3d_thrusters` itself (thrusters draining a tank: the momentum form does not hold there, so only the
force form is shown). The gyro's noise density is set to each level (1e-6 rad/s/√Hz: a fibre-optic gyro; 1e-5:
tactical grade; 1e-4 and 1e-3: MEMS-class), the same run is measured (seeded) and identified by the standard RLS
of each form. The error is the RMS, over the base's mass, the target's mass and the target's principal moments
(m1, mn, Inxx, Inyy, Inzz), of the relative error of the final estimate against the truth at that instant.

    python tools/force_form_gyro_noise.py [--duration 100] [--seeds 3]

prints the tables docs/postcapture.md shows (median over the seeds, and the spread min-max).
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
from freefloat.postcapture.estimators import target_index
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
    ("force, exact accelerations (reference)", "force", {"accelerations": "exact"}),
    ("force, central differences", "force", {"accelerations": "central_difference"}),
    _sg(5, 2),
    _sg(11, 4),
    _sg(21, 3),
    _sg(21, 2),
    _sg(51, 2),
    ("force, RTS smoother (GCV bandwidth)", "force", {"accelerations": "rts"}),
    ("force, RTS smoother, Hermite poses", "force", {"accelerations": "rts", "integration": "hermite"}),
    ("momentum about the origin (the paper's eqs. 9-10)", "momentum", {"momentum_point": "origin"}),
    ("momentum about the base point (default)", "momentum", {"momentum_point": "base"}),
    ("momentum about the base point, Hermite poses", "momentum", {"momentum_point": "base", "integration": "hermite"}),
]


def scenario(name: str, duration: float):
    """The built-in scenario `name` shortened to `duration`; `zhang2020_3d` gets the sensors and telemetry blocks of
    `zhang2020_3d_thrusters` (and central differences), so that both forms read the same kind of telemetry."""
    import tempfile
    from pathlib import Path

    text = data.read_text("scenarios", name)
    text = re.sub(r"^duration: [\d.]+", f"duration: {duration}", text, count=1, flags=re.M)
    if name == "zhang2020_3d":
        thr = data.read_text("scenarios", "zhang2020_3d_thrusters")
        text += thr[thr.index("\nsensors:") :]
    p = Path(tempfile.mkdtemp()) / f"{name}.yaml"
    p.write_text(text)
    sc = pc.load_scenario(p)
    if name == "zhang2020_3d":  # the thruster scenario's measurement (the variants set the momentum point)
        sc = dataclasses.replace(sc, measurement={"accelerations": "central_difference"})
    return sc


def _with(sc, level: float, measurement: dict, seed: int):
    """The scenario with the gyro at `level`, the measurement settings, and `integration` (a variant's key for the
    telemetry's pose rule, not a measurement setting) on the sensor set."""
    measurement = dict(measurement)
    sens = dataclasses.replace(copy.deepcopy(sc.sensors), integration=measurement.pop("integration", "trapezoid"))
    sens.sensors = [dict(s) for s in sens.sensors]
    for s in sens.sensors:
        if s["type"] == "gyro":
            s["noise_density"] = level
    mode = {k: v for k, v in sc.measurement.items() if not k.startswith("savgol") and k != "momentum_point"}
    return dataclasses.replace(sc, sensors=sens, measurement={**mode, **measurement}, sensor_seed=seed)


def acceleration_bias(m, sim, sc, measurement: dict) -> float:
    """RMS error of the derived accelerations (every coordinate) against the exact ones with a noiseless gyro:
    what the derivative itself costs on this motion."""
    if measurement["accelerations"] == "exact":
        return 0.0
    exact = pc.measure(m, sim, _with(sc, 0.0, {"accelerations": "exact"}, 0))
    r = pc.measure(m, sim, _with(sc, 0.0, measurement, 0))
    i = np.searchsorted(exact.t, r.t)
    return float(np.sqrt(np.mean((r.ddq - exact.ddq[i]) ** 2)))


def error(m, sim, sc, level: float, method: str, measurement: dict, seed: int) -> float:
    s2 = _with(sc, level, measurement, seed)
    meas = pc.measure(m, sim, s2)
    res = pc.identify(m, meas, s2, methods=(method,))
    res.truth_history = truth_history(m, sim, False, target_index(m))
    return res.rms_rel_error(method, "standard_rls", COLS)


def study(name: str, duration: float, seeds: int, variants) -> list:
    sc = scenario(name, duration)
    m = models.load(sc.model)
    t0 = time.perf_counter()
    sim = pc.simulate(sc, m)
    print(f"# {name}: simulated {duration:g} s in {time.perf_counter() - t0:.1f} s; seeds 0..{seeds - 1}", flush=True)
    rows = []
    for label, method, meas in variants:
        cells = []
        for lvl in LEVELS:
            errs = [error(m, sim, sc, lvl, method, meas, seed) for seed in range(seeds)]
            cells.append((float(np.median(errs)), min(errs), max(errs)))
        bias = acceleration_bias(m, sim, sc, meas) if method == "force" else None
        rows.append((label, cells, bias))
        print(f"{label:40s}", " ".join(f"{c[0]:.3g} [{c[1]:.3g}, {c[2]:.3g}]" for c in cells), bias, flush=True)
    for point in ("origin", "base") if any(v[1] == "momentum" for v in variants) else ():
        # the momentum form's floor: the true states at the samples (no sensors)
        s0 = dataclasses.replace(sc, sensors=None, measurement={"accelerations": "exact", "momentum_point": point})
        res = pc.identify(m, pc.measure(m, sim, s0), s0, methods=("momentum",))
        res.truth_history = truth_history(m, sim, False, target_index(m))
        floor = res.rms_rel_error("momentum", "standard_rls", COLS)
        label = f"momentum about the {point}{' point' if point == 'base' else ''}, true states (no sensors; reference)"
        rows.append((label, [(floor, floor, floor)] * len(LEVELS), None))
        print(label, floor, flush=True)
    return rows


def markdown(title: str, rows) -> str:
    out = [
        f"{title}",
        "",
        "| form, accelerations \\ gyro N [rad/s/√Hz] | "
        + " | ".join(f"{x:.0e}" for x in LEVELS)
        + " | derivative's own error (rms, noiseless gyro) |",
    ]
    out.append("|---|" + "---|" * (len(LEVELS) + 1))
    for label, cells, bias in rows:
        b = "" if bias is None else f"{bias:.2g}"
        out.append(f"| {label} | " + " | ".join(f"{c[0]:.2g} ({c[1]:.2g}–{c[2]:.2g})" for c in cells) + f" | {b} |")
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--duration", type=float, default=100.0)
    ap.add_argument("--seeds", type=int, default=3)
    a = ap.parse_args()
    plain = study("zhang2020_3d", a.duration, a.seeds, VARIANTS)
    thr = study("zhang2020_3d_thrusters", a.duration, a.seeds, [v for v in VARIANTS if v[1] == "force"])
    print()
    print(markdown("zhang2020_3d with the gyro, base-velocity and tachometer telemetry (100 Hz), λ = 1:", plain))
    print()
    print(markdown("zhang2020_3d_thrusters (thrusters, depletion), λ = 0.99, force form only:", thr))


if __name__ == "__main__":
    main()
