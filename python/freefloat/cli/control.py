"""`freefloat control ...`: the controllers of Valverde 2018, each a subcommand in its own module (registered in
`cli/__init__.py`)."""

from __future__ import annotations

import click


@click.group("control", context_settings={"help_option_names": ["-h", "--help"]})
def control_group():
    """Run a controller of a free-flying spacecraft on a built-in scenario or your own scenario file.

    List the scenarios with `freefloat scenarios`; each subcommand's --help says what it reproduces."""
