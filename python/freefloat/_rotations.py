"""Rotation helpers shared by the Python layer (the engine has its own in Rust)."""

from __future__ import annotations

import numpy as np


def quat_to_matrix(Q) -> np.ndarray:
    """Rotation matrices (T, 3, 3) from unit quaternions (T, 4) in (x, y, z, w) order (frame to inertial)."""
    x, y, z, w = Q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)
