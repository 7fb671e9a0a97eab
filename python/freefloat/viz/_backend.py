"""The one place that imports matplotlib (lazily, on a file-only backend)."""

from __future__ import annotations


def pyplot():
    """`matplotlib.pyplot` on the non-interactive Agg backend: every figure freefloat draws goes to a file, so
    plotting works on machines without a display. Imported on first use, so the rest of freefloat does not
    pay matplotlib's import time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
