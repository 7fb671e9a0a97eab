"""`freefloat identify cl` (Valverde 2018, ch. 9: concurrent-learning mass estimation)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click


@click.command("cl")
@click.argument("scenario")
@click.option("--out", type=click.Path(file_okay=False), help="Directory for results.json, table.txt and the figures.")
@click.option("--ns", type=int, help="Stack size N_s (overrides the scenario's; the thesis uses 10; at least 2).")
@click.option(
    "--sweep/--no-sweep",
    default=True,
    show_default=True,
    help="Also run the N_s sweep of Figs. 9.5-9.6 (accuracy and run time against N_s).",
)
@click.option("--repeats", type=int, default=3, show_default=True, help="Timed runs per N_s in the sweep (median).")
@click.option(
    "--wrench-noise",
    type=float,
    multiple=True,
    help="Joint force/torque sensor noise σ (N, N m) to study, repeatable (default: the scenario's `studies`).",
)
@click.option(
    "--rate-noise",
    type=float,
    multiple=True,
    help="Body twist and twist-rate noise σ to study, repeatable (default: the scenario's `studies`).",
)
@click.option("--noise/--no-noise", default=True, show_default=True, help="Run the measurement-noise study.")
@click.option(
    "--compare-ls/--no-compare-ls",
    default=False,
    show_default=True,
    help="Also identify the same motion with freefloat's momentum least squares and compare (about 15 s).",
)
@click.option("--plain", is_flag=True, help="Use the plain law (9.15) throughout (no SVD gain at T_th,2).")
@click.option(
    "--gain",
    type=click.Choice(["thesis", "truncated"]),
    help="The SVD gain from T_th,2 (overrides the scenario's; default thesis). thesis: Valverde's (9.27), every "
    "direction with sigma_i < sigma_th,2 driven at rate sigma_new to its least-squares value, however noisy "
    "(the reproduction). truncated: (9.27) only for the directions where the estimate's residual along them is "
    "at least KAPPA times the stored data's noise estimate, the others left at the plain law's rate; the same "
    "as thesis without noise, bounded with noisy sensors (docs/identification.md).",
)
@click.option(
    "--kappa",
    type=float,
    help="Threshold of the truncated gain, in noise standard deviations (> 0; default 6). Larger: fewer "
    "directions accelerated, safer with noise.",
)
@click.option(
    "--sigma-th2",
    type=float,
    help="sigma_th,2 of (9.27) (overrides the scenario's; the thesis uses 0.5): directions with a singular value of "
    "the stacked sum RᵀR below it converge at rate sigma_new from T_th,2, the others at their own rate sigma_i. "
    "With the thesis' 0.5, values just above it (0.54-0.68 at N_s >= 50 on valverde_ch9_two_arm) set the final "
    "error; a value at sigma_new (100) makes every direction converge at least at sigma_new "
    "(docs/identification.md, 'Accuracy against N_s').",
)
@click.option(
    "--noise-seeds",
    type=int,
    default=1,
    show_default=True,
    help="Noise seeds per run of the noise study (the scenario's noise_seed and the ones after it); the study "
    "reports the largest error over them.",
)
def identify_cl_cmd(
    scenario,
    out,
    ns,
    sweep,
    repeats,
    wrench_noise,
    rate_noise,
    noise,
    compare_ls,
    plain,
    gain,
    kappa,
    sigma_th2,
    noise_seeds,
):
    """Valverde 2018 ch. 9: estimate all mass properties of a multi-arm spacecraft by concurrent learning.

    SCENARIO is a built-in name (`freefloat scenarios`, e.g. valverde_ch9_two_arm) or a YAML file of kind
    identify_cl. The robot (here 11 bodies: a 50 kg base and two arms of five 5 kg links) starts at rest; every
    joint is driven with 0.5 sin t for 2-3 s; at every 0.01 s step the estimator receives each body's motion and
    the wrench its joints apply (reaction + actuation, as joint force/torque sensors would measure), keeps the
    N_s most informative samples (Algorithm 3) and integrates the estimation law; at T_th,2 = 4.9 s an SVD gain
    makes the weakly excited directions converge at rate σ_new. Prints the 77 estimates against the truth;
    with --out writes results.json (truth, final_estimate, time_within_1pct_s, ...), table.txt and the figures
    9.1-9.6, the noise study and, with --compare-ls, the least-squares comparison.

    With noisy sensors the thesis gain drives weakly excited directions to least-squares values dominated by the
    noise (max relative error about 2e4 at 1e-3 N); --gain truncated accelerates only the directions the data
    determine. The noise study compares the plain law, the thesis gain and the truncated gain side by side."""
    import warnings

    from tqdm import tqdm

    from ..identification import concurrent as cl
    from ..identification import concurrent_plots as plots
    from ..identification import concurrent_studies as studies

    sc = cl.load_scenario(scenario)
    if ns is not None and ns < 2:
        raise click.BadParameter("the stack must hold at least 2 points", param_hint="--ns")
    if repeats < 1:
        raise click.BadParameter("at least 1", param_hint="--repeats")
    if kappa is not None and not (kappa > 0 and kappa < float("inf")):
        raise click.BadParameter(f"must be positive and finite, got {kappa}", param_hint="--kappa")
    if sigma_th2 is not None and not (sigma_th2 > 0 and sigma_th2 < float("inf")):
        raise click.BadParameter(f"must be positive and finite, got {sigma_th2}", param_hint="--sigma-th2")
    if noise_seeds < 1:
        raise click.BadParameter("at least 1", param_hint="--noise-seeds")
    for x in (*wrench_noise, *rate_noise):
        if not x >= 0:
            raise click.BadParameter(f"noise levels must be ≥ 0, got {x}", param_hint="--wrench-noise/--rate-noise")
    if ns is not None:
        sc = cl.with_settings(sc, ns=ns)
    if plain:
        sc = cl.with_settings(sc, aggressive=False)
    if gain is not None:
        sc = cl.with_settings(sc, gain=gain)
    if kappa is not None:
        sc = cl.with_settings(sc, kappa=kappa)
    if sigma_th2 is not None:
        sc = cl.with_settings(sc, sigma_th2=sigma_th2)
    bar = tqdm(total=round(sc.duration, 2), unit="s sim", desc=f"ch. 9 {sc.name}", leave=False, bar_format=None)
    last = [0.0]

    def progress(t):
        bar.update(t - last[0])
        last[0] = t
        return True

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = cl.run(sc, progress=progress)
    bar.close()
    for w in caught:
        click.echo(f"warning: {w.message}", err=True)
    if res.interrupted:
        click.echo("interrupted: results up to the interruption", err=True)
    table = res.table()
    click.echo(table)
    extra = {}
    if sweep and not res.interrupted:
        values = sorted(set(sc.ns_sweep))
        with tqdm(total=len(values) * repeats, desc="N_s sweep (Figs. 9.5-9.6)", unit="run", leave=False) as b:
            sw = studies.ns_sweep(sc, values, repeats=repeats, progress=lambda: b.update(1))
        extra["ns_sweep"] = sw
        click.echo(
            f"\nN_s   sup err (9.7-10 s)   within 1 % from   error decay rate, last 3 s [1/s]   "
            f"run time [s] (median of {repeats})"
        )
        for r in sw:
            w = r["time_within_1pct_s"]
            click.echo(
                f"{r['ns']:4d}   {r['sup_error_9p7_to_10s']:18.3e}   {'never' if w is None else f'{w:.2f} s':>15s}   "
                f"{r['tail_decay_rate_per_s']:32.4f}   {r['run_time_s_median']:.3f}"
            )
    wl = list(wrench_noise) or sc.wrench_noise_levels
    rl = list(rate_noise) or sc.rate_noise_levels
    if noise and (wl or rl) and not res.interrupted:
        seeds = list(range(sc.noise_seed, sc.noise_seed + noise_seeds))
        ng = len(studies.NOISE_GAINS)
        with tqdm(total=ng * len(seeds) * (len(wl) + len(rl)), desc="noise study", unit="run", leave=False) as b:
            rows = studies.noise_study(sc, wl, rl, seeds=seeds, kappa=kappa, progress=lambda: b.update(1))
        extra["noise_study"] = rows
        over = f"over noise seeds {seeds[0]}-{seeds[-1]}" if len(seeds) > 1 else f"noise seed {seeds[0]}"
        click.echo(f"\nnoise study ({over}; errors relative to each parameter's scale)")
        click.echo(
            "noise    level      gain       max rel. err   median rel. err   max mass err   realisable   withheld"
        )
        for r in rows:
            click.echo(
                f"{r['kind']:7s}  {r['level']:9.2e}  {r['gain']:9s}  "
                f"{r['max_final_relative_error']:13.3e}  {r['median_final_relative_error']:16.3e}  "
                f"{r['max_mass_relative_error']:13.3e}  {r['realisable_bodies']:6d}/{sc.model.nbodies}   "
                f"{r['withheld_directions'] if r['gain'] == 'truncated' else '':>8}"
            )
    if compare_ls and not res.interrupted:
        click.echo("\nmomentum least squares on the same motion ...", err=True)
        comp = studies.compare_ls(sc, rate_levels=(0.0, *rl))
        extra["compare_ls"] = comp
        click.echo(
            f"\nLS identifies {comp['ls_identifiable_combinations']} combinations (base known for the scale); "
            f"CL identifies {comp['cl_parameters']} parameters"
        )
        click.echo("rate noise   LS max rel. err   CL max rel. err (same combinations)   LS condition number")
        for lvl in comp["levels"]:
            click.echo(
                f"{lvl['rate_noise']:10.2e}   {lvl['ls_max_rel_error']:15.3e}   "
                f"{lvl['cl_max_rel_error_on_combinations']:35.3e}   {lvl['ls_condition_number']:.3e}"
            )
    if res.interrupted:  # Ctrl-C: the results up to it, without the figures (plotting would delay the exit)
        if out:
            o = Path(out)
            o.mkdir(parents=True, exist_ok=True)
            res.save(o, figures=False)
            (o / "table.txt").write_text(table + "\n")
            click.echo(f"wrote {o / 'results.json'} and {o / 'table.txt'} (interrupted; no figures)", err=True)
        sys.exit(130)
    if out:
        o = Path(out)
        o.mkdir(parents=True, exist_ok=True)
        res.extra.update(extra)
        res.save(o)
        (o / "table.txt").write_text(table + "\n")
        if "ns_sweep" in extra:
            plots.ns_figures(extra["ns_sweep"], o)
        if "noise_study" in extra:
            plots.noise_figure(extra["noise_study"], o)
        if "compare_ls" in extra:
            plots.comparison_figure(extra["compare_ls"], o)
        json.loads((o / "results.json").read_text())  # written and readable
        click.echo(f"\nwrote {o}/results.json, table.txt and the figures")
