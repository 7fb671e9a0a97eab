#!/usr/bin/env python3
"""Write the problem of identify_vs_numpy.py (67,000 samples of naveen_dual_arm, the 52 closed-form minimal
parameters, wheels known) to a file for `crates/freefloat-core/examples/identify_profile.rs identify FILE REPS`,
which times and profiles the whole identification without Python.

Layout (little-endian): five u64 (T, nq, nv, number of unknown columns, number of standard parameters), then f64
arrays: Q (T x nq), V (T x nv), H (T x 6), the unknown columns (as f64), the known standard parameters.

    python benches/identify_dump.py /tmp/naveen67k.bin
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import identify_vs_numpy as bench  # noqa: E402

import freefloat as ff  # noqa: E402
from freefloat.identification.estimation import absolute_columns, known_parameters  # noqa: E402


def main(path: str, samples: int = 67_000) -> None:
    m = ff.models.load(bench.MODEL)
    Q, V, H = bench.make_data(m, samples / 1000)
    mp = ff.minimal_parameters(m, method="closed-form")
    cols = np.asarray(absolute_columns(mp), dtype=float)
    known = np.asarray(known_parameters(mp, None), dtype=float)
    header = np.array([len(Q), Q.shape[1], V.shape[1], len(cols), len(known)], dtype="<u8")
    with open(path, "wb") as f:
        f.write(header.tobytes())
        for a in (Q, V, H, cols, known):
            f.write(np.ascontiguousarray(a, dtype="<f8").tobytes())
    print(f"{path}: {len(Q)} samples, {len(cols)} unknowns")


if __name__ == "__main__":
    main(sys.argv[1])
