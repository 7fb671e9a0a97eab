"""`freefloat report` (issue 15) without a browser: which folder gets which page, self-contained HTML, the tables
beside the paper's values, the 3D view's geometry, the PNG figures, bad input. The browser checks are in
test_report_browser.py."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
import yaml
from click.testing import CliRunner

from freefloat import campaign as cp
from freefloat import models
from freefloat._core import InputError
from freefloat.campaign import dataset, runner
from freefloat.report import build_report, write_report
from freefloat.report.robot3d import figure


def _fake_campaign(out, grid, summary):
    """A campaign folder as `freefloat campaign` leaves it, with made-up summary numbers (summary(run) -> dict)
    and no cluster: the report only reads the folder."""
    s = cp.spec.parse(
        {
            "name": "fake_sweep",
            "kind": "postcapture",
            "scenario": "zhang2020_2d_sweep",
            "grid": grid,
            "paper": {"momentum_In": [{"velocity": [200, 200], "error_percent": 7.2}]},
        },
        "test",
    )
    w = dataset.Writer(out / "runs")
    for r in s.runs():
        row = {
            "status": "done",
            "run_key": r.key,
            "run_index": r.index,
            "seed": r.seed,
            "inputs": runner._canonical({"kind": r.kind, "scenario": r.scenario, "seed": r.seed}),
            "run_wall_s": 1.0,
            **{f"param.{k}": v for k, v in r.params.items()},
            **summary(r),
        }
        w.add(row)
    w.flush()
    (out / "campaign.json").write_text(json.dumps({"name": s.name, "fingerprint": s.fingerprint(), "spec": s.raw}))
    res = {
        "campaign": s.name,
        "kind": "postcapture",
        "runs_total": s.runs_total,
        "runs_done": s.runs_total,
        "runs_failed": 0,
        "runs_new": 0,
        "runs_remaining": 0,
        "dataset": str(out / "runs"),
    }
    (out / "results.json").write_text(json.dumps(res))
    return s


NAMES = ("m1", "b1x", "b1y", "I1", "mn", "bnx", "bny", "In")


def _summary(r):
    vx, vy = r.params["initial.base_velocity.0"], r.params["initial.base_velocity.1"]
    out = {}
    for m in ("momentum", "force"):
        for s in ("modified_rls", "standard_rls"):
            for k, n in enumerate(NAMES):
                out[f"error.{m}.{s}.{n}"] = 1e-4 * (1 + vx + 2 * vy + k)
                out[f"estimate.{m}.{s}.{n}"] = 1.0 + k
    out.update({f"truth.{n}": 1.0 + k for k, n in enumerate(NAMES)})
    return out


@pytest.mark.slow
def test_campaign_report_is_self_contained_and_shows_the_sweep(tmp_path):
    _fake_campaign(
        tmp_path, {"initial.base_velocity.0": [0.0, 200.0], "initial.base_velocity.1": [0.0, 200.0]}, _summary
    )
    p = write_report(tmp_path)
    assert p == tmp_path / "report.html"
    html = p.read_text(encoding="utf-8")
    assert not re.search(r"<script[^>]+src=", html)  # plotly.js is inlined, nothing fetched
    assert len(html) > 3e6 and "Plotly.newPlot" in html  # the plotly.js library itself is in the page
    assert len(re.findall(r"class=\"plotly-graph-div\"", html)) == 4  # one (Vx, Vy) figure per form and solver
    # the paper's value beside ours at the nearest grid point: (200, 200) -> 1e-4 (1 + 200 + 400 + 7) = 6.08 %
    row = re.search(r"<td class='l'>\[200, 200\]</td><td>7.2</td><td>\[200, 200\]</td><td>([^<]+)</td>", html)
    assert row and float(row.group(1)) == pytest.approx(100 * 1e-4 * 608, rel=1e-3)
    assert (tmp_path / "figures" / "velocity_sweep.png").stat().st_size > 10_000  # the papers' format, for print


@pytest.mark.slow
def test_report_of_a_postcapture_folder_puts_the_paper_beside_ours(tmp_path):
    import freefloat.postcapture as pc
    from freefloat import data

    d = yaml.safe_load(data.read_text("scenarios", "zhang2020_2d_medium"))
    d["duration"] = 1.0
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(d))
    res = pc.run(pc.load_scenario(tmp_path / "s.yaml"))
    res.save(tmp_path / "pc")
    html = build_report(tmp_path / "pc")
    # m1: truth 500, the paper's momentum-based final value 500.0, our estimate of the saved results
    est = json.loads((tmp_path / "pc" / "results.json").read_text())["methods"]["momentum"]["modified_rls"]["m1"]
    cells = re.search(r"<td class='l'>m1</td><td>([^<]+)</td><td>([^<]+)</td><td>([^<]+)</td>", html)
    assert cells and [float(c) for c in cells.groups()] == pytest.approx([500.0, 500.0, est["estimate"]], rel=1e-3)
    assert "momentum-based identification" in html and "force-based identification" in html


def test_the_3d_view_moves_the_bodies_rigidly_with_the_base():
    m = models.load("naveen_dual_arm")
    q0 = m.neutral()
    q1 = q0.copy()
    q1[:3] += [1.0, -2.0, 0.5]  # translate the base only: every body moves by the same vector
    fig = figure(m, np.array([0.0, 1.0]), np.stack([q0, q1]))
    assert len(fig.frames) == 2
    b0 = fig.frames[0].data[1]
    b1 = fig.frames[1].data[1]
    p0 = np.stack([b0.x, b0.y, b0.z], 1)
    p1 = np.stack([b1.x, b1.y, b1.z], 1)
    assert p0.shape == (len(m.body_names), 3)
    assert np.allclose(p0[0], q0[:3]) and np.allclose(p1 - p0, [1.0, -2.0, 0.5], atol=1e-12)
    # links: one segment per non-root body, from its parent's origin to its own
    links = fig.frames[0].data[0]
    assert sum(x is None for x in links.x) == sum(1 for p in m.parents if p is not None and p >= 0)


def test_report_bad_input(tmp_path):
    with pytest.raises(InputError, match="no results.json"):
        build_report(tmp_path)
    (tmp_path / "results.json").write_text("{not json")
    with pytest.raises(InputError, match="not valid JSON"):
        build_report(tmp_path)
    with pytest.raises(InputError, match="not a folder"):
        build_report(tmp_path / "nope")
    from freefloat.cli import main

    r = CliRunner().invoke(main, ["report", str(tmp_path)])
    assert r.exit_code == 2 and "not valid JSON" in r.output


def test_unknown_results_are_shown_not_refused(tmp_path):
    (tmp_path / "results.json").write_text(json.dumps({"something": 1.5}))
    html = build_report(tmp_path)
    assert "something" in html and "1.5" in html
