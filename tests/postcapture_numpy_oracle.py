"""Test oracle: the numpy version of seed 000's identification equations (Zhang, Yue, Yuan 2020) that
`freefloat.postcapture_equations` held before the engine took them over (`postcapture/equations.rs`).
Kept verbatim, only in the tests, as the independent computation the engine's rows are checked against
(tests/test_postcapture.py). The rotations use this file's own quaternion formula."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from freefloat import algorithms as alg
from freefloat.postcapture_equations import Layout, Measurements


def quat_to_matrix(Q) -> np.ndarray:
    """Rotation matrices (T, 3, 3) from unit quaternions (T, 4) in (x, y, z, w) order (frame to inertial)."""
    x, y, z, w = Q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrices (…, 3, 3), eq. (14)."""
    z = np.zeros_like(v[..., 0])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)], -2)


def sharp(v: np.ndarray) -> np.ndarray:
    """[#v] (…, 3, 6) with I v = [#v] I#, eq. (20)."""
    z = np.zeros_like(v[..., 0])
    a, b, c = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([np.stack([a, b, c, z, z, z], -1), np.stack([z, a, z, b, c, z], -1),
                     np.stack([z, z, a, z, b, c], -1)], -2)


def quad(u: np.ndarray) -> np.ndarray:
    """W(u) (…, 3, 6) with (|b|² 1 − b bᵀ) u = W(u) mono(b), mono(b) = [bx², bx by, bx bz, by², by bz, bz²]
    (digest §4.2; replaces the garbled Appendix A)."""
    z = np.zeros_like(u[..., 0])
    a, b, c = u[..., 0], u[..., 1], u[..., 2]
    return np.stack([np.stack([z, -b, -c, a, z, a], -1), np.stack([b, -a, z, z, -c, b], -1),
                     np.stack([c, z, -a, c, -b, z], -1)], -2)


def mono(b: np.ndarray) -> np.ndarray:
    x, y, z = b
    return np.array([x * x, x * y, x * z, y * y, y * z, z * z])


def mJ(m: float, b: np.ndarray) -> np.ndarray:
    """m J(b') (10,), eq. (23): [m, m b', m·mono(b')]."""
    return np.concatenate([[m], m * np.asarray(b, float), m * mono(np.asarray(b, float))])


def mv(M, x):
    return np.einsum("...ij,...j->...i", M, x)


def mm(A, B):
    return np.einsum("...ij,...jk->...ik", A, B)


@dataclass
class PointMotion:
    """Motion of a reference point with the axes of its body: position r, attitude A (body → inertial),
    velocity v, angular velocity ω, acceleration a, angular acceleration β, all inertial (T, …)."""

    r: np.ndarray
    A: np.ndarray
    v: np.ndarray
    w: np.ndarray
    a: np.ndarray
    b: np.ndarray

    def shifted(self, origin: np.ndarray) -> "PointMotion":
        """Positions relative to a moving origin (the force form's base-sensor point, digest §5);
        velocities and accelerations stay absolute."""
        return PointMotion(self.r - origin, self.A, self.v, self.w, self.a, self.b)


def point_motion(model, q, v, ddq, body: int) -> PointMotion:
    """Motion of body `body`'s frame origin (the base sensor / the capture point in the seed-000 models)."""
    fk = np.asarray(alg.forward_kinematics(model, q))[:, body]
    A = quat_to_matrix(fk[:, 3:])
    tw = np.asarray(alg.body_velocities(model, q, v))[:, body]
    ac = np.asarray(alg.body_accelerations(model, q, v, ddq, classical=True))[:, body]
    return PointMotion(fk[:, :3], A, mv(A, tw[:, :3]), mv(A, tw[:, 3:]), mv(A, ac[:, :3]), mv(A, ac[:, 3:]))


# -- the paper's blocks ---------------------------------------------------------------------------------
def B_block(p: PointMotion) -> np.ndarray:
    """(T, 3, 4): m v_c = B [m; m b'] (eq. 12 block)."""
    return np.concatenate([p.v[..., None], mm(skew(p.w), p.A)], -1)


def H_block(p: PointMotion) -> np.ndarray:
    """(T, 3, 10): m c × ċ = H m J(b') (eq. 19; closed form of digest §4.2)."""
    rt, wt, vt = skew(p.r), skew(p.w), skew(p.v)
    wb = np.einsum("tji,tj->ti", p.A, p.w)  # A^T ω
    return np.concatenate([mv(rt, p.v)[..., None], mm(mm(rt, wt) - vt, p.A), mm(p.A, quad(wb))], -1)


def D_block(p: PointMotion) -> np.ndarray:
    """(T, 3, 6): I_c ω = D I'# (eq. 17 block)."""
    wb = np.einsum("tji,tj->ti", p.A, p.w)
    return mm(p.A, sharp(wb))


def G_block(p: PointMotion) -> np.ndarray:
    """(T, 3, 4): m a_c = G [m; m b'] (eq. 29 block)."""
    wt = skew(p.w)
    return np.concatenate([p.a[..., None], mm(skew(p.b) + mm(wt, wt), p.A)], -1)


def S_block(p: PointMotion) -> np.ndarray:
    """(T, 3, 10): m c × c̈ = S m J(b') (eq. 31; digest §5 closed form, S = dH/dt)."""
    rt, wt, bt, at = skew(p.r), skew(p.w), skew(p.b), skew(p.a)
    wb = np.einsum("tji,tj->ti", p.A, p.w)
    bb = np.einsum("tji,tj->ti", p.A, p.b)
    lin = mm(mm(rt, bt + mm(wt, wt)) - at, p.A)
    q6 = mm(p.A, quad(bb) + mm(skew(wb), quad(wb)))
    return np.concatenate([mv(rt, p.a)[..., None], lin, q6], -1)


def Q_block(p: PointMotion) -> np.ndarray:
    """(T, 3, 6): I_c β + ω × I_c ω = Q I'# (eq. 32 block)."""
    wb = np.einsum("tji,tj->ti", p.A, p.w)
    bb = np.einsum("tji,tj->ti", p.A, p.b)
    return mm(p.A, sharp(bb) + mm(skew(wb), sharp(wb)))


def known_params(model, unknown: list[int]) -> np.ndarray:
    P = np.array(model.parameters(), float)
    P[unknown] = 0.0
    return P.ravel()


@dataclass
class PaperRows:
    """Seed 000's regression in the modified-RLS form (eqs. 34-35), one block per sample."""

    t: np.ndarray
    A: np.ndarray
    b: np.ndarray
    Phi: np.ndarray
    y: np.ndarray
    Psi: np.ndarray


@dataclass
class StandardRows:
    t: np.ndarray
    Phi: np.ndarray
    y: np.ndarray


def _paper_assemble(L: Layout, A, b, Phi, y, Psi, t) -> PaperRows:
    lr, ar = L.lin_rows, L.ang_rows
    mc = L.mu_cols + [4 + c for c in L.mu_cols]
    tc = L.th_cols + [6 + c for c in L.th_cols]
    dc = L.d_cols + [10 + c for c in L.d_cols]
    return PaperRows(t, A[:, lr][:, :, mc], b[:, lr], Phi[:, ar][:, :, tc], y[:, ar], Psi[:, ar][:, :, dc])


def paper_momentum_rows(model, meas: Measurements, base: int, target: int) -> PaperRows:
    """Momentum form, eqs. (11)-(18), rows as cumulative differences from the first sample (t0)."""
    L = Layout(model.joint_types[0] == "planar")
    zero = np.zeros_like(meas.ddq)
    p1 = point_motion(model, meas.q, meas.v, zero, base)
    pn = point_motion(model, meas.q, meas.v, zero, target)
    K = np.asarray(alg.momentum_regressor(model, meas.q, meas.v))
    known = K @ known_params(model, [base, target])           # Σ_known [m v ; m r × v + I ω]
    Bt = np.concatenate([B_block(p1), B_block(pn)], -1)       # eq. (12)
    C = meas.impulse_F - known[:, :3]                        # eq. (13)
    Dt = np.concatenate([D_block(p1), D_block(pn)], -1)       # eq. (17)
    E = meas.impulse_M - known[:, 3:]                        # eq. (18)
    Ht = np.concatenate([H_block(p1), H_block(pn)], -1)       # eq. (19)
    d = lambda X: X[1:] - X[:1]  # noqa: E731  (eq. 16: H(t) − H(t0), the printed H(t) is a typo)
    return _paper_assemble(L, d(Bt), d(C), d(Dt), d(E), -d(Ht), meas.t[1:])


def paper_force_rows(model, meas: Measurements, base: int, target: int) -> PaperRows:
    """Force form, eqs. (26)-(33), moments about the current base-sensor point (digest §5)."""
    L = Layout(model.joint_types[0] == "planar")
    p1 = point_motion(model, meas.q, meas.v, meas.ddq, base)
    pn = point_motion(model, meas.q, meas.v, meas.ddq, target)
    origin = p1.r
    p1s, pns = p1.shifted(origin), pn.shifted(origin)
    nb = meas.base_wrench.shape[1]
    Y = np.asarray(alg.dynamics_regressor(model, meas.q, meas.v, meas.ddq))[:, :nb]
    known_b = Y @ known_params(model, [base, target])         # base-frame wrench of the known links
    wrench = meas.base_wrench - known_b
    f3, m3 = _base_wrench_3d(wrench, L.planar)
    K = mv(p1.A, f3)                                          # eq. (30)
    R = mv(p1.A, m3)                                          # eq. (33), about the base sensor
    Gt = np.concatenate([G_block(p1s), G_block(pns)], -1)     # eq. (29)
    Qt = np.concatenate([Q_block(p1s), Q_block(pns)], -1)     # eq. (32)
    St = np.concatenate([S_block(p1s), S_block(pns)], -1)     # eq. (31)
    return _paper_assemble(L, Gt, K, Qt, R, -St, meas.t)


def _base_wrench_3d(w: np.ndarray, planar: bool):
    if planar:
        z = np.zeros(len(w))
        return np.stack([w[:, 0], w[:, 1], z], -1), np.stack([z, z, w[:, 2]], -1)
    return w[:, :3], w[:, 3:6]


def standard_momentum_rows(model, meas: Measurements, base: int, target: int) -> StandardRows:
    """Digest §7 momentum form: the engine's momentum regressor columns of base and target (standard
    parameters about the sensor / capture point), cumulative differences from t0."""
    L = Layout(model.joint_types[0] == "planar")
    K = np.asarray(alg.momentum_regressor(model, meas.q, meas.v))
    known = K @ known_params(model, [base, target])
    cols = [10 * base + c for c in L.std_cols] + [10 * target + c for c in L.std_cols]
    rows = L.momentum_rows()
    Phi = K[:, rows][:, :, cols]
    y = np.concatenate([meas.impulse_F, meas.impulse_M], -1)[:, rows] - known[:, rows]
    return StandardRows(meas.t[1:], Phi[1:] - Phi[:1], y[1:] - y[:1])


def standard_force_rows(model, meas: Measurements, base: int, target: int) -> StandardRows:
    """Digest §7 Newton-Euler form: base rows of the engine's inverse-dynamics regressor (the total
    wrench at the base sensor, base frame) for the base and target columns."""
    L = Layout(model.joint_types[0] == "planar")
    nb = meas.base_wrench.shape[1]
    Y = np.asarray(alg.dynamics_regressor(model, meas.q, meas.v, meas.ddq))[:, :nb]
    known_b = Y @ known_params(model, [base, target])
    cols = [10 * base + c for c in L.std_cols] + [10 * target + c for c in L.std_cols]
    return StandardRows(meas.t, Y[:, :, cols], meas.base_wrench - known_b)


# -- parameters in each form ----------------------------------------------------------------------------
def body_truth(model, body: int) -> tuple[float, np.ndarray, np.ndarray]:
    """(m, b', I'_c) of a body from the model file: b' = h/m; I'_c = I_o − m(|b|²1 − b bᵀ) (parallel axes)."""
    p = np.array(model.parameters(), float)[body]
    m, h = p[0], p[1:4]
    Io = np.array([[p[4], p[5], p[7]], [p[5], p[6], p[8]], [p[7], p[8], p[9]]])
    b = h / m
    return m, b, Io - m * (b @ b * np.eye(3) - np.outer(b, b))


def inertia_sharp(I: np.ndarray) -> np.ndarray:
    return np.array([I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]])


def standard_vector(m: float, b, Ic) -> np.ndarray:
    """Engine-order standard parameters [m, m b', I about the reference point] from (m, b', I_c)."""
    b = np.asarray(b, float)
    Io = np.asarray(Ic, float) + m * (b @ b * np.eye(3) - np.outer(b, b))
    return np.array([m, *(m * b), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]])


def from_standard(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Histories (N, 10) of standard parameters → m (N,), b' (N, 3), I'_c (N, 3, 3)."""
    m, h = x[:, 0], x[:, 1:4]
    Io = np.stack([np.stack([x[:, 4], x[:, 5], x[:, 7]], -1), np.stack([x[:, 5], x[:, 6], x[:, 8]], -1),
                   np.stack([x[:, 7], x[:, 8], x[:, 9]], -1)], -2)
    b = h / m[:, None]
    hh = np.einsum("ti,tj->tij", h, h)
    Ic = Io - (np.einsum("ti,ti->t", h, h)[:, None, None] * np.eye(3) - hh) / m[:, None, None]
    return m, b, Ic


def project_consistent(x: np.ndarray, eps: float = 1e-9) -> np.ndarray:
    """Nearest physically consistent standard parameters (Frobenius norm on the pseudo-inertia
    J = [[½tr(I)1 − I, h], [hᵀ, m]], which is positive definite exactly for physical bodies):
    eigenvalues clipped at `eps`·max. x: (…, 10) engine order. Used on the reported estimate only."""
    x = np.array(x, float)
    flat = x.reshape(-1, 10)
    out = np.empty_like(flat)
    for k, p in enumerate(flat):
        I = np.array([[p[4], p[5], p[7]], [p[5], p[6], p[8]], [p[7], p[8], p[9]]])
        J = np.zeros((4, 4))
        J[:3, :3] = 0.5 * np.trace(I) * np.eye(3) - I
        J[:3, 3] = J[3, :3] = p[1:4]
        J[3, 3] = p[0]
        w, V = np.linalg.eigh(J)
        w = np.maximum(w, eps * max(w.max(), 1e-300))
        J = (V * w) @ V.T
        S = J[:3, :3]
        I = np.trace(S) * np.eye(3) - S
        out[k] = [J[3, 3], *J[:3, 3], I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]]
    return out.reshape(x.shape)
