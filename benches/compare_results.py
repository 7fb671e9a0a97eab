"""Compare two sets of `results.json` files number by number (behaviour-unchanged checks).

    python benches/compare_results.py BEFORE_DIR AFTER_DIR [--rtol 1e-12]

Every `results.json` under BEFORE_DIR (any depth) is matched with the same relative path under AFTER_DIR. Numbers
are compared with |a − b| <= rtol·max(|a|, |b|) (and exactly-equal zeros); strings and booleans must be
equal. Three kinds of leaves are treated apart:
- wall-clock measurements (keys with "timings", "seconds", "elapsed", "wall") are not compared;
- relative errors (a key `error`, or under `errors`) are themselves differences of nearly equal numbers
  (estimate − truth, divided by truth), so they are compared absolutely: |a − b| <= --error-atol;
- `equation_residuals_at_truth` entries other than the `*_scale` ones are round-off by construction (the
  largest residual of an equation that holds exactly); they are compared to their scale:
  |a − b| <= rtol_residual · scale (--residual-rtol).
Prints every differing leaf and a summary per file; exit status 1 if any compared number differs.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

WALL_CLOCK = ("timings", "timing", "seconds", "elapsed", "wall")


def is_wall_clock(path: str) -> bool:
    return any(w in path.lower() for w in WALL_CLOCK)


def leaves(x, path=""):
    if isinstance(x, dict):
        for k, v in x.items():
            yield from leaves(v, f"{path}/{k}")
    elif isinstance(x, list):
        for i, v in enumerate(x):
            yield from leaves(v, f"{path}[{i}]")
    else:
        yield path, x


def rel(a: float, b: float) -> float:
    if a == b:
        return 0.0
    if math.isnan(a) and math.isnan(b):
        return 0.0
    s = max(abs(a), abs(b))
    return abs(a - b) / s if s > 0 else 0.0


def is_error(path: str) -> bool:
    return path.endswith("/error") or "/errors/" in path


def residual_scale(path: str, table: dict):
    if "equation_residuals_at_truth" not in path or path.endswith("_scale"):
        return None
    head, name = path.rsplit("/", 1)
    return table.get(f"{head}/{name.replace('paper_', 'paper_')}_scale")


def compare(before: Path, after: Path, rtol: float, error_atol: float = 1e-12,
            residual_rtol: float = 1e-13) -> tuple[int, int, float, list]:
    A = dict(leaves(json.loads(before.read_text())))
    B = dict(leaves(json.loads(after.read_text())))
    bad, compared, worst, rows = 0, 0, 0.0, []
    for k in sorted(set(A) | set(B)):
        if is_wall_clock(k):
            continue
        if k not in A or k not in B:
            bad += 1
            rows.append((k, "missing in " + ("before" if k not in A else "after"), None))
            continue
        a, b = A[k], B[k]
        if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
            compared += 1
            scale = residual_scale(k, A)
            if scale is not None:
                if abs(a - b) > residual_rtol * scale:
                    bad += 1
                    rows.append((k, f"{a!r} -> {b!r} (scale {scale:.3g})", abs(a - b) / scale))
                continue
            if is_error(k):
                if abs(a - b) > error_atol:
                    bad += 1
                    rows.append((k, f"{a!r} -> {b!r} (absolute difference {abs(a - b):.3g})", None))
                continue
            r = rel(float(a), float(b))
            worst = max(worst, r)
            if r > rtol:
                bad += 1
                rows.append((k, f"{a!r} -> {b!r}", r))
        elif a != b:
            bad += 1
            rows.append((k, f"{a!r} -> {b!r}", None))
    return bad, compared, worst, rows


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--rtol", type=float, default=1e-12)
    ap.add_argument("--error-atol", type=float, default=1e-12)
    ap.add_argument("--residual-rtol", type=float, default=1e-13)
    ap.add_argument("--max-rows", type=int, default=40)
    a = ap.parse_args()
    status = 0
    for f in sorted(Path(a.before).rglob("results.json")):
        g = Path(a.after) / f.relative_to(a.before)
        if not g.exists():
            print(f"{f.parent.relative_to(a.before)}: no results.json in {a.after}")
            status = 1
            continue
        bad, n, worst, rows = compare(f, g, a.rtol, a.error_atol, a.residual_rtol)
        print(f"{f.parent.relative_to(a.before)}: {n} numbers compared, {bad} differ beyond the tolerances; largest relative difference of the others {worst:.3g}")
        for k, what, r in rows[: a.max_rows]:
            print(f"    {k}: {what}" + (f"  (rel {r:.3g})" if r is not None else ""))
        if len(rows) > a.max_rows:
            print(f"    … {len(rows) - a.max_rows} more")
        status |= bad > 0
    return status


if __name__ == "__main__":
    sys.exit(main())
