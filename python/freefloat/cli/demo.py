"""`freefloat demo`: the main job on its built-in default (the pipeline is `freefloat.demo.run`)."""

from __future__ import annotations

import click


@click.command("demo")
@click.option(
    "--out", default="freefloat-demo", show_default=True, help="Directory for the trajectory, results.json and figure."
)
@click.option("--t-final", type=float, default=20.0, show_default=True, help="Length of the manoeuvre [s].")
def demo_cmd(out, t_final):
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

    demo.run(out, t_final, echo=click.echo, progress=True)
