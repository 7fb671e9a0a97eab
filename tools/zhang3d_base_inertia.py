"""Why the force form is slower than the momentum form on the base inertia of `zhang2020_3d` with the paper's prior
(Zhang, Yue, Yuan 2020, Table 6 finds the opposite), measured on one noise-free run.

1. The information each form's angular rows carry about the base's principal moments: the sum over the samples up
   to t of the squared I'1xx, I'1yy, I'1zz columns of Φ (eqs. 16 and 31; θ = [I'1#, I'n#]). The force form's
   columns are the base's angular acceleration and gyroscopic terms, which vanish once eq. (39) has stopped the
   base; the momentum form's are cumulative differences from t0, which keep the initial rate.
2. The base-inertia estimates of the paper's modified RLS (eqs. 34-38) and of the standard-parameter RLS:
   with the paper's prior P0 = 1e6 and guesses (the scenario), with the guesses of m and m b' replaced by the truth
   (only the inertia guesses left: the part of the bias that comes through D(μ) removed), and with weaker priors.

    python tools/zhang3d_base_inertia.py

prints the tables docs/postcapture.md ("Table 6, 3D": why the force form is slow on I'1xx) shows.
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np

import freefloat.postcapture as pc
from freefloat import models
from freefloat.postcapture import equations as eq
from freefloat.postcapture.estimators import target_index

BASE_I = ("I1xx", "I1yy", "I1zz")
#: columns of the base's principal moments in θ = [I'1#, I'n#], I# = [I11, I12, I13, I22, I23, I33] (eq. 21)
THETA_COLS = (0, 3, 5)


def information(rows: eq.PaperRows, times) -> np.ndarray:
    """(len(times), 3): Σ_{t_k ≤ t} of the squared I'1xx, I'1yy, I'1zz columns of the angular rows Φ."""
    sq = (rows.Phi[:, :, list(THETA_COLS)] ** 2).sum(axis=1)  # (N, 3)
    return np.array([sq[rows.t <= t + 1e-9].sum(axis=0) for t in times])


def true_mu_guess(sc: pc.Scenario, model) -> dict:
    """The scenario's guesses with the masses and CoM offsets of base and target set to the model's truth."""
    guess = copy.deepcopy(sc.guess)
    for key, body in (("base", 0), ("target", target_index(model))):
        m, b, _ = eq.body_truth(model, body)
        guess[key]["mass"], guess[key]["com"] = float(m), [float(x) for x in b]
    return guess


def main() -> None:
    sc = pc.load_scenario("zhang2020_3d")
    m = models.load(sc.model)
    sim = pc.simulate(sc, m)
    meas = pc.measure(m, sim, sc, None)
    tgt = target_index(m)
    times = (2, 5, 10, 20, 50, 100)
    print("information on the base's principal moments, Σ φ² of the I'1 columns of Φ up to t [(kg m²)⁻² units]")
    print("| form | axis | " + " | ".join(f"t ≤ {t} s" for t in times) + " |")
    print("|---|---|" + "---|" * len(times))
    for form, rows in (
        ("momentum", eq.paper_momentum_rows(m, meas, 0, tgt)),
        ("force", eq.paper_force_rows(m, meas, 0, tgt)),
    ):
        info = information(rows, times)
        for k, name in enumerate(BASE_I):
            print(f"| {form} | {name} | " + " | ".join(f"{x:.3g}" for x in info[:, k]) + " |")

    variants = [
        ("paper: P0 = 1e6, the scenario's guesses", sc),
        ("P0 = 1e6, m and m b' guessed right", dataclasses.replace(sc, guess=true_mu_guess(sc, m))),
        ("P0 = 1e8", dataclasses.replace(sc, P0=1e8)),
        ("P0 = 1e10", dataclasses.replace(sc, P0=1e10)),
        ("P0 = 1e14", dataclasses.replace(sc, P0=1e14)),
    ]
    print("\nfinal relative error [%] (transit time to 1 %, stays within [s]; first entry in brackets for I'1xx)")
    print("| prior | form / solver | " + " | ".join(BASE_I) + " |")
    print("|---|---|" + "---|" * len(BASE_I))
    for label, s in variants:
        res = pc.identify(m, meas, s)
        for form in pc.METHODS:
            for solver in pc.SOLVERS:
                tt = res.transits(form, solver)
                err = res.rel_error(form, solver)
                cells = []
                for n in BASE_I:
                    j = res.names.index(n)
                    first, stays = tt[j]
                    extra = f", first {first:.1f}" if n == "I1xx" and first is not None else ""
                    cells.append(f"{100 * err[j]:.3f} ({'—' if stays is None else f'{stays:.1f}'}{extra})")
                print(f"| {label} | {form} / {solver} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
