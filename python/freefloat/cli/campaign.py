"""`freefloat campaign`: grid and Monte Carlo campaigns over scenario parameters, on Dask
(the library is `freefloat.campaign`)."""

from __future__ import annotations

import os
import sys

import click


@click.command("campaign")
@click.argument("spec", required=False)
@click.option("--out", type=click.Path(file_okay=False), help="Folder for the dataset, campaign.json and results.json.")
@click.option("--list", "list_", is_flag=True, help="List the built-in campaign specs and exit.")
@click.option(
    "--runs", type=int, help="Run only the first N runs of the spec (a quick look; the rest can follow later)."
)
@click.option(
    "--workers",
    type=int,
    help="Worker processes of the local Dask cluster (default: one per core). Ignored with --scheduler.",
)
@click.option(
    "--scheduler",
    metavar="ADDRESS",
    help="Run on an existing Dask cluster instead of this machine, e.g. tcp://10.0.0.5:8786 (started with "
    "`dask scheduler`, workers with `dask worker ADDRESS`; they need freefloat installed).",
)
@click.option("--retry-failed", is_flag=True, help="Run again the runs recorded as failed in --out.")
@click.option(
    "--repair",
    is_flag=True,
    help="Move damaged dataset files of --out to --out/quarantine/ and run their runs again (without it they are "
    "reported and nothing runs).",
)
@click.option("--report/--no-report", default=False, show_default=True, help="Write --out/report.html at the end.")
def campaign_cmd(spec, out, list_, runs, workers, scheduler, retry_failed, repair, report):
    """Run many scenarios at once: a grid and/or Monte Carlo over any scenario parameter.

    SPEC is a built-in campaign name (`freefloat campaign --list`) or a YAML file: the scenario kind and base
    scenario, fixed overrides (`set`), a `grid` of values per dotted parameter path (e.g.
    initial.base_velocity.0 for the initial Vx of a post-capture scenario), and `monte_carlo` draws (noise seeds,
    random parameters). Each run's inputs and summary numbers become one row of a Parquet dataset in
    OUT/runs/ (readable by pyarrow, pandas, polars, DuckDB), written as runs finish. Kinds: postcapture
    (Zhang 2020), identify_minimal (Naveen et al.), identify_cl, control_adaptive and control_ddp (Valverde 2018
    ch. 9, 4 and 8; their scenario files, e.g. valverde_ch9_two_arm with noise.wrench / noise.rate), mission
    (capture missions, e.g. zhang2020_capture_monte_carlo over target inertia and gyro noise) and sensor_classes
    (every estimator on the navigation / tactical / MEMS sensor presets: sensor_class_monte_carlo).

    Re-running the same command skips the runs already in OUT (each run is keyed by a hash of its inputs), so
    an interrupted campaign (Ctrl-C) continues where it stopped. A run that raises is recorded with its error;
    the runs of a worker that dies are run again. OUT/results.json holds runs_total, runs_done, runs_new,
    runs_failed and the dataset's path; `freefloat report OUT` makes an HTML page of it.

    Example: freefloat campaign zhang2020_velocity_sweep --out sweep --runs 4 --workers 2"""
    from .. import campaign as cp
    from .._core import InputError

    if list_:
        for name in cp.builtin_names():
            try:
                s = cp.load_spec(name)
                click.echo(f"{name:<30} {s.kind:<17} {s.runs_total:>5} runs  {s.description}")
            except InputError as e:  # a broken built-in is shown, not hidden
                click.echo(f"{name:<30} (cannot be loaded: {e})")
        return
    if spec is None:
        raise click.UsageError("give a SPEC (a built-in name from --list, or a YAML file) and --out DIR")
    if out is None:
        raise click.UsageError("--out DIR is required: the folder that keeps the campaign's results")
    if runs is not None and runs < 1:
        raise click.BadParameter("must be at least 1", param_hint="--runs")
    if workers is not None and workers < 1:
        raise click.BadParameter("must be at least 1", param_hint="--workers")
    s = cp.load_spec(spec)
    n = min(runs, s.runs_total) if runs else s.runs_total
    where = scheduler or f"a local Dask cluster of {workers or 'one worker per core'}" + (" workers" if workers else "")
    click.echo(f"campaign {s.name} ({s.kind}): {n} of {s.runs_total} runs on {where}; results in {out}/runs/")
    try:
        res = cp.run_campaign(
            s,
            out,
            runs=runs,
            workers=workers,
            scheduler=scheduler,
            retry_failed=retry_failed,
            repair=repair,
            echo=click.echo,
        )
    except KeyboardInterrupt:
        click.echo(
            f"\ninterrupted: the finished runs are kept in {out}/runs/; run the same command again to continue",
            err=True,
        )
        # Everything the campaign keeps is written and closed before run_campaign re-raises (rows, results.json)
        # and its local workers are killed: what is left is the interpreter's teardown of the Dask client and
        # cluster machinery (event-loop thread, finalizers), measured at about 0.5 s of the one second a stop may
        # take. Leave without it.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(130)
    click.echo(
        f"{res['runs_done']} of {res['runs_total']} runs done, {res['runs_failed']} failed, "
        f"{res['runs_remaining']} remaining; {res['runs_new']} run now ({res['runs_skipped']} already in {out}) "
        f"in {res['wall_s']:.1f} s on {res['scheduler'] or 'no cluster (nothing to run)'}"
    )
    for f in res["failures"][:5]:
        click.echo(f"  failed run {f['run_key']}: {f['error'][:300]}")
    click.echo(f"wrote {out}/results.json; dataset {res['dataset']}")
    if report:
        from ..report import write_report

        click.echo(f"wrote {write_report(out)}")
