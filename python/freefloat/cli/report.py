"""`freefloat report DIR`: the HTML report of an `--out` folder (the library is `freefloat.report`)."""

from __future__ import annotations

import click


@click.command("report")
@click.argument("folder", type=click.Path(exists=True, file_okay=False))
def report_cmd(folder):
    """Write FOLDER/report.html: one self-contained web page of the results in FOLDER.

    FOLDER is the --out folder of `freefloat campaign`, `freefloat demo`, `freefloat identify postcapture`,
    `freefloat identify minimal` or `freefloat simulate`. The page holds the tables beside the paper's values,
    interactive plots (zoom, hover; Plotly, built into the page so it opens without network access), the
    settings of the run, and for a trajectory a 3D view of the robot's motion. A campaign report also writes the
    papers' figures as PNG in FOLDER/figures/.

    Example: freefloat demo --out demo && freefloat report demo   (then open demo/report.html)"""
    from ..report import write_report

    p = write_report(folder)
    click.echo(f"wrote {p} ({p.stat().st_size / 1e6:.1f} MB); open it in a browser")
