"""Convention checks on telemetry before identifying: does the model conserve (or follow) the measured momentum
along the data, and if not, which usual mistake explains it?

Without external wrench the total momentum of a free-floating robot is constant, so the momentum model
h = K(q, v) φ must fit the data for *some* parameters φ. The check solves the identification's own least-squares
problem on an even subsample of the data, once for the data as given and once for each usual misreading of a
free base's state:
  - the base quaternion stored w-first (MuJoCo, Eigen's coefficients, many logs) instead of x, y, z, w;
  - the base linear velocity in the world frame (MuJoCo's free joint) instead of the base frame;
  - the base angular velocity in the world frame instead of the base frame;
and their combinations. It compares what share of the measured momentum each reading leaves unexplained (the
relative residual). The reading the data were written in fits to the noise floor; a wrong one leaves a residual
orders of magnitude larger. Fitting the parameters (rather than using the model's own) makes the check blind to
how good the model's parameters are — which is what identification is for — and sensitive only to geometry and
conventions. When no reading fits, the likely cause is the model itself (geometry, joint order or signs), an
external wrench the file does not record, or a momentum that is not the assumed h0."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from .._core import NumericalError

#: samples used by the check (spread evenly over the data); the regressor is cheap, a few thousand suffice
CHECK_SAMPLES = 2000
#: a misreading is named as the cause when it fits this many times better than the data as given
CAUSE_FACTOR = 100.0
#: relative residual above which the data as given are reported as not following the model's momentum
#: (the paper's rate noise on a correct file leaves about 0.1; a misread or wrong model about 0.5)
RESIDUAL_WARN = 0.25
#: readings within this factor of the best fit count as ties, broken towards fewer corrections (with zero total
#: momentum the base orientation does not enter the fit, so the quaternion order alone is not observable)
TIE_FACTOR = 2.0

FIXES = {
    "quat": "the base quaternion is stored w-first (w, x, y, z; MuJoCo's order), not x, y, z, w",
    "lin": "the base linear velocity is in the world frame (MuJoCo's free joint), not the base frame",
    "ang": "the base angular velocity is in the world frame, not the base frame",
}


@dataclass
class ConventionReport:
    """Relative residual (unexplained share of the measured momentum) of each reading of the data."""

    samples: int
    residuals: dict = field(default_factory=dict)  # reading (tuple of FIXES keys) -> relative residual
    best: tuple = ()

    @property
    def as_given(self) -> float:
        return self.residuals.get((), float("nan"))

    @property
    def cause(self) -> str | None:
        """The misreading(s) that explain the data, or None when the data as given fit best."""
        if not self.best or not self.residuals[self.best] * CAUSE_FACTOR < self.as_given:
            return None
        return "; ".join(FIXES[k] for k in self.best)

    @property
    def ok(self) -> bool:
        """No misreading named and the data as given fit (an unexcited fit, residual inf, is left to the
        identification, which names the unexcited parameters)."""
        g = self.as_given
        return self.cause is None and not (np.isfinite(g) and g > RESIDUAL_WARN)

    def message(self) -> str:
        g = self.as_given
        if self.cause:
            return (
                f"the telemetry does not follow the model's momentum as written (relative residual {g:.3g}); read "
                f"with this correction it fits to {self.residuals[self.best]:.3g}: {self.cause}. Convert the data to "
                "freefloat's conventions (q = [position, quaternion x y z w, joints], v = [base linear and angular "
                "velocity in the BASE frame, joint rates]); for MuJoCo states use `freefloat convert --from mujoco`"
            )
        if g > RESIDUAL_WARN:
            return (
                f"the model explains only {100 * (1 - min(g, 1)):.3g} % of the measured momentum along the data "
                f"(relative residual {g:.3g}, and no usual convention mistake explains it). Likely causes: the wrong "
                "model (geometry, joint order or signs), an external wrench the file does not record (add wrench.* "
                "columns), or a total momentum that is not h0 (pass the initial momentum as h0 / --h0)"
            )
        return f"momentum check passed (relative residual {g:.3g} on {self.samples} samples)"

    def to_dict(self) -> dict:
        return {
            "samples": self.samples,
            "relative_residual": self.as_given,
            "cause": self.cause,
            "readings": {"+".join(k) or "as given": v for k, v in self.residuals.items()},
        }


def check_conventions(mp, q, v, h, samples: int = CHECK_SAMPLES) -> ConventionReport:
    """Fit the minimal parameters `mp` to an even subsample of (q, v, h) as given and under each misreading
    (module docstring); return the relative residuals."""
    from ..algorithms import quat_to_matrix
    from .estimation import least_squares

    model = mp.model
    idx = np.unique(np.linspace(0, len(q) - 1, min(samples, len(q))).round().astype(int))
    qs, vs, hs = q[idx], v[idx], h[idx]
    _, h_known = mp.regressor_and_known_momentum(qs, vs)
    signal = float(np.sum((hs - h_known) ** 2))
    keys = ("quat", "lin", "ang") if model.joint_types[0] == "free" else ()
    report = ConventionReport(samples=len(idx))
    for r in range(len(keys) + 1):
        for combo in itertools.combinations(keys, r):
            qq, vv = qs.copy(), vs.copy()
            if "quat" in combo:
                qq[:, 3:7] = qs[:, [4, 5, 6, 3]]
            if "lin" in combo or "ang" in combo:
                R = quat_to_matrix(qq[:, 3:7])
                for k, sl in (("lin", slice(0, 3)), ("ang", slice(3, 6))):
                    if k in combo:
                        vv[:, sl] = np.einsum("tji,tj->ti", R, vs[:, sl])
            try:
                fit = least_squares(model, qq, vv, hs, mp)
                rel = float(np.sqrt(fit.rss / signal)) if signal > 0 else float("nan")
            except NumericalError:
                rel = float("inf")
            report.residuals[combo] = rel
    finite = {k: x for k, x in report.residuals.items() if np.isfinite(x)}
    if finite:
        low = min(finite.values())
        report.best = min((k for k, x in finite.items() if x <= TIE_FACTOR * low), key=len)
    return report
