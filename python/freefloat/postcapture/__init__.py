"""Post-capture identification of base and grasped target (Zhang, Yue, Yuan 2020): scenario files, simulation,
both identification forms (momentum-based and force-based) with both solvers (the paper's modified RLS and the
ordinary RLS on standard parameters), results, tables beside the paper's, figures.

    import freefloat.postcapture as pc
    sc = pc.load_scenario("zhang2020_2d_medium")      # built-in (freefloat/data/scenarios/) or a file path
    res = pc.run(sc)                                    # simulate + identify (4 estimators)
    print(res.table()); res.save("out/")

Modules: `scenario` (files), `simulation` (motion and measurements), `equations` (the paper's regressions),
`estimators` (both solvers), `results` (tables, results.json), `pipeline` (run, sweep, noise study), `plots`.
Where the paper is silent the scenario files carry our documented choices (docs/postcapture.md).
"""

from . import equations
from .estimators import (
    METHODS,
    SOLVERS,
    equation_residuals,
    identify_modified,
    identify_standard,
    parameter_names,
    target_index,  # noqa: F401  (used by the tests of the target check)
    truth_vector,
)
from .pipeline import identify, noise_study, run, sweep
from .plots import plot_histories, plot_sweep
from .results import SOLVER_TITLES, PostcaptureResult, noise_table, sweep_table, transit_times
from .scenario import DEFAULT_NOISE, Scenario, list_scenarios, load_scenario
from .simulation import measure, simulate

__all__ = [
    "DEFAULT_NOISE",
    "METHODS",
    "SOLVERS",
    "SOLVER_TITLES",
    "PostcaptureResult",
    "Scenario",
    "equation_residuals",
    "equations",
    "identify",
    "identify_modified",
    "identify_standard",
    "list_scenarios",
    "load_scenario",
    "measure",
    "noise_study",
    "noise_table",
    "parameter_names",
    "plot_histories",
    "plot_sweep",
    "run",
    "simulate",
    "sweep",
    "sweep_table",
    "transit_times",
    "truth_vector",
]
