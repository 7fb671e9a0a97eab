"""A full set of physically consistent standard parameters that reproduces identified minimal parameters.

Minimal (base) parameters fix only some combinations of the 10 standard parameters per body; the rest are
unidentifiable from momentum (or dynamics) and can take any value.  A user who needs a complete model back (a URDF
to simulate, plan or control with) needs one representative, and it has to be physically consistent: positive
mass and an inertia about the centre of mass that is positive definite and satisfies the triangle inequalities.

All of these conditions are one linear matrix inequality per body on the 4×4 pseudo-inertia (Wensing, Kim and
Slotine, "Linear matrix inequalities for physically consistent inertial parameter identification", 2017):

    J(P) = [[Σ, h], [hᵀ, m]] ⪰ 0,   Σ = ½ tr(I) 1 − I  (I about the body origin),  h = m c,

so the search is a convex program (cvxpy, solved by Clarabel, with SCS as a fallback):

  1. misfit  r* = min  ‖L (B P_u − φ̂)‖²  over J_i ⪰ ε 1         (L: whitening from the estimate's covariance)
  2. among the parameters with misfit ≤ r* + tol, the one closest to a prior model in the log-det (Bregman)
     divergence  d(J, J₀) = −log det J + tr(J₀⁻¹ J) + const  (Lee, Wensing and Park 2020), which is
     coordinate-free and keeps every J_i away from the boundary.

When the identified φ̂ admits a consistent representative (always for noise-free data of a consistent robot)
step 1 gives r* ≈ 0 and the result reproduces φ̂ to the solver's tolerance; otherwise it is the consistent model
whose minimal parameters are nearest φ̂ in the Mahalanobis metric, and `misfit` says how far that is.  Known bodies
(wheels) keep their parameters."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._core import InputError, NumericalError

#: smallest eigenvalue allowed for a pseudo-inertia, relative to the body's prior scale (strict consistency)
EPS_REL = 1e-6
#: whitened misfit per parameter below which step 1 counts as "phi is reachable" (then step 2 reproduces phi
#: exactly); otherwise step 2 may exceed the step-1 misfit by this relative slack
FEASIBLE_MISFIT, MISFIT_SLACK_REL = 1e-6, 1e-6


@dataclass
class ConsistentEstimate:
    """Physically consistent standard parameters reproducing (as nearly as possible) identified minimal ones."""

    parameters: np.ndarray  # (nbodies, 10) in the model's body order; known bodies unchanged
    minimal: np.ndarray  # (n_min,) the minimal parameters these standard parameters map to
    target: np.ndarray  # (n_min,) the identified minimal parameters they were fitted to
    misfit: float  # whitened residual norm ‖L (B P − φ̂)‖ (≈ number of standard deviations)
    max_rel_deviation: float  # max_i |(B P − φ̂)_i| / |φ̂_i| over nonzero φ̂_i
    min_eigenvalue: np.ndarray  # (n_unknown,) smallest eigenvalue of each unknown body's pseudo-inertia
    solver: str

    def model(self, model):
        """`model` with these parameters (a new, physically consistent Model)."""
        return model.with_parameters(self.parameters)


def pseudo_inertia(p) -> np.ndarray:
    """4×4 pseudo-inertia of standard parameters p = [m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]."""
    p = np.asarray(p, dtype=float)
    m, h = p[0], p[1:4]
    I = np.array([[p[4], p[5], p[7]], [p[5], p[6], p[8]], [p[7], p[8], p[9]]])
    J = np.empty((4, 4))
    J[:3, :3] = 0.5 * np.trace(I) * np.eye(3) - I
    J[:3, 3] = J[3, :3] = h
    J[3, 3] = m
    return J


def is_consistent(p, tol: float = 0.0) -> bool:
    """True when the pseudo-inertia of p is positive definite (eigenvalues > tol·scale)."""
    J = pseudo_inertia(p)
    return bool(np.linalg.eigvalsh(J)[0] > tol * max(np.abs(J).max(), 1e-300))


def consistent_parameters(mp, phi, covariance=None, prior=None, solver: str | None = None) -> ConsistentEstimate:
    """Physically consistent standard parameters of every body whose minimal parameters (`mp`) equal `phi`.

    mp: `MinimalParameters`; phi (n_min,): identified minimal parameters; covariance (n_min, n_min): their
    covariance (default: each parameter scaled by max(|phi_i|, 1e-6 · max|phi|)).  prior: a Model or (nbodies, 10)
    parameters that choose the unidentifiable part (default: mp.model's own parameters); bodies whose prior is not
    physically consistent get the nearest consistent pseudo-inertia as prior.  solver: a cvxpy solver name."""
    import cvxpy as cp

    model = mp.model
    phi = np.asarray(phi, dtype=float)
    if phi.shape != (mp.n_min,) or not np.all(np.isfinite(phi)):
        raise InputError(f"argument `phi`: expected {mp.n_min} finite numbers, got shape {phi.shape}")
    L = _whitening(phi, covariance)
    P_prior = _prior_parameters(model, prior)
    J0 = [_nearest_consistent(pseudo_inertia(P_prior[b])) for b in mp.unknown]

    # Decision variables: one symmetric 4x4 pseudo-inertia per unknown body; P is linear in them.
    Js = [cp.Variable((4, 4), symmetric=True) for _ in mp.unknown]
    P_u = cp.hstack([_standard_from_pseudo(J) for J in Js])
    resid = L @ (mp.matrix @ P_u - phi)
    scales = [max(np.abs(J).max(), 1e-12) for J in J0]
    lmi = [J >> EPS_REL * s * np.eye(4) for J, s in zip(Js, scales)]

    solvers = [solver] if solver else ["CLARABEL", "SCS"]
    step1 = cp.Problem(cp.Minimize(cp.sum_squares(resid)), lmi)
    used = _solve(step1, solvers, "misfit")
    r_star = float(step1.value)
    # Step 2: reproduce phi exactly when step 1 found it reachable, else stay within the step-1 misfit.
    if r_star <= FEASIBLE_MISFIT**2 * mp.n_min:
        fit = [mp.matrix @ P_u == phi]
    else:
        fit = [cp.sum_squares(resid) <= r_star * (1 + MISFIT_SLACK_REL)]
    # Divergence scaled per body so bodies of very different size count alike.
    div = sum(-cp.log_det(J / s) + cp.trace(np.linalg.inv(J0_ / s) @ (J / s)) for J, J0_, s in zip(Js, J0, scales))
    step2 = cp.Problem(cp.Minimize(div), lmi + fit)
    values = [J.value for J in Js]  # step 1's answer: consistent and nearest phi
    try:
        used = _solve(step2, solvers, "prior")
        values = [J.value for J in Js]
    except NumericalError:  # keep step 1's answer, but say that the prior was not used
        used += " (step 2 failed: nearest-misfit solution, prior not used)"

    P = np.array(model.parameters(), dtype=float)  # known bodies keep theirs
    for b, Jv in zip(mp.unknown, values):
        P[b] = _standard_from_pseudo_np(0.5 * (Jv + Jv.T))
    minimal = mp.from_standard(P)
    nz = phi != 0
    return ConsistentEstimate(
        parameters=P,
        minimal=minimal,
        target=phi,
        misfit=float(np.linalg.norm(L @ (minimal - phi))),
        max_rel_deviation=float(np.max(np.abs((minimal - phi)[nz] / phi[nz]))) if nz.any() else 0.0,
        min_eigenvalue=np.array([np.linalg.eigvalsh(pseudo_inertia(P[b]))[0] for b in mp.unknown]),
        solver=used,
    )


def representative_parameters(mp, phi, prior=None) -> np.ndarray:
    """(nbodies, 10) standard parameters that map exactly to `phi`, the smallest change of `prior` (default:
    mp.model's parameters) that does: P_u = P0 + Bᵀ(BBᵀ)⁻¹(φ − B P0).  Linear and exact, but not necessarily
    physically consistent — use it when only momentum and dynamics matter (prediction), e.g. for a robot whose
    true parameters are themselves inconsistent (Naveen, Shah, Misra Table 2)."""
    phi = np.asarray(phi, dtype=float)
    if phi.shape != (mp.n_min,) or not np.all(np.isfinite(phi)):
        raise InputError(f"argument `phi`: expected {mp.n_min} finite numbers, got shape {phi.shape}")
    P = _prior_parameters(mp.model, prior)
    P[mp.known] = mp.model.parameters()[mp.known]
    B = mp.matrix
    P0 = P[mp.unknown].ravel()
    P[mp.unknown] = (P0 + B.T @ np.linalg.solve(B @ B.T, phi - B @ P0)).reshape(len(mp.unknown), 10)
    return P


def _pseudo_to_standard_map() -> np.ndarray:
    """T (10 × 16) with P = T vec(J) for a symmetric pseudo-inertia J (vec in either order: J is symmetric):
    m = J₃₃, h = J_{i3}, and I = tr(Σ) 1 − Σ with Σ the upper-left block."""
    T = np.zeros((10, 16))
    e = lambda r, c: 4 * r + c  # noqa: E731 - index of J[r, c] in vec(J)
    T[0, e(3, 3)] = 1.0
    for k in range(3):
        T[1 + k, e(k, 3)] = 1.0
    for row, (a, b) in ((4, (1, 2)), (6, (0, 2)), (9, (0, 1))):  # Ixx = Σyy + Σzz, ...
        T[row, e(a, a)] = T[row, e(b, b)] = 1.0
    for row, (a, b) in ((5, (0, 1)), (7, (0, 2)), (8, (1, 2))):  # Ixy = −Σxy, ...
        T[row, e(a, b)] = -1.0
    return T


#: standard parameters from a pseudo-inertia, the one linear map used for both cvxpy variables and numbers
PSEUDO_TO_STANDARD = _pseudo_to_standard_map()


def _standard_from_pseudo(J):
    """cvxpy expression J (symmetric 4×4 variable) -> its 10 standard parameters."""
    import cvxpy as cp

    return PSEUDO_TO_STANDARD @ cp.vec(J, order="C")


def _standard_from_pseudo_np(J) -> np.ndarray:
    return PSEUDO_TO_STANDARD @ np.asarray(J, dtype=float).ravel()


def _whitening(phi, covariance) -> np.ndarray:
    """L with LᵀL = Σ⁻¹ (Cholesky of the inverse covariance), or a diagonal relative scaling."""
    if covariance is None:
        floor = 1e-6 * max(np.abs(phi).max(), 1e-300)
        return np.diag(1.0 / np.maximum(np.abs(phi), floor))
    C = np.asarray(covariance, dtype=float)
    if C.shape != (phi.size, phi.size) or not np.all(np.isfinite(C)):
        raise InputError(f"argument `covariance`: expected a finite ({phi.size}, {phi.size}) matrix, got {C.shape}")
    C = 0.5 * (C + C.T)
    w, V = np.linalg.eigh(C)
    if w[0] <= 0:
        raise InputError(f"argument `covariance`: not positive definite (smallest eigenvalue {w[0]:.3g})")
    return (V / np.sqrt(w)).T  # rows: eigen-directions scaled by 1/sigma


def _prior_parameters(model, prior) -> np.ndarray:
    if prior is None:
        return model.parameters()
    P = prior.parameters() if hasattr(prior, "parameters") else np.asarray(prior, dtype=float)
    if P.shape != (model.nbodies, 10) or not np.all(np.isfinite(P)):
        raise InputError(f"argument `prior`: expected ({model.nbodies}, 10) finite parameters, got {P.shape}")
    return np.array(P, dtype=float)


def _nearest_consistent(J) -> np.ndarray:
    """J with its eigenvalues raised to at least 1e-3 of its largest: a usable (positive-definite) prior."""
    w, V = np.linalg.eigh(0.5 * (J + J.T))
    w = np.maximum(w, 1e-3 * max(np.abs(w).max(), 1e-12))
    return (V * w) @ V.T


def _solve(problem, solvers, what) -> str:
    import warnings

    last = None
    for s in solvers:
        try:
            with warnings.catch_warnings():  # an inaccurate solve is reported in the returned name instead
                warnings.simplefilter("ignore", UserWarning)
                problem.solve(solver=s)
        except Exception as e:  # solver missing or failed: try the next one
            last = e
            continue
        if problem.status == "optimal":
            return s
        if problem.status == "optimal_inaccurate":
            return f"{s} (inaccurate)"
        last = problem.status
    raise NumericalError(f"consistent_parameters: the {what} program was not solved ({last})")
