"""Least-squares identification of the minimal inertial parameters from momentum (Naveen, Shah, Misra, eqs. 26-27).

`least_squares(model, Q, V, H, mp)` solves `G_m phi_m = m` (eq. 26: the minimal regressor stacked over samples,
with the known bodies' momentum moved to the right-hand side) in Rust, streaming over the samples so the
6T x n_min regressor is never formed.  Accuracy is that of a QR of the whole matrix: the engine uses the normal
equations (eq. 27) only when the measured condition number allows it, followed by one refinement pass on the true
residual, and a streaming Householder QR otherwise (see `freefloat_core::estimation`).  The result carries the
covariance sigma^2 (G^T W G)^-1 with sigma^2 = RSS / (6T - n_min), and `relative_errors` gives the paper's error
figures (eqs. 38-39).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._core import InputError, NumericalError


@dataclass
class LeastSquaresResult:
    """Estimate of the minimal parameters with its statistics (order and names as `mp.names`)."""

    estimate: np.ndarray  # (n_min,)  phi_m hat
    std: np.ndarray  # (n_min,)  sqrt(diag(covariance))
    covariance: np.ndarray  # (n_min, n_min)  sigma^2 (G^T W G)^-1
    rss: float  # weighted residual sum of squares
    dof: int  # rows - n_min
    condition_number: float  # 2-norm condition number of the weighted regressor G_m
    rows: int  # 6 x samples
    method: str  # "normal equations", "normal equations + refinement" or "streaming QR"
    names: list = field(default_factory=list)

    @property
    def sigma(self) -> float:
        """Residual standard deviation sqrt(RSS / dof)."""
        return float(np.sqrt(self.rss / self.dof)) if self.dof > 0 else float("nan")


def absolute_columns(mp) -> np.ndarray:
    """mp's kept columns (indices into the unknown bodies' 10*len(unknown) columns) as indices into 10*nbodies."""
    unknown_cols = np.array([10 * b + k for b in mp.unknown for k in range(10)], dtype=int)
    return unknown_cols[np.asarray(mp.columns, dtype=int)]


def known_parameters(mp, P_known=None) -> np.ndarray:
    """(10*nbodies,) standard parameters with the known bodies' rows from P_known (default: the model's) and
    zeros for the unknown bodies."""
    P = mp.model.parameters() if P_known is None else np.asarray(P_known, dtype=float)
    if P.shape != (mp.model.nbodies, 10):
        raise InputError(f"argument `P_known`: expected shape ({mp.model.nbodies}, 10), got {P.shape}")
    out = np.zeros_like(P)
    out[mp.known] = P[mp.known]
    return out.ravel()


def least_squares(model, Q, V, H, mp, P_known=None, weights=None, method: str = "auto") -> LeastSquaresResult:
    """Minimal parameters of `mp` (a `MinimalParameters` of `model`) from measured momenta.

    Q (T, nq), V (T, nv): states; H (T, 6): measured total momentum [p; L] about the inertial origin (e.g.
    `traj.momentum`).  The known bodies' momentum (parameters from P_known, default the model's) is subtracted.
    weights (6,): inverse variances of the six momentum components.  method: "auto" or "qr" (always the
    streaming QR).  Raises NumericalError naming the unexcited parameter combinations if the data do not
    excite every minimal parameter (the index k in x[k] is the position in mp.names).
    """
    if mp.model is not model and getattr(mp.model, "_core", None) is not getattr(model, "_core", None):
        raise InputError("argument `mp`: minimal parameters of another model")
    w = None if weights is None else np.ascontiguousarray(weights, dtype=float)
    try:
        out = _core.identify_momentum(
            model,
            np.ascontiguousarray(Q, dtype=float),
            np.ascontiguousarray(V, dtype=float),
            np.ascontiguousarray(H, dtype=float),
            absolute_columns(mp).tolist(),
            known_parameters(mp, P_known),
            w,
            method,
        )
    except NumericalError as e:  # name the unexcited parameters: x[k] -> x[k](base.Ixx)
        raise NumericalError(re.sub(r"x\[(\d+)\]", lambda g: f"{g[0]}({mp.names[int(g[1])]})", str(e))) from None
    return LeastSquaresResult(
        estimate=out["x"],
        std=out["std"],
        covariance=out["covariance"],
        rss=out["rss"],
        dof=out["dof"],
        condition_number=out["condition_number"],
        rows=out["rows"],
        method=out["method"],
        names=list(mp.names),
    )


def relative_errors(estimate, truth) -> tuple[float, float]:
    """Naveen, Shah, Misra's error figures in percent: (median_i |(phi_i - phi_hat_i) / phi_i|, max_i ...)
    (eqs. 38, 39)."""
    est, tru = np.asarray(estimate, dtype=float), np.asarray(truth, dtype=float)
    if est.shape != tru.shape or est.ndim != 1:
        raise InputError(f"arguments `estimate`, `truth`: expected two equal 1-d shapes, got {est.shape}, {tru.shape}")
    if np.any(tru == 0.0):
        raise InputError("argument `truth`: a zero entry has no relative error (eqs. 38-39 divide by phi_i)")
    rel = np.abs((tru - est) / tru) * 100.0
    return float(np.median(rel)), float(np.max(rel))
