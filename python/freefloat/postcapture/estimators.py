"""Both solvers on both equation forms (Zhang, Yue, Yuan 2020): the paper's modified RLS on its parameters
(eqs. 34-38) and an ordinary RLS on the standard inertial parameters, started from the scenario's guesses;
the true parameter vector and the residuals of the equations at it."""

from __future__ import annotations

import numpy as np

from .._core import InputError
from ..identification import online
from . import equations as eq
from .scenario import Scenario

METHODS = ("momentum", "force")
SOLVERS = ("modified_rls", "standard_rls")
#: the solvers' names in tables and figures
SOLVER_TITLES = {"modified_rls": "paper (modified RLS)", "standard_rls": "standard params (RLS)"}


def is_product(name: str) -> bool:
    """Whether a parameter name is a product of inertia (Ixy, Ixz, Iyz of any body)."""
    return name[-2:] in ("xy", "xz", "yz") and name[0] == "I"


def parameter_names(planar: bool) -> list[str]:
    if planar:
        return ["m1", "b1x", "b1y", "I1", "mn", "bnx", "bny", "In"]
    body = lambda s: [
        f"m{s}",
        f"b{s}x",
        f"b{s}y",
        f"b{s}z",
        f"I{s}xx",
        f"I{s}xy",
        f"I{s}xz",
        f"I{s}yy",
        f"I{s}yz",
        f"I{s}zz",
    ]  # noqa: E731
    return body("1") + body("n")


def _physical(planar, m1, b1, I1, mn, bn, In) -> np.ndarray:
    """Histories → (N, P) in parameter_names order. b: (N, 3); I: (N, 3, 3)."""
    if planar:
        return np.stack([m1, b1[:, 0], b1[:, 1], I1[:, 2, 2], mn, bn[:, 0], bn[:, 1], In[:, 2, 2]], -1)
    f = lambda m, b, I: [
        m,
        b[:, 0],
        b[:, 1],
        b[:, 2],
        I[:, 0, 0],
        I[:, 0, 1],
        I[:, 0, 2],
        I[:, 1, 1],
        I[:, 1, 2],
        I[:, 2, 2],
    ]  # noqa: E731
    return np.stack(f(m1, b1, I1) + f(mn, bn, In), -1)


def _sharp_to_matrix(s):
    return np.stack(
        [
            np.stack([s[:, 0], s[:, 1], s[:, 2]], -1),
            np.stack([s[:, 1], s[:, 3], s[:, 4]], -1),
            np.stack([s[:, 2], s[:, 4], s[:, 5]], -1),
        ],
        -2,
    )


def initial_guesses(sc: Scenario, planar: bool):
    """Initial guesses (m, b', I'_c) of base and target from the scenario (the paper's §V values)."""
    out = []
    for key in ("base", "target"):
        g = sc.guess[key]
        b = np.zeros(3)
        b[: len(g["com"])] = g["com"]
        I = np.asarray(g["inertia"], float)
        Ic = np.diag(np.full(3, float(I))) if I.ndim == 0 else (np.diag(I) if I.ndim == 1 else I)
        out.append((float(g["mass"]), b, Ic))
    return out


def identify_modified(model, rows: eq.PaperRows, sc: Scenario, planar: bool) -> np.ndarray:
    """The paper's modified RLS (eqs. 34-38) over the rows; returns (N, P) physical parameters."""
    L = eq.Layout(planar)
    (m1, b1, I1), (mn, bn, In) = initial_guesses(sc, planar)
    mu0 = np.concatenate([np.concatenate([[m], m * b])[L.mu_cols] for m, b in ((m1, b1), (mn, bn))])
    th0 = np.concatenate([eq.inertia_sharp(I)[L.th_cols] for I in (I1, In)])
    est = online.ModifiedRLS(L.coupling, mu0, np.full(len(mu0), sc.P0), th0, np.full(len(th0), sc.P0))
    mu, th = est.run(rows.t, rows.A, rows.b, rows.Phi, rows.y, rows.Psi)
    k = len(L.mu_cols)
    hist = []
    for body in range(2):
        m = mu[:, body * k]
        b = np.zeros((len(m), 3))
        b[:, : k - 1] = mu[:, body * k + 1 : (body + 1) * k] / m[:, None]
        if planar:
            I = np.zeros((len(m), 3, 3))
            I[:, 2, 2] = th[:, body]
        else:
            I = _sharp_to_matrix(th[:, 6 * body : 6 * body + 6])
        hist += [m, b, I]
    return _physical(planar, *hist)


def identify_standard(
    model, rows: eq.StandardRows, sc: Scenario, planar: bool, forgetting: float | None = None, project: bool = False
) -> np.ndarray:
    """Ordinary RLS on the standard parameters; returns (N, P) physical parameters."""
    L = eq.Layout(planar)
    x0 = np.concatenate([eq.standard_vector(*g)[L.std_cols] for g in initial_guesses(sc, planar)])
    est = online.RecursiveLS(x0, np.full(len(x0), sc.P0), sc.forgetting if forgetting is None else forgetting)
    x = est.run(rows.t, rows.Phi, rows.y)
    k = len(L.std_cols)
    hist = []
    for body in range(2):
        full = np.zeros((len(x), 10))
        full[:, L.std_cols] = x[:, body * k : (body + 1) * k]
        if planar:
            # Out-of-plane inertia is not identifiable in planar motion. Complete it as an isotropic CoM
            # inertia (as the model files do) so the projection sees a body: I_ref = I_czz 1 + (|h|²1 − hhᵀ)/m,
            # which keeps the identified I_ref,zz.
            m_, h = full[:, 0], full[:, 1:4]
            iczz = full[:, 9] - (h[:, 0] ** 2 + h[:, 1] ** 2) / m_
            Io = (
                iczz[:, None, None] * np.eye(3)
                + (np.einsum("ti,ti->t", h, h)[:, None, None] * np.eye(3) - np.einsum("ti,tj->tij", h, h))
                / m_[:, None, None]
            )
            full[:, 4:] = np.stack([Io[:, 0, 0], Io[:, 0, 1], Io[:, 1, 1], Io[:, 0, 2], Io[:, 1, 2], Io[:, 2, 2]], -1)
        if project:
            full = eq.project_consistent(full)
        m, b, I = eq.from_standard(full)
        hist += [m, b, I]
    return _physical(planar, *hist)


def truth_vector(model, planar: bool) -> np.ndarray:
    base, target = 0, target_index(model)
    (m1, b1, I1), (mn, bn, In) = eq.body_truth(model, base), eq.body_truth(model, target)
    one = lambda x: x[None]  # noqa: E731
    return _physical(planar, np.array([m1]), one(b1), one(I1), np.array([mn]), one(bn), one(In))[0]


def target_index(model) -> int:
    idx = [i for i, tags in enumerate(model.tags) if "target" in tags]
    if len(idx) != 1:
        raise InputError(f"model '{model.name}' must have exactly one body tagged 'target' (found {len(idx)})")
    i = idx[0]
    # The paper's target is rigidly grasped: a fixed joint on the end-effector link.
    if model.joint_types[i] != "fixed" or any(model.parents[j] == i for j in range(model.nbodies)):
        raise InputError(
            f"the target '{model.body_names[i]}' must be welded to the end effector (a leaf body on a fixed joint)"
        )
    return i


def equation_residuals(model, pr: eq.PaperRows, sr: eq.StandardRows, planar, base, target) -> dict:
    """Largest residual of each regression at the model file's true parameters, and the size of the
    right-hand side, so that a reader can see the equations hold (noise-free data)."""
    L = eq.Layout(planar)
    (m1, b1, I1), (mn, bn, In) = eq.body_truth(model, base), eq.body_truth(model, target)
    mu = np.concatenate([np.concatenate([[m], m * b])[L.mu_cols] for m, b in ((m1, b1), (mn, bn))])
    th = np.concatenate([eq.inertia_sharp(I)[L.th_cols] for I in (I1, In)])
    D = np.concatenate([eq.mJ(m1, b1)[L.d_cols], eq.mJ(mn, bn)[L.d_cols]])
    if planar:
        D[3] = m1 * (b1 @ b1)
        D[7] = mn * (bn @ bn)
    P = np.array(model.parameters(), float)
    x = np.concatenate([P[base][L.std_cols], P[target][L.std_cols]])
    lin = np.abs(eq.mv(pr.A, mu) - pr.b).max()
    ang = np.abs(eq.mv(pr.Phi, th) - pr.y - eq.mv(pr.Psi, D)).max()
    std = np.abs(eq.mv(sr.Phi, x) - sr.y).max()
    return {
        "paper_linear": float(lin),
        "paper_linear_scale": float(np.abs(pr.b).max()),
        "paper_angular": float(ang),
        "paper_angular_scale": float(np.abs(pr.y).max()),
        "standard": float(std),
        "standard_scale": float(np.abs(sr.y).max()),
    }
