"""Command line: `freefloat --help` lists the commands; each has its own `--help`.

One module per command group, each a thin layer over the library: `models`, `simulate`, `reactions`, `demo`,
`params`, `identify` (+ `postcapture` for `identify postcapture` and `scenarios`), `excite`, `control`
(the group; one module per controller), `campaign` and `report`. A new command goes
in its own module and is registered below.
"""

from __future__ import annotations

import sys

import click

from .. import _core
from . import (
    adaptive,
    campaign,
    concurrent,
    control,
    convert,
    ddp,
    demo,
    excite,
    export,
    identify,
    measure,
    models,
    params,
    postcapture,
    reactions,
    report,
    simulate,
)


class FriendlyGroup(click.Group):
    """Turn the engine's errors into one clear line instead of a traceback."""

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except (_core.ModelError, _core.InputError, _core.NumericalError, FileNotFoundError) as e:
            click.echo(f"error: {e}", err=True)
            sys.exit(2)


@click.group(cls=FriendlyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="freefloat")
def main():
    """freefloat: model, simulate and identify free-floating space robots.

    Start with `freefloat demo`, list robots with `freefloat models`, and simulate one with
    `freefloat simulate naveen_dual_arm --out run.parquet`."""


main.add_command(models.models_cmd)
main.add_command(simulate.simulate_cmd)
main.add_command(reactions.reactions_cmd)
main.add_command(measure.measure_cmd)
main.add_command(demo.demo_cmd)
main.add_command(params.params_group)
main.add_command(identify.identify_group)
identify.identify_group.add_command(postcapture.identify_postcapture_cmd)
identify.identify_group.add_command(concurrent.identify_cl_cmd)
main.add_command(excite.excite_cmd)
main.add_command(postcapture.scenarios_cmd)
main.add_command(control.control_group)
control.control_group.add_command(adaptive.adaptive_cmd)
main.add_command(export.export_cmd)
main.add_command(convert.convert_cmd)
main.add_command(campaign.campaign_cmd)
main.add_command(report.report_cmd)
control.control_group.add_command(ddp.ddp_cmd)

__all__ = ["main"]
