"""The identification equations of Zhang, Yue, Yuan 2020, a thin facade over the engine.

The equations themselves -- the paper's form (eqs. 11-33: `A μ = b`, `Φ θ = y + Ψ D(μ)`, solved by the
modified RLS) and the standard-parameter form (per body [m, m b', inertia about the reference point], from
the engine's momentum and inverse-dynamics regressors) -- are computed by the engine
(`crates/freefloat-core/src/postcapture/equations.rs`) over the whole measurement record in one call
(`_core.postcapture_rows`). So are the parameter conversions (parallel axes, m J(b'), the consistent
projection). This module keeps the data classes, the row/column layout the estimators are set up with,
and small array helpers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core

# I# order of eq. (21) and the engine's inertia order [Ixx, Ixy, Iyy, Ixz, Iyz, Izz]:
# engine = I#[[0, 1, 3, 2, 4, 5]] (the permutation is its own inverse).
SHARP_FROM_ENGINE = [0, 1, 3, 2, 4, 5]


def mJ(m: float, b: np.ndarray) -> np.ndarray:
    """m J(b') (10,), eq. (23): [m, m b', m·mono(b')] (the engine's `postcapture::equations::m_j`)."""
    b = np.zeros(3) if b is None else np.asarray(b, float)
    return _core.postcapture_m_j(float(m), [float(x) for x in b])


def mv(M, x):
    """Stacked matrix-vector products (…, i, j) · (…, j)."""
    return np.einsum("...ij,...j->...i", M, x)


# -- problem layout (3D or planar) ----------------------------------------------------------------------
@dataclass(frozen=True)
class Layout:
    """Which rows and columns of the 3D equations a model uses (the same table as the engine's
    `postcapture::equations::Layout`, needed here to set up the estimators' priors). Planar: linear rows
    x, y; angular row z; μ per body [m, m bx, m by]; θ per body I_zz; D per body [m, m bx, m by,
    m(bx² + by²)] (the bx² and by² columns of H and S are equal, the bx·by column vanishes)."""

    planar: bool

    @property
    def lin_rows(self):
        return [0, 1] if self.planar else [0, 1, 2]

    @property
    def ang_rows(self):
        return [2] if self.planar else [0, 1, 2]

    @property
    def mu_cols(self):  # of the 4 columns [m, mbx, mby, mbz]
        return [0, 1, 2] if self.planar else [0, 1, 2, 3]

    @property
    def th_cols(self):  # of I# (6)
        return [5] if self.planar else list(range(6))

    @property
    def d_cols(self):  # of mJ (10)
        return [0, 1, 2, 4] if self.planar else list(range(10))

    @property
    def std_cols(self):  # of the engine's 10 standard parameters
        return [0, 1, 2, 9] if self.planar else list(range(10))

    @property
    def coupling(self):
        return "planar" if self.planar else "spatial"

    def momentum_rows(self):
        """Rows of the engine's 6-vector [p; L] used."""
        return [0, 1, 5] if self.planar else list(range(6))


@dataclass
class Measurements:
    """What the identification sees at the sample instants."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    ddq: np.ndarray
    base_wrench: np.ndarray  # (T, nb) thruster generalized force [f; τ] in the base frame at the sensor
    impulse_F: np.ndarray  # (T, 3) ∫ F dτ, inertial
    impulse_M: np.ndarray  # (T, 3) ∫ (M + x_F × F) dτ about the inertial origin, or ∫ M_B dτ (with transport)
    # (T, 3, 10·nbodies) ∫ [v_B]× K_lin dτ (`momentum_transport`): when given, the momentum rows balance the
    # angular momentum about the moving base point B instead of the inertial origin, and impulse_M is ∫ M_B dτ
    # about B (the engine's `postcapture::momentum_point`; docs/postcapture.md, "Momentum about the base point")
    transport: np.ndarray | None = None


@dataclass
class PaperRows:
    """The paper's regression in the modified-RLS form (eqs. 34-35), one block per sample."""

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


def _rows(model, meas: Measurements, form: str, solver: str, base: int, target: int) -> dict:
    return _core.postcapture_rows(
        model,
        form,
        solver,
        meas.t,
        meas.q,
        meas.v,
        meas.ddq,
        meas.base_wrench,
        meas.impulse_F,
        meas.impulse_M,
        int(base),
        int(target),
        transport=meas.transport,
    )


def momentum_transport(model, t, q, v, at, point: int = 0) -> np.ndarray:
    """∫_{t[at[0]]}^{t[at[s]]} [v_B]× K_lin dτ (T, 3, 10·nbodies) on the dense record (t, q, v) at its frame
    indices `at`, B the frame origin of body `point` (the engine's `postcapture::momentum_point`; Simpson's rule
    on an evenly spaced record). The term that moves the momentum form's angular balance to the base point."""
    return _core.postcapture_momentum_transport(
        model, np.asarray(t, float), np.asarray(q, float), np.asarray(v, float), [int(k) for k in at], int(point)
    )


def paper_momentum_rows(model, meas: Measurements, base: int, target: int) -> PaperRows:
    """Momentum form, eqs. (11)-(19), rows as cumulative differences from the first sample (t0); engine."""
    return PaperRows(**_rows(model, meas, "momentum", "paper", base, target))


def paper_force_rows(model, meas: Measurements, base: int, target: int) -> PaperRows:
    """Force form, eqs. (26)-(33), moments about the current base-sensor point; engine."""
    return PaperRows(**_rows(model, meas, "force", "paper", base, target))


def standard_momentum_rows(model, meas: Measurements, base: int, target: int) -> StandardRows:
    """Standard form, momentum: the engine's momentum-regressor columns of base and target, cumulative
    differences from t0."""
    return StandardRows(**_rows(model, meas, "momentum", "standard", base, target))


def standard_force_rows(model, meas: Measurements, base: int, target: int) -> StandardRows:
    """Standard form, Newton-Euler: base rows of the engine's inverse-dynamics regressor for the base and
    target columns."""
    return StandardRows(**_rows(model, meas, "force", "standard", base, target))


# -- parameters in each form ----------------------------------------------------------------------------
def body_truth(model, body: int) -> tuple[float, np.ndarray, np.ndarray]:
    """(m, b', I'_c) of a body from the model file (parallel axes, in the engine)."""
    m, b, Ic = _core.inertia_com_form(np.array(model.parameters(), float)[body])
    return float(m), b, Ic


def inertia_sharp(I: np.ndarray) -> np.ndarray:
    """I# of eq. (21): [I11, I12, I13, I22, I23, I33] (a selection of entries)."""
    return np.array([I[0, 0], I[0, 1], I[0, 2], I[1, 1], I[1, 2], I[2, 2]])


def standard_vector(m: float, b, Ic) -> np.ndarray:
    """Engine-order standard parameters [m, m b', I about the reference point] from (m, b', I_c)."""
    return _core.inertia_standard_form(np.asarray(m, float), np.asarray(b, float), np.asarray(Ic, float))


def from_standard(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Histories (N, 10) of standard parameters → m (N,), b' (N, 3), I'_c (N, 3, 3)."""
    return _core.inertia_com_form(np.asarray(x, float))


def project_consistent(x: np.ndarray, eps: float = 1e-9) -> np.ndarray:
    """Nearest physically consistent standard parameters (Frobenius norm on the pseudo-inertia
    J = [[½tr(I)1 − I, h], [hᵀ, m]], which is positive definite exactly for physical bodies):
    eigenvalues clipped at `eps`·max. x: (…, 10) engine order. Used on the reported estimate only."""
    return _core.inertia_project_consistent(np.asarray(x, float), float(eps))
