"""Argument conversion shared by the function layer: anything array-like becomes a float64 array,
and a value that cannot be converted is reported with the argument's name."""

from __future__ import annotations

import numpy as np

from ._core import InputError


def as_f64(x, name: str) -> np.ndarray:
    """Convert `x` to a C-contiguous float64 array, naming `name` if that fails. Complex numbers are refused
    (numpy would drop the imaginary part with only a ComplexWarning)."""
    if np.iscomplexobj(x):
        raise InputError(
            f"argument `{name}`: complex numbers are not accepted (got dtype {np.asarray(x).dtype}); give real numbers"
        )
    try:
        return np.ascontiguousarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InputError(f"argument `{name}`: cannot be read as an array of numbers ({e})") from None
