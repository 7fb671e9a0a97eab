"""Check what an installed freefloat wrote, from outside the package (CI, after running it from an empty directory).

    python check_results.py SCENARIOS_TXT DEMO_RESULTS_JSON [POSTCAPTURE_RESULTS_JSON]

SCENARIOS_TXT is the output of `freefloat scenarios`; the JSON files are the `results.json` of `freefloat demo --out`
and `freefloat identify postcapture <scenario> --out`. The thresholds are the documented results with a margin, so
an install that finds no data, a wrong model or a broken estimator fails here.
"""

from __future__ import annotations

import json
import math
import sys


def fail(msg: str) -> None:
    print(f"check_results: FAIL: {msg}")
    sys.exit(1)


def finite(x, where: str) -> float:
    if not isinstance(x, (int, float)) or not math.isfinite(x):
        fail(f"{where} = {x!r} is not a finite number")
    return float(x)


def check_scenarios(path: str) -> None:
    lines = [
        ln for ln in open(path, encoding="utf-8").read().splitlines() if ln.strip() and not ln.startswith((" ", "#"))
    ]
    if len(lines) < 5:
        fail(
            f"`freefloat scenarios` listed {len(lines)} entries, expected the built-in ones (>= 5):\n"
            + "\n".join(lines)
        )
    print(f"check_results: {len(lines)} built-in scenarios listed")


def check_demo(path: str) -> None:
    d = json.load(open(path, encoding="utf-8"))
    drift = finite(d["momentum_drift_angular_rel"], "demo momentum_drift_angular_rel")
    if drift > 1e-10:
        fail(f"demo: momentum not conserved (relative drift {drift:.3g})")
    ident = d["identification"]
    if len(ident["estimate"]) != 52:
        fail(f"demo: {len(ident['estimate'])} minimal parameters identified, expected 52")
    med = finite(ident["median_rel_error_pct"], "demo identification median error")
    mx = finite(ident["max_rel_error_pct"], "demo identification max error")
    if med > 0.05 or mx > 2.0:  # documented: median 0.005 %, max 0.18 %
        fail(f"demo: identification errors median {med:.3g} %, max {mx:.3g} % exceed 0.05 % / 2 %")
    rms = d["prediction"]["rms_torque"]
    worst = max(finite(v, f"demo prediction rms_torque.{k}") for k, v in rms.items())
    if worst > 0.01:  # documented: 2e-5 to 4e-4 N m
        fail(f"demo: prediction torque RMS {worst:.3g} N m exceeds 0.01")
    print(f"check_results: demo ok (drift {drift:.2g}, median {med:.3g} %, max {mx:.3g} %, torque RMS <= {worst:.2g})")


def check_postcapture(path: str) -> None:
    d = json.load(open(path, encoding="utf-8"))
    n = 0
    for method, solvers in d["methods"].items():
        for solver, params in solvers.items():
            for name, p in params.items():
                err = finite(p["error"], f"postcapture {method}/{solver}/{name} error")
                if err > 1e-3:  # the noise-free scenarios converge well inside the paper's 0.1 % tolerance
                    fail(f"postcapture {method}/{solver}: {name} error {err:.3g} > 1e-3")
                n += 1
    if n < 8:
        fail(f"postcapture: only {n} parameter estimates in {path}")
    print(f"check_results: post-capture ok ({n} estimates within 1e-3)")


def main(argv: list[str]) -> None:
    if len(argv) not in (3, 4):
        fail(__doc__)
    check_scenarios(argv[1])
    check_demo(argv[2])
    if len(argv) == 4:
        check_postcapture(argv[3])


if __name__ == "__main__":
    main(sys.argv)
