"""`freefloat demo`: the main job on its built-in default (the pipeline is `freefloat.demo.run`)."""

from __future__ import annotations

import click


@click.command("demo")
@click.option(
    "--out", default="freefloat-demo", show_default=True, help="Directory for the trajectory, results.json and figure."
)
@click.option("--t-final", type=float, default=20.0, show_default=True, help="Length of the manoeuvre [s].")
@click.option(
    "--case1",
    is_flag=True,
    help="Instead: Naveen, Shah, Misra's Case 1 under the paper's own conditions (67 undesigned intervals, its "
    "noise, plain least squares, --case1-rate sampling), then each of freefloat's improvements as its own row "
    "(1 kHz samples, errors-in-variables removal, designed excitation). Minutes: it simulates 67 s and more.",
)
@click.option("--case1-rate", type=float, default=20.0, show_default=True, help="--case1: sampling rate of row 1 [Hz].")
def demo_cmd(out, t_final, case1, case1_rate):
    """Run the main job on its built-in default, on the Naveen, Shah, Misra dual-arm robot with three reaction wheels.

    1. Simulation: the robot floats freely while its six arm joints follow a smooth prescribed manoeuvre
       (hybrid dynamics: the base responds, the joint torques needed are recorded); prints and plots how
       well momentum and energy are conserved.
    2. Identification: the exciting trajectory designed by `freefloat excite` (shipped in the package) with the paper's
       rate noise, then the 52 minimal parameters from the momentum model; prints the paper's error
       figures and plots every parameter's error.
    3. Validation by prediction (Naveen, Shah, Misra Sec. VI.D): true and identified robots along a Fourier
       trajectory."""
    from .. import demo

    if case1:
        import json
        from pathlib import Path

        res = demo.case1_table(case1_rate, echo=click.echo, progress=True)
        res.pop("table")  # printed above; the numbers are in the rows
        p = Path(out)
        p.mkdir(parents=True, exist_ok=True)
        (p / "case1.json").write_text(json.dumps(res, indent=2))
        click.echo(f"wrote {p / 'case1.json'}")
        return
    demo.run(out, t_final, echo=click.echo, progress=True)
