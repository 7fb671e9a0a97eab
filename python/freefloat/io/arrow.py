"""Arrow tables from numpy columns without importing pandas.

`pyarrow.table`, `pyarrow.array` and `Table.from_pydict` ask pandas whether their input is a DataFrame or Series,
and that question imports pandas when it is installed: about half a second on this project's machines, paid by every
Parquet write and, worst, by the write that saves a run after Ctrl-C (the exit must come within a second). A float64
or int64 numpy column is handed to Arrow as a buffer instead, which needs no such check; any other column takes the
ordinary route.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa

_BY_BUFFER = {np.dtype(np.float64): pa.float64(), np.dtype(np.int64): pa.int64()}


def column(values) -> pa.Array:
    """One Arrow array from a 1-D numpy array (copied to contiguous memory if it is a strided view)."""
    a = np.asarray(values)
    kind = _BY_BUFFER.get(a.dtype)
    if kind is None or a.ndim != 1:
        return pa.array(a)
    a = np.ascontiguousarray(a)
    return pa.Array.from_buffers(kind, len(a), [None, pa.py_buffer(a)])


def table(columns: dict, metadata: dict | None = None) -> pa.Table:
    """A table of the named columns, in order, with optional schema metadata."""
    t = pa.Table.from_arrays([column(v) for v in columns.values()], names=list(columns))
    return t.replace_schema_metadata(metadata) if metadata else t
