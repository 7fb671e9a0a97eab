"""`freefloat params`: which combinations of the inertial parameters the momentum model identifies."""

from __future__ import annotations

import json
from pathlib import Path

import click

from ._common import load_model


@click.group("params", context_settings={"help_option_names": ["-h", "--help"]})
def params_group():
    """Inertial parameters: which combinations of them the momentum model can identify.

    The momentum of a free-floating robot is linear in the 10 standard parameters of each body
    (mass, first moment, inertia), but only certain combinations of them affect it. Run
    `freefloat params minimal MODEL` to list those combinations."""


@params_group.command("minimal")
@click.argument("model")
@click.option(
    "--method",
    type=click.Choice(["auto", "closed-form", "numeric"]),
    default="auto",
    show_default=True,
    help="'numeric': QR of the momentum regressor over random states (any robot). 'closed-form': Naveen, Shah, "
    "Misra's grouping rules (revolute joints in modified-DH frames only), numbered like their Table 4. 'auto': "
    "the closed form where it applies, else numeric (the same default, names and order as `identify minimal`).",
)
@click.option(
    "--known",
    help="Comma-separated body names whose parameters are known and not identified "
    "(default: bodies tagged 'known' or 'wheel'); pass '' for none.",
)
@click.option("--out", help="Directory; gets results.json with names, expressions, values and rank.")
def minimal_cmd(model, method, known, out):
    """Print the minimal (identifiable) inertial parameters of MODEL.

    MODEL is a built-in robot name or a .yaml/.urdf file. Each line is one minimal parameter: a linear
    combination of standard parameters (body.m, body.mcx = mass times CoM x, body.Ixx = inertia about
    the body-frame origin, ...), with its value for the model's own parameters. Momentum measurements
    determine these combinations and nothing finer."""
    from ..identification.minimal import minimal_parameters  # scipy is only needed here

    m = load_model(model)
    names = None if known is None else [s.strip() for s in known.split(",") if s.strip()]
    try:
        mp = minimal_parameters(m, method=method, known=names)
    except ValueError as e:
        raise click.UsageError(str(e)) from None
    values = mp.from_standard(m.parameters())
    ex = mp.expressions()
    known_names = [m.body_names[i] for i in mp.known]
    click.echo(
        f"{m.name}: {mp.n_min} minimal parameters ({mp.method}; rank {mp.rank} of {mp.matrix.shape[1]} "
        f"standard columns); known bodies: {', '.join(known_names) or 'none'}"
    )
    if not known_names:
        click.echo(
            "  note: no body is known, so the overall scale of the parameters is unobservable from momentum "
            "(multiplying every parameter by one factor fits the same data): identification needs a body with "
            "known parameters, such as a reaction wheel. Name it with --known BODY (or tag it 'known')."
        )
    w = max(len(n) for n in mp.names)
    for n, e, x in zip(mp.names, ex, values):
        click.echo(f"  {n:{w}s} = {x:14.6g}   = {e}")
    if out:
        d = Path(out)
        d.mkdir(parents=True, exist_ok=True)
        res = {
            "model": m.name,
            "method": mp.method,
            "rank": mp.rank,
            "n_standard": int(mp.matrix.shape[1]),
            "known_bodies": known_names,
            "unknown_bodies": [m.body_names[i] for i in mp.unknown],
            "names": mp.names,
            "expressions": ex,
            "values": values.tolist(),
        }
        (d / "results.json").write_text(json.dumps(res, indent=2))
        click.echo(f"  wrote {d / 'results.json'}")
