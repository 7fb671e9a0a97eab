"""Identification of inertial parameters from measured motion (Naveen, Shah, Misra: the momentum model of a
tree-type free-floating robot), in pipeline order:

- `minimal`: the minimal (identifiable) parameters — closed-form grouping and a numeric method for any tree;
- `excitation` (+ `excitation_results`, `pruning`, `comparison`): design of exciting trajectories (cycloids,
  eq. 32, Algorithm 1);
- `estimation`: streaming least squares in the engine, with covariance and rank checks;
- `identify`: `identify_minimal` from telemetry (weighted, errors-in-variables bias compensation);
- `consistent`: physically consistent standard parameters reproducing the minimal ones (a convex program);
- `validation`: prediction of base twist and joint torques by true and identified robots (Table 6);
- `concurrent` (+ `concurrent_plots`, `concurrent_studies`): concurrent-learning estimation of every body's mass
  properties from the Newton–Euler equations with measured joint wrenches (Valverde 2018, ch. 9);
- `online`: recursive estimators (RLS with forgetting, the modified RLS of Zhang, Yue, Yuan 2020).

A new estimator goes here: a function that takes a model and a `Telemetry` (or regressor rows) and returns a result
object with `to_dict()` / `save(out)`, its arithmetic in the engine (`crates/freefloat-core/src/estimation/`).
"""

from . import (
    comparison,
    concurrent,
    consistent,
    estimation,
    excitation,
    excitation_results,
    identify,
    minimal,
    online,
    pruning,
    validation,
)
from .concurrent import ConcurrentLearningEstimator
from .identify import IdentificationResult, identify_minimal
from .minimal import MinimalParameters, minimal_parameters

__all__ = [
    "ConcurrentLearningEstimator",
    "IdentificationResult",
    "MinimalParameters",
    "comparison",
    "concurrent",
    "consistent",
    "estimation",
    "excitation",
    "excitation_results",
    "identify",
    "identify_minimal",
    "minimal",
    "minimal_parameters",
    "online",
    "pruning",
    "validation",
]
