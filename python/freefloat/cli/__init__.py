"""Command line: `freefloat --help` lists the commands; each has its own `--help`.

One module per command group, each a thin layer over the library: `models`, `simulate`, `reactions`, `demo`,
`params`, `identify` (+ `postcapture` for `identify postcapture` and `scenarios`), `excite`, `control`
(the group; one module per controller), `campaign` and `report`. A new command goes
in its own module and is registered below.
"""

from __future__ import annotations

import sys

import click

from . import (
    _common,
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
    mission,
    models,
    params,
    postcapture,
    reactions,
    report,
    simulate,
)


class FriendlyGroup(click.Group):
    """No Python traceback reaches a command-line user: every error becomes one line on stderr and a non-zero
    exit code (`_common.report_error`); `freefloat --debug COMMAND ...` (or FREEFLOAT_DEBUG=1) shows the
    traceback instead."""

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except (click.exceptions.ClickException, click.exceptions.Exit, click.exceptions.Abort, SystemExit):
            raise  # click's own usage errors and exits: already one clear line
        except KeyboardInterrupt:
            raise  # click reports "Aborted!" (commands that keep partial results handle Ctrl-C themselves)
        except BaseException as e:  # noqa: BLE001  (a Rust panic arrives as pyo3's PanicException, a BaseException)
            if _common.debug_enabled(ctx):
                raise
            sys.exit(_common.report_error(e))


@click.group(cls=FriendlyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="freefloat")
@click.option(
    "--debug",
    is_flag=True,
    envvar="FREEFLOAT_DEBUG",
    help="On an error, show the Python traceback instead of the one-line message (for a bug report).",
)
@click.pass_context
def main(ctx, debug):
    """freefloat: model, simulate and identify free-floating space robots.

    Start with `freefloat demo`, list robots with `freefloat models`, and simulate one with
    `freefloat simulate naveen_dual_arm --out run.parquet`."""
    ctx.ensure_object(dict)
    ctx.obj["debug"] = debug


main.add_command(models.models_cmd)
main.add_command(simulate.simulate_cmd)
main.add_command(reactions.reactions_cmd)
main.add_command(measure.measure_cmd)
main.add_command(demo.demo_cmd)
main.add_command(mission.mission_cmd)
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
