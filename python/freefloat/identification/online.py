"""Online (recursive) estimators, computed in Rust one sample at a time (O(1) per sample).

- `RecursiveLS(theta0, p0, forgetting=1.0)`: ordinary RLS for `phi @ theta = y` (rows of one sample in `phi`),
  with an optional forgetting factor.
- `ModifiedRLS(coupling, mu0, p_mu0, theta0, p_theta0)`: Zhang, Yue, Yuan 2020's modified RLS (eqs. 34-38) for
  `A mu = b` and `Phi theta = y + Psi D(mu)`, `D(mu) = [m_1 J(b'_1); m_n J(b'_n)]`; coupling "spatial" (3D)
  or "planar".

`update(...)` takes one sample; `run(...)` many (leading sample axis, one call into Rust) and returns the estimate
after every sample. Covariances are given as a diagonal (n,) or in full (n, n). Bad samples (NaN, time not
increasing, wrong shapes) raise `InputError` naming the sample; a covariance that loses positive definiteness
raises `NumericalError` and the estimator refuses further samples: it never returns NaN silently."""

from __future__ import annotations

import numpy as np

from .. import _core
from .._arrays import as_f64


class RecursiveLS:
    def __init__(self, theta0, p0, forgetting: float = 1.0):
        self._core = _core.RecursiveLS(as_f64(theta0, "theta0").ravel(), as_f64(p0, "p0"), float(forgetting))

    def update(self, t: float, phi, y) -> np.ndarray:
        """Fold in one sample: phi (r, n), y (r,). Returns the new estimate."""
        y = np.atleast_1d(as_f64(y, "y"))
        self._core.update(float(t), as_f64(phi, "phi").reshape(len(y), -1), y)
        return self.estimate

    def run(self, t, phi, y) -> np.ndarray:
        """Many samples: t (N,), phi (N, r, n), y (N, r). Returns the estimates (N, n)."""
        return self._core.run(as_f64(t, "t"), as_f64(phi, "phi"), as_f64(y, "y"))

    @property
    def estimate(self) -> np.ndarray:
        return self._core.estimate

    @property
    def covariance(self) -> np.ndarray:
        return self._core.covariance

    @property
    def samples(self) -> int:
        return self._core.samples


class ModifiedRLS:
    def __init__(self, coupling: str, mu0, p_mu0, theta0, p_theta0):
        self._core = _core.ModifiedRLS(
            coupling,
            as_f64(mu0, "mu0").ravel(),
            as_f64(p_mu0, "p_mu0"),
            as_f64(theta0, "theta0").ravel(),
            as_f64(p_theta0, "p_theta0"),
        )

    def update(self, t: float, a, b, phi, y, psi):
        """One sample: a (r_mu, n_mu), b (r_mu,), phi (r_th, n_th), y (r_th,), psi (r_th, n_D). Returns (mu, theta)."""
        b, y = np.atleast_1d(as_f64(b, "b")), np.atleast_1d(as_f64(y, "y"))
        self._core.update(
            float(t),
            as_f64(a, "a").reshape(len(b), -1),
            b,
            as_f64(phi, "phi").reshape(len(y), -1),
            y,
            as_f64(psi, "psi").reshape(len(y), -1),
        )
        return self.mu, self.theta

    def run(self, t, a, b, phi, y, psi):
        """Many samples (leading axis N). Returns (mu (N, n_mu), theta (N, n_th))."""
        return self._core.run(
            as_f64(t, "t"), as_f64(a, "a"), as_f64(b, "b"), as_f64(phi, "phi"), as_f64(y, "y"), as_f64(psi, "psi")
        )

    @property
    def mu(self) -> np.ndarray:
        return self._core.mu

    @property
    def theta(self) -> np.ndarray:
        return self._core.theta

    @property
    def samples(self) -> int:
        return self._core.samples
