"""Minimal (base) inertial parameters of the momentum model.

The momentum of a free-floating tree is linear in the standard parameters, `h = K(q, v) @ P.ravel()`, but the
columns of K are not independent: every revolute joint makes three of its child's columns combinations of the
parent's (Naveen, Shah, Misra, eqs. 18-20).  `minimal_parameters` finds a linear map B and a column subset so that

    K_unknown @ P_unknown.ravel() == K_min @ phi_min,   phi_min = B @ P_unknown.ravel(),   K_min = K_unknown[:, columns]

for every state.  Two methods:

* "numeric": any model.  Rank-revealing QR of the regressor stacked over random states (Gautier's method).
* "closed-form": Naveen, Shah, Misra's recursive grouping (eqs. 21-25) for revolute trees in modified-DH
  frames; names and order follow the paper's Table 4 / Appendix A.

Bodies treated as known (default: tagged "known" or "wheel") are not identified; their momentum is moved to the
right-hand side (`known_momentum`).  This is a one-off structural computation, so it is plain numpy/scipy.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .._core import InputError, ModelError
from ..algorithms import momentum_regressor

#: our standard-parameter order (ARCHITECTURE.md), used to name columns
PARAM_NAMES = ("m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
#: Naveen, Shah, Misra's order [Ixx Iyy Izz Ixy Iyz Izx m mx my mz] (eq. 10) as indices into ours
PAPER_ORDER = np.array([4, 6, 9, 5, 8, 7, 0, 1, 2, 3])
#: relative tolerance on |R_kk| / |R_00| of the column-scaled, pivoted QR; the seed-001 gap is ~1e-3 -> ~1e-16
RANK_RTOL = 1e-10
#: a column whose norm is below this fraction of the largest never moves (e.g. a fixed base): unidentifiable
DEAD_RTOL = 1e-13
#: coefficients smaller than this (relative to the row's largest) are structural zeros polluted by round-off
COEF_CLEAN = 1e-9
N_STATES = 50
SEED = 20261122


class MinimalParameters:
    """Result of `minimal_parameters`: names, the map B, the kept regressor columns and helpers."""

    def __init__(self, model, unknown, known, matrix, columns, names, method, rank):
        self.model = model
        self.unknown = list(unknown)  # body indices identified, in model order
        self.known = list(known)  # body indices on the right-hand side
        self.matrix = np.asarray(matrix)  # B: (n_min, 10 * len(unknown))
        self.columns = np.asarray(columns, dtype=int)  # columns of K_unknown forming K_min; B[:, columns] == I
        self.names = list(names)
        self.method = method
        self.rank = rank

    @property
    def n_min(self) -> int:
        return self.matrix.shape[0]

    def standard_names(self) -> list[str]:
        """Name of every column of K_unknown, e.g. 'L1.mcz'."""
        bn = self.model.body_names
        return [f"{bn[b]}.{p}" for b in self.unknown for p in PARAM_NAMES]

    def expressions(self, digits: int = 6) -> list[str]:
        """Each minimal parameter as a linear combination of standard parameters (like Naveen, Shah, Misra,
        Appendix A)."""
        cols = self.standard_names()
        return [_format_row(row, cols, digits) for row in self.matrix]

    def from_standard(self, P) -> np.ndarray:
        """(nbodies, 10) standard parameters of the whole model -> (n_min,) minimal parameters."""
        P = np.asarray(P, dtype=float)
        if P.shape != (self.model.nbodies, 10):
            raise InputError(f"argument `P`: expected shape ({self.model.nbodies}, 10), got {P.shape}")
        return self.matrix @ P[self.unknown].ravel()

    def regressor(self, q, v) -> np.ndarray:
        """K_min (6, n_min) or (T, 6, n_min): momentum of the unknown bodies == K_min @ phi_min."""
        return self._full_regressor(q, v)[..., self._unknown_cols()[self.columns]]

    def known_momentum(self, q, v, P=None) -> np.ndarray:
        """Momentum (6,) or (T, 6) of the known bodies, with the model's parameters (or P's rows for them)."""
        P = self.model.parameters() if P is None else np.asarray(P, dtype=float)
        K = self._full_regressor(q, v)
        cols = _body_columns(self.known)
        return K[..., cols] @ P[self.known].ravel()

    def regressor_and_known_momentum(self, q, v, P=None):
        """(`regressor(q, v)`, `known_momentum(q, v, P)`) from one build of the momentum regressor."""
        P = self.model.parameters() if P is None else np.asarray(P, dtype=float)
        K = self._full_regressor(q, v)
        return K[..., self._unknown_cols()[self.columns]], K[..., _body_columns(self.known)] @ P[self.known].ravel()

    def _full_regressor(self, q, v):
        return momentum_regressor(self.model, q, v)

    def _unknown_cols(self):
        return _body_columns(self.unknown)

    def __repr__(self) -> str:
        return (
            f"MinimalParameters({self.model.name!r}, method={self.method!r}, "
            f"n_min={self.n_min}, unknown={len(self.unknown)} bodies)"
        )


def minimal_parameters(model, method: str = "numeric", known=None) -> MinimalParameters:
    """Minimal parameters of `model`'s momentum model.

    method: "numeric" (any model), "closed-form" (Naveen, Shah, Misra's grouping; revolute trees in
      modified-DH frames), or "auto": the closed form where it applies, else numeric (the command line's default,
      and `identify_minimal`'s, so both give the same names in the same order).
    known: body names treated as known (moved to the right-hand side); default: bodies tagged "known" or "wheel".
    """
    if method == "auto":  # the closed form where it applies (its names follow the paper), else numeric
        try:
            return minimal_parameters(model, "closed-form", known)
        except (ModelError, ValueError):
            return minimal_parameters(model, "numeric", known)
    unknown, known_idx = _split_bodies(model, known)
    if method == "numeric":
        return _numeric(model, unknown, known_idx)
    if method in ("closed-form", "closed_form", "closedform"):
        return _closed_form(model, unknown, known_idx)
    raise InputError(f"argument `method`: expected 'numeric' or 'closed-form', got {method!r}")


# ---------------------------------------------------------------------------------------------------- helpers
def check_known(model, known) -> None:
    """An InputError naming `known`, the bodies that do not exist and the model's bodies (the list a user needs)."""
    if known is None:
        return
    if isinstance(known, str):
        known = [known]
    names = list(model.body_names)
    missing = [n for n in known if n not in names]
    if missing:
        raise InputError(
            f"argument `known`: {', '.join(repr(n) for n in missing)} "
            f"{'is not a body' if len(missing) == 1 else 'are not bodies'} of model '{model.name}'; its bodies are "
            f"{', '.join(names)}"
        )


def _split_bodies(model, known):
    if known is None:
        known_idx = [i for i, t in enumerate(model.tags) if "known" in t or "wheel" in t]
    else:
        check_known(model, known)
        known_idx = sorted(model.body_index(n) for n in ([known] if isinstance(known, str) else known))
    unknown = [i for i in range(model.nbodies) if i not in known_idx]
    if not unknown:
        raise InputError("every body is declared known: there is nothing to identify")
    return unknown, known_idx


def _body_columns(bodies) -> np.ndarray:
    return np.array([10 * b + k for b in bodies for k in range(10)], dtype=int)


def _format_row(row, cols, digits) -> str:
    terms = []
    for c, name in zip(row, cols):
        if c == 0.0:
            continue
        mag = abs(c)
        coef = "" if np.isclose(mag, 1.0, rtol=0, atol=10.0 ** -(digits + 2)) else f"{mag:.{digits}g}*"
        terms.append(("- " if c < 0 else "+ ") + coef + name)
    if not terms:
        return "0"
    s = " ".join(terms)
    return s[2:] if s.startswith("+ ") else "-" + s[2:]


# ---------------------------------------------------------------------------------------------------- numeric
def _stacked_regressor(model, unknown, n_states=N_STATES, seed=SEED) -> np.ndarray:
    """K_unknown stacked over random states (6*n_states, 10*len(unknown)); fixed seed -> deterministic."""
    rng = np.random.default_rng(seed)
    Q = np.array([model.random_configuration(rng) for _ in range(n_states)])
    V = rng.normal(size=(n_states, model.nv))
    K = momentum_regressor(model, Q, V)[..., _body_columns(unknown)]
    return K.reshape(-1, K.shape[-1])


def _numeric(model, unknown, known) -> MinimalParameters:
    """Gautier's rank-revealing QR: G S Π = Q R; the first r pivots are independent, the others are
    combinations of them, G_dep = G_indep X with X = S_I⁻¹ R11⁻¹ R12 S_D (S: column scales)."""
    G = _stacked_regressor(model, unknown)
    n = G.shape[1]
    scale = np.linalg.norm(G, axis=0)
    # Columns that vanish at every state (e.g. a parameter that never moves) are unidentifiable and
    # contribute nothing: they are dependent with zero coefficients.
    live = scale > DEAD_RTOL * scale.max()
    Gs = G[:, live] / scale[live]
    _, R, piv = scipy.linalg.qr(Gs, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    r = int(np.sum(d > RANK_RTOL * d[0]))
    live_idx = np.flatnonzero(live)
    X = scipy.linalg.solve_triangular(R[:r, :r], R[:r, r:])  # scaled: Gs_dep = Gs_indep @ X
    indep, dep = live_idx[piv[:r]], live_idx[piv[r:]]
    X = X * scale[dep][None, :] / scale[indep][:, None]  # G_dep = G_indep diag(1/s_I) X diag(s_D)
    # B: phi_min = P_indep + X @ P_dep (then K P = K_indep phi_min); rows sorted by column index for readability.
    B = np.zeros((r, n))
    B[np.arange(r), indep] = 1.0
    B[:, dep] = X
    order = np.argsort(indep)
    B, indep = B[order], indep[order]
    B[np.abs(B) < COEF_CLEAN * np.abs(B).max(axis=1, keepdims=True)] = 0.0
    names = _numeric_names(model, unknown, B, indep)
    return MinimalParameters(model, unknown, known, B, indep, names, "numeric", r)


def _numeric_names(model, unknown, B, indep) -> list[str]:
    """The kept standard parameter's name, with 'R' (regrouped, Khalil's notation) if others are folded in."""
    cols = [f"{model.body_names[b]}.{p}" for b in unknown for p in PARAM_NAMES]
    return [cols[c] + ("R" if np.count_nonzero(row) > 1 else "") for row, c in zip(B, indep)]


# ---------------------------------------------------------------------------------------------- closed form
def _check_closed_form_model(model, unknown):
    """Naveen, Shah, Misra's grouping assumes a free base and revolute joints about z of modified-DH frames whose rest
    placement is Rx(α_j) with an arbitrary offset ^i b_j."""
    hint = 'use method="numeric", which works for any model'
    if model.joint_types[0] != "free" or 0 not in unknown:
        raise ModelError(f"closed-form minimal parameters need an unknown free-floating base; {hint}")
    for j in unknown[1:]:
        name, parent = model.body_names[j], model.parents[j]
        if model.joint_types[j] != "revolute":
            raise ModelError(
                f"closed-form: body '{name}' has a {model.joint_types[j]} joint (only revolute is covered); {hint}"
            )
        if parent not in unknown:
            raise ModelError(
                f"closed-form: body '{name}' hangs from the known body '{model.body_names[parent]}'; {hint}"
            )
        if not np.allclose(model.joint_axes[j], [0, 0, 1], atol=1e-12):
            raise ModelError(f"closed-form: joint of '{name}' is not about its frame's z axis (modified DH); {hint}")
        R = model.placements[j][:3, :3]
        if not (np.allclose(R[0], [1, 0, 0], atol=1e-12) and np.allclose(R[:, 0], [1, 0, 0], atol=1e-12)):
            raise ModelError(f"closed-form: placement of '{name}' is not a pure rotation about x (Rx(alpha)); {hint}")


def _dh_geometry(model, j):
    """(^i b_j, α_j) from the rest placement [Rx(α_j), ^i b_j] of joint j in its parent (eqs. 14-15, 43)."""
    T = model.placements[j]
    return T[:3, 3].copy(), float(np.arctan2(T[2, 1], T[1, 1]))


def _k_vectors(b, alpha):
    """k_{1,j}, k_{2,j}, k_{3,j} of Naveen, Shah, Misra, 10-vectors in the paper's order
    [Ixx Iyy Izz Ixy Iyz Izx m mx my mz]."""
    C, S = np.cos(alpha), np.sin(alpha)
    b1, b2, b3 = b
    t1 = [1, C * C, S * S, 0, C * S, 0]  # eq. (18)
    t2 = [2 * b3 * C - 2 * b2 * S, 2 * b3 * C, -2 * b2 * S, b1 * S, b3 * S - b2 * C, -b1 * C]  # eq. (20)
    t3 = [0, -S, C]
    # −[•(b̃)²] (eq. 19; the printed k_2 lacks the square)
    bb = [b2 * b2 + b3 * b3, b1 * b1 + b3 * b3, b1 * b1 + b2 * b2, -b1 * b2, -b2 * b3, -b1 * b3]
    k1 = np.array(t1 + [0, 0, 0, 0], dtype=float)
    k2 = np.array(bb + [1, b1, b2, b3], dtype=float)
    k3 = np.array(t2 + [0] + t3, dtype=float)
    return k1, k2, k3


#: kept entries of a non-base link, paper indexing: D(φ̃) = [XX−YY, ZZ, XY, YZ, ZX, MX, MY] (eq. 22)
KEPT_PAPER = [0, 2, 3, 4, 5, 7, 8]
KEPT_LABELS = ["Ixx-Iyy", "Izz", "Ixy", "Iyz", "Ixz", "mcx", "mcy"]  # our names (Izx == Ixz)
BASE_LABELS = ["Ixx", "Iyy", "Izz", "Ixy", "Iyz", "Ixz", "m", "mcx", "mcy", "mcz"]


def _group(phi, parents, geometry):
    """Naveen, Shah, Misra's recursion on paper-ordered parameters phi (nb, 10) of the unknown tree (local indices,
    parents[j] < j).  Returns φ_m (10 + 7 n).  Linear in phi."""
    ph = np.array(phi, dtype=float)
    for j in range(len(ph) - 1, 0, -1):  # children first: eqs. (21)-(23)
        k1, k2, k3 = geometry[j]
        ph[parents[j]] += ph[j, 1] * k1 + ph[j, 6] * k2 + ph[j, 9] * k3
    out = [ph[0]]  # base keeps all 10 (eq. 23)
    for j in range(1, len(ph)):
        d = ph[j, KEPT_PAPER].copy()
        d[0] -= ph[j, 1]  # XX ← XX − YY after the children were added (eq. 22)
        out.append(d)
    return np.concatenate(out)  # eq. (25)


def _closed_form(model, unknown, known) -> MinimalParameters:
    _check_closed_form_model(model, unknown)
    local = {b: k for k, b in enumerate(unknown)}
    parents = [-1] + [local[model.parents[j]] for j in unknown[1:]]
    geometry = [None] + [_k_vectors(*_dh_geometry(model, j)) for j in unknown[1:]]
    nu = len(unknown)
    # The recursion is linear: build B column by column from unit standard-parameter vectors (our order).
    B = np.zeros((10 + 7 * (nu - 1), 10 * nu))
    for c in range(10 * nu):
        P = np.zeros(10 * nu)
        P[c] = 1.0
        B[:, c] = _group(P.reshape(nu, 10)[:, PAPER_ORDER], parents, geometry)
    B[np.abs(B) < 1e-14] = 0.0
    # The kept regressor columns: base in the paper's order, then D(K_i) (eq. 24) mapped to our order.
    columns = list(PAPER_ORDER) + [10 * k + PAPER_ORDER[p] for k in range(1, nu) for p in KEPT_PAPER]
    bn = model.body_names
    names = [f"{bn[unknown[0]]}.{lab}" for lab in BASE_LABELS]
    names += [f"{bn[b]}.{lab}" for b in unknown[1:] for lab in KEPT_LABELS]
    names = [f"phi_m({k + 1}) {n}" for k, n in enumerate(names)]
    return MinimalParameters(model, unknown, known, B, columns, names, "closed-form", B.shape[0])
