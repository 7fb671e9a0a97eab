"""Compare two sets of `results.json` files number by number (behaviour-unchanged checks).

    python benches/compare_results.py BEFORE_DIR AFTER_DIR [--rtol 1e-12]

Every `*/results.json` under BEFORE_DIR is matched with the same relative path under AFTER_DIR. Numbers
are compared with |a − b| <= rtol·max(|a|, |b|) (and exactly-equal zeros); strings and booleans must be
equal; keys whose name contains "time" and "seconds" or that sit under a "timings" entry are wall-clock
measurements and are reported apart, not compared. Prints every differing leaf with its relative
difference and a summary per file; exit status 1 if any compared number differs.
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


def compare(before: Path, after: Path, rtol: float) -> tuple[int, int, float, list]:
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
    ap.add_argument("--max-rows", type=int, default=40)
    a = ap.parse_args()
    status = 0
    for f in sorted(Path(a.before).glob("*/results.json")):
        g = Path(a.after) / f.relative_to(a.before)
        if not g.exists():
            print(f"{f.parent.name}: no results.json in {a.after}")
            status = 1
            continue
        bad, n, worst, rows = compare(f, g, a.rtol)
        print(f"{f.parent.name}: {n} numbers compared, {bad} differ beyond rtol {a.rtol:g}; largest relative difference {worst:.3g}")
        for k, what, r in rows[: a.max_rows]:
            print(f"    {k}: {what}" + (f"  (rel {r:.3g})" if r is not None else ""))
        if len(rows) > a.max_rows:
            print(f"    … {len(rows) - a.max_rows} more")
        status |= bad > 0
    return status


if __name__ == "__main__":
    sys.exit(main())
