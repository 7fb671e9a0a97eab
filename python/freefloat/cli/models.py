"""`freefloat models`: the built-in robots."""

from __future__ import annotations

import click

from .. import models


@click.command("models")
@click.option("--show", metavar="NAME", help="Print the YAML description of one built-in robot.")
def models_cmd(show):
    """List the built-in robots (name, sizes, mass), or print one with --show."""
    if show:
        click.echo(models.source(show))
        return
    click.echo(f"{'name':32s} {'bodies':>6s} {'base':>7s} {'nq':>4s} {'nv':>4s} {'mass [kg]':>10s}")
    for n in models.names():
        m = models.load(n)
        click.echo(f"{n:32s} {m.nbodies:6d} {m.joint_types[0]:>7s} {m.nq:4d} {m.nv:4d} {m.total_mass:10.2f}")
    click.echo(f"({models.ALIAS_NOTE})")
