"""The HTML reports in a real browser (issue 15): headless Chromium (Debian's `chromium`, installed by .ci/run)
opens the report of `freefloat demo --out`, of `freefloat identify postcapture --out` and of a campaign, with no
network; no console errors; every Plotly figure rendered (SVG drawn, WebGL canvas for the 3D view); a screenshot
meets a loose expectation (not blank, dark title text at the top, coloured plot pixels).

Skipped with the reason when no chromium is installed locally; CI installs it, so there it runs."""

from __future__ import annotations

import html as html_lib
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

CHROMIUM = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)
needs_chromium = pytest.mark.skipif(
    CHROMIUM is None and not os.environ.get("CI"),
    reason="headless Chromium not installed (apt-get install chromium; CI installs it and runs these tests)",
)
pytestmark = [pytest.mark.slow, needs_chromium]

#: injected before the report's own scripts: collects uncaught errors and console.error calls, and after load
#: writes them and the rendering counts into the DOM for --dump-dom
PROBE = """<script>
window.__errors = [];
window.addEventListener('error', function (e) { window.__errors.push('error: ' + e.message); });
(function () { var ce = console.error; console.error = function () {
  window.__errors.push('console.error: ' + Array.prototype.join.call(arguments, ' '));
  ce.apply(console, arguments); }; })();
window.addEventListener('load', function () { setTimeout(function () {
  var plots = document.querySelectorAll('.js-plotly-plot'), drawn = 0, gl = 0, marks = 0;
  plots.forEach(function (p) {
    if (p.querySelector('svg.main-svg')) drawn++;
    if (p.querySelector('canvas')) gl++;
    marks += p.querySelectorAll('.trace, .point, .hm, path.box, .bars').length;
  });
  var out = document.createElement('pre'); out.id = '__probe';
  out.textContent = JSON.stringify({errors: window.__errors, plots: plots.length, drawn: drawn, gl: gl,
    marks: marks, figures: document.querySelectorAll('div.plot').length});
  document.body.appendChild(out); }, 4000); });
</script>"""


def _open(report: Path, tmp: Path, height: int = 2400) -> tuple[dict, list[str], Path]:
    """Open `report` in headless Chromium: (probe result, console lines of level error, screenshot path)."""
    assert CHROMIUM, "chromium is required here (CI installs it in .ci/run's tools stage)"
    html = report.read_text(encoding="utf-8")
    probed = tmp / f"probed-{report.parent.name}.html"
    probed.write_text(html.replace("<head>", "<head>" + PROBE, 1), encoding="utf-8")
    shot = tmp / f"shot-{report.parent.name}.png"
    common = [
        CHROMIUM,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--enable-logging=stderr",
        "--v=0",
        "--no-first-run",
        "--disable-extensions",
        f"--user-data-dir={tmp / 'chromium-profile'}",
        "--virtual-time-budget=20000",
        f"--window-size=1280,{height}",
    ]
    r = subprocess.run([*common, "--dump-dom", probed.as_uri()], capture_output=True, text=True, timeout=180)
    m = re.search(r'<pre id="__probe">(.*?)</pre>', r.stdout, re.S)
    assert m, f"the page did not finish loading in Chromium: {r.stderr[-2000:]}"
    probe = json.loads(html_lib.unescape(m.group(1)))
    console = [
        ln
        for ln in r.stderr.splitlines()
        if "CONSOLE" in ln and ("Uncaught" in ln or "Error" in ln or "error" in ln.split("CONSOLE", 1)[1][:40])
    ]
    s = subprocess.run([*common, f"--screenshot={shot}", report.as_uri()], capture_output=True, text=True, timeout=180)
    assert shot.is_file(), f"no screenshot: {s.stderr[-2000:]}"
    return probe, console, shot


def _check_screenshot(shot: Path):
    """Loose expectation of a report's first screen: a white page with dark title text at the top and coloured
    plot marks below (not blank, not an error page, not unstyled)."""
    import matplotlib.image as mpimg

    img = mpimg.imread(shot)[..., :3].astype(float)  # (H, W, 3) in [0, 1]
    h, w, _ = img.shape
    assert w == 1280 and h >= 1000
    lum = img.mean(axis=2)
    assert np.median(lum) > 0.9, "the page background is not white"
    top = lum[:80]
    assert (top < 0.3).mean() > 0.002, "no dark title text at the top"
    sat = img.max(axis=2) - img.min(axis=2)
    coloured = (sat > 0.25).mean()
    assert 0.003 < coloured < 0.6, f"coloured plot pixels {coloured:.4f}: plots missing (or a page of colour)"


def _check(report: Path, tmp: Path, min_figures: int, gl: int = 0):
    html = report.read_text(encoding="utf-8")
    # self-contained: no script or stylesheet fetched from the network
    assert not re.search(r"<script[^>]+src=|<link[^>]+href=[\"']https?:", html)
    probe, console, shot = _open(report, tmp)
    assert probe["errors"] == [], probe["errors"]
    assert console == [], console
    assert probe["figures"] >= min_figures and probe["plots"] == probe["figures"]
    assert probe["drawn"] == probe["plots"], probe  # every figure drew its SVG layers
    assert probe["marks"] >= probe["plots"], probe  # and traces in them
    assert probe["gl"] >= gl, probe  # the 3D view drew into a WebGL canvas
    _check_screenshot(shot)


def _ff(*args, cwd):
    r = subprocess.run([sys.executable, "-m", "freefloat", *args], cwd=cwd, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    return r.stdout


def test_demo_report_in_chromium(demo_run, tmp_path):
    cwd, out, _ = demo_run
    _ff("report", str(out), cwd=cwd)
    _check(out / "report.html", tmp_path, min_figures=3, gl=1)  # motion, 3D view, parameter errors


def test_postcapture_report_in_chromium(tmp_path):
    from freefloat import data

    d = yaml.safe_load(data.read_text("scenarios", "zhang2020_2d_medium"))
    d["duration"] = 3.0
    (tmp_path / "short.yaml").write_text(yaml.safe_dump(d))
    _ff("identify", "postcapture", "short.yaml", "--out", "pc", cwd=tmp_path)
    _ff("report", "pc", cwd=tmp_path)
    _check(tmp_path / "pc" / "report.html", tmp_path, min_figures=2)


def test_campaign_report_in_chromium(tmp_path):
    spec = {
        "name": "report_check",
        "kind": "postcapture",
        "scenario": "zhang2020_2d_sweep",
        "set": {"duration": 2.0},
        "grid": {"initial.base_velocity.0": [0.0, 100.0], "initial.base_velocity.1": [0.0, 100.0]},
    }
    (tmp_path / "spec.yaml").write_text(yaml.safe_dump(spec))
    _ff("campaign", "spec.yaml", "--out", "c", "--workers", "1", "--report", cwd=tmp_path)
    assert (tmp_path / "c" / "figures" / "velocity_sweep.png").is_file()
    _check(tmp_path / "c" / "report.html", tmp_path, min_figures=4)
