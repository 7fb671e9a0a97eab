"""`freefloat report DIR`: one self-contained HTML page (DIR/report.html) for any `--out` folder — a campaign
(`freefloat campaign`), `freefloat demo`, `freefloat identify postcapture`, `freefloat identify minimal` or
`freefloat simulate` — with the tables beside the paper's values, interactive Plotly plots (plotly.js inlined: the
page opens without network access), the settings, and a 3D view of the robot for trajectories. Campaign reports
also write the papers' figures as PNG in DIR/figures/.

    from freefloat.report import write_report
    write_report("freefloat-demo")        # -> freefloat-demo/report.html
"""

from __future__ import annotations

import json
from pathlib import Path

from .._core import InputError
from .page import Page

__all__ = ["Page", "build_report", "write_report"]


def build_report(out) -> str:
    """The HTML text of the report of folder `out`."""
    from . import runs

    out = Path(out)
    rj = out / "results.json"
    if not out.is_dir():
        raise InputError(f"report: '{out}' is not a folder (give the --out folder of a freefloat command)")
    if not rj.is_file():
        raise InputError(f"report: '{out}' has no results.json (give the --out folder of a freefloat command)")
    try:
        res = json.loads(rj.read_text())
    except ValueError as e:
        raise InputError(f"report: {rj} is not valid JSON ({e})") from None
    page = Page(title=out.name)
    kind = runs.what(res)
    if kind == "campaign":
        from . import campaign

        campaign.build(out, page)
    elif kind == "unknown":
        page.title = f"Results in {out.name}"
        page.text("results.json of a kind this report does not know; its content:")
        page.settings("results.json", res)
    else:
        getattr(runs, kind)(page, out, res)
    return page.render()


def write_report(out) -> Path:
    """Write `out/report.html` and return its path."""
    text = build_report(out)
    p = Path(out) / "report.html"
    p.write_text(text, encoding="utf-8")
    return p
