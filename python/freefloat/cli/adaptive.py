"""`freefloat control adaptive`: Valverde 2018 ch. 4, adaptive pose tracking with concurrent learning."""

from __future__ import annotations

import sys

import click


@click.command("adaptive")
@click.argument("scenario")
@click.option("--out", help="Directory for results.json and the figures (PNG).")
@click.option("--baseline", is_flag=True, help="Run only the baseline controller (alpha = 0, no concurrent learning).")
@click.option(
    "--alpha",
    type=float,
    multiple=True,
    help="Concurrent-learning weight(s) instead of the scenario's (repeat for several runs); the baseline runs beside.",
)
@click.option("--no-compare", is_flag=True, help="Do not run the baseline beside the concurrent-learning runs.")
@click.option(
    "--alpha-off-after",
    type=float,
    metavar="SECONDS",
    help="Valverde 2018 Remark 6: set alpha to 0 this many seconds after the concurrent-learning matrix first has "
    "rank 7 (overrides the scenario's learning.alpha_off_after; default: never). 0 switches it off at rank 7; "
    "the estimate then keeps only the baseline's adaptation (docs/architecture.md, 'Remark 6').",
)
def adaptive_cmd(scenario, out, baseline, alpha, no_compare, alpha_off_after):
    """Valverde 2018 ch. 4: a spacecraft tracks a moving reference frame while it learns its own mass and inertia.

    SCENARIO is a built-in name (`freefloat scenarios`: valverde_ch4_example_a, valverde_ch4_example_b) or a
    YAML file. The relative pose-error dynamics are simulated with the adaptive control law (4.9) (its swap typo
    corrected) and the update law with continuous concurrent learning (Theorem 1, example A) or a stored data
    stack (Theorem 2, example B), each beside the baseline of Filipe and Tsiotras (alpha = 0). Prints the final
    estimates against the truth [I11, I12, I13, I22, I23, I33, m], the time after which all stay within 1 %,
    and the final tracking errors; --out writes results.json and Figs. 4.1-4.7 (tracking errors, estimates,
    singular values, control effort). Ctrl-C stops a run and keeps what was simulated."""
    import dataclasses
    import math

    from tqdm import tqdm

    from ..control import adaptive as ad

    if any(not (a >= 0 and math.isfinite(a)) for a in alpha):
        raise click.BadParameter("must be finite and >= 0", param_hint="--alpha")
    if alpha_off_after is not None and not (alpha_off_after >= 0 and math.isfinite(alpha_off_after)):
        raise click.BadParameter(f"must be finite and >= 0, got {alpha_off_after}", param_hint="--alpha-off-after")
    sc = ad.load_scenario(scenario)
    if alpha_off_after is not None:
        sc = dataclasses.replace(sc, alpha_off_after=float(alpha_off_after))
    labels = ["baseline"] if baseline else [f"alpha={a:g}" for a in (alpha or sc.alphas) if a != 0]
    if not baseline and not no_compare:
        labels.append("baseline")
    bars = {}

    def progress(label, t):
        bar = bars.get(label)
        if bar is None:
            for b in bars.values():
                b.close()
            bar = bars[label] = tqdm(
                total=round(sc.duration, 6), desc=f"{sc.name} {label}", unit="sim s", leave=False,
                bar_format="{l_bar}{bar}| {n:.1f}/{total:.0f} sim s [{elapsed}<{remaining}]",
            )  # fmt: skip
        bar.update(min(t, sc.duration) - bar.n)
        return True

    try:
        res = ad.run(sc, alphas=list(alpha) or None, baseline=not no_compare, baseline_only=baseline, progress=progress)
    finally:
        for b in bars.values():
            b.close()
    click.echo(res.table())
    stopped = [k for k, r in res.runs.items() if r.data["interrupted"]]
    if stopped:
        click.echo(f"interrupted: {stopped[0]} stopped at t = {res.runs[stopped[0]].t[-1]:.2f} s; results so far kept")
    if stopped:  # Ctrl-C: the results so far, without the figures (plotting would delay the exit by seconds)
        if out:
            path = res.save(out, figures=False)
            click.echo(f"wrote {path} (interrupted; no figures)", err=True)
        sys.exit(130)
    if out:
        path = res.save(out)
        click.echo(f"wrote {path} and figures in {out}")
