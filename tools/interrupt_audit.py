"""Ctrl-C audit of the long-running `freefloat` commands: each is started on an input large enough to run for
minutes, sent SIGINT once its work is under way, and timed from the signal to its exit; what it left in its
output directory is listed.

    python tools/interrupt_audit.py [--only NAME ...] [--delay 0.5] [--json audit.json]

The signal goes `--delay` seconds after the command's first progress output on stderr (the import is done
and the work has started), or after `--fallback` seconds if it prints none. A command passes when it exits
within 1 s of the signal. Exit code 130 means the command kept what was finished and said so; 1 is click's
"Aborted!" (nothing partial to keep)."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from _helpers import sigint_when, start_cli  # noqa: E402  (the tests' Ctrl-C helper, one copy)

LIMIT = 1.0


def _scenario(tmp: Path, name: str, edit) -> str:
    """A built-in scenario with `edit(dict)` applied, written to tmp; returns its path."""
    from freefloat.io import data as shipped

    d = yaml.safe_load(shipped.read_text("scenarios", name))
    edit(d)
    p = tmp / f"{name}_long.yaml"
    p.write_text(yaml.safe_dump(d))
    return str(p)


def _campaign(tmp: Path) -> str:
    sc = _scenario(tmp, "zhang2020_2d_medium", lambda d: d.update(duration=600.0))
    spec = {
        "name": "audit",
        "kind": "postcapture",
        "scenario": sc,
        "grid": {"initial.base_velocity.0": list(range(50))},
    }
    p = tmp / "campaign.yaml"
    p.write_text(yaml.safe_dump(spec))
    return str(p)


def _run_file(tmp: Path) -> str:
    """A long simulated run for `freefloat measure`."""
    out = tmp / "run"
    subprocess.run(
        [sys.executable, "-m", "freefloat.cli", "simulate", "naveen_dual_arm", "--t-final", "300", "--out", str(out)],
        check=True,
        capture_output=True,
    )
    return str(out)


def _sensors(tmp: Path) -> str:
    p = tmp / "sensors.yaml"
    p.write_text("sensors:\n  - type: gyro\n    noise_density: 1.0e-5\n")
    return str(p)


def commands(tmp: Path) -> list[tuple[str, list[str]]]:
    o = lambda name: str(tmp / f"out_{name}")  # noqa: E731
    return [
        (
            "simulate",
            ["simulate", "naveen_dual_arm", "--t-final", "1e6", "--record-every", "100000", "--out", o("sim")],
        ),
        ("reactions", ["reactions", "naveen_dual_arm", "--t-final", "4e4", "--record-every", "1000", "--out", o("re")]),
        ("demo", ["demo", "--t-final", "4e4", "--out", o("demo")]),
        ("identify minimal", ["identify", "minimal", "naveen_dual_arm", "--simulate", "256", "--out", o("idm")]),
        (
            "identify postcapture",
            [
                "identify",
                "postcapture",
                _scenario(tmp, "zhang2020_2d_medium", lambda d: d.update(duration=2000.0)),
                "--no-sweep",
                "--out",
                o("pc"),
            ],
        ),
        (
            "identify cl",
            [
                "identify",
                "cl",
                _scenario(tmp, "valverde_ch9_two_arm", lambda d: d.update(duration=1.0e4)),
                "--no-sweep",
                "--out",
                o("cl"),
            ],
        ),
        ("excite", ["excite", "naveen_dual_arm", "--guess", "naveen_dual_arm_offset", "--out", o("ex")]),
        (
            "control adaptive",
            [
                "control",
                "adaptive",
                _scenario(tmp, "valverde_ch4_example_a", lambda d: d["simulation"].update(duration=1.0e5)),
                "--out",
                o("ad"),
            ],
        ),
        (
            "control ddp",
            ["control", "ddp", "valverde_ch8_tracking", "--max-iter", "100000", "--no-plots", "--out", o("ddp")],
        ),
        ("campaign", ["campaign", _campaign(tmp), "--out", o("camp"), "--workers", "1"]),
        ("measure", ["measure", _run_file(tmp), "--sensors", _sensors(tmp), "--out", o("meas")]),
    ]


def audit_one(name: str, argv: list[str], cwd: Path, delay: float, fallback: float) -> dict:
    t_start = time.monotonic()
    # the first progress output on stderr, or `fallback` seconds, then `delay` more
    r = sigint_when(start_cli(argv, cwd), None, delay, wait=fallback, exit_within=30, strict=False)
    if r.took is None:
        return {
            "command": name,
            "result": f"ended before the signal (exit {r.code})",
            "ok": None,
            "stderr": r.err[-800:],
        }
    took, sent = r.took, t_start + r.sent_after
    outs = sorted(
        str(f.relative_to(cwd)) for d in cwd.glob("out_*") for f in (d.rglob("*") if d.is_dir() else [d]) if f.is_file()
    )
    tail = [ln for ln in r.err.replace("\r", "\n").splitlines() if ln.strip()][-3:]
    return {
        "command": name,
        "signal_after_s": round(sent - t_start, 2),
        "exit_after_signal_s": round(took, 3),
        "exit_code": r.code,
        "ok": took < LIMIT,
        "kept": outs,
        "last_lines": tail,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", nargs="*", help="command names to audit (default: all)")
    ap.add_argument("--delay", type=float, default=0.5, help="seconds after the first progress output")
    ap.add_argument("--fallback", type=float, default=30.0, help="seconds to wait for progress output at most")
    ap.add_argument("--json", help="write the results here")
    a = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmpd:
        tmp = Path(tmpd)
        for name, argv in commands(tmp):
            if a.only and name not in a.only:
                continue
            cwd = tmp / name.replace(" ", "_")
            cwd.mkdir()
            # outputs relative to the command's own directory
            argv = [str(cwd / Path(x).name) if x.startswith(str(tmp / "out_")) else x for x in argv]
            r = audit_one(name, argv, cwd, a.delay, a.fallback)
            rows.append(r)
            print(json.dumps(r), flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))
    print("\n| command | exit after SIGINT | exit code | kept |\n|---|---|---|---|")
    for r in rows:
        if r.get("ok") is None:
            print(f"| {r['command']} | {r['result']} | | |")
            continue
        kept = ", ".join(Path(k).name for k in r["kept"]) or "nothing"
        print(f"| {r['command']} | {r['exit_after_signal_s']:.2f} s | {r['exit_code']} | {kept} |")


if __name__ == "__main__":
    main()
