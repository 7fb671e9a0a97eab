"""Public plotting helpers. Every figure freefloat writes goes through `pyplot()` (matplotlib on the Agg
backend, imported on first use); `conservation(traj, path)` draws the conservation report of a simulation.
The figures of the paper reproductions live beside their code (`freefloat.postcapture.plots`,
`freefloat.identification.pruning.plot_fig4`, ...) and use the same helper.

    from freefloat.viz import pyplot, conservation
    plt = pyplot()
    conservation(traj, "run.png", title="my run")
"""

from ._backend import pyplot
from .conservation import conservation

__all__ = ["conservation", "pyplot"]
