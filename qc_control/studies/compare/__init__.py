"""Compare fixed-step methods against python-control's exact response.

`compare_methods` computes every number of the comparison once, into a
frozen `MethodComparison`; the report writers in `qc_control.report` only
format them. The package is in rooms of one concept each, whose names it
hands on (``from qc_control.studies.compare import X`` as before the split):

- `problem`: the defaults and `ComparisonProblem`, the arguments checked;
- `measures`: what every path measures of its runs (errors, the
  convergence ladder, observed orders, costs to reach, coincident pairs,
  numerical modes, ride metrics), and `Reference`;
- `linear`: a linear car against python-control's exact response, its
  ladder timed in interleaved rounds;
- `nlreference`: `nonlinear_reference`, solve_ivp restarted at each event;
- `nonlinear`: a nonlinear car, with and without events;
- `sampled`: a sampled-data loop against its exact loop, tick by tick;
- `result`: `MethodComparison` and `NonlinearStudy`;
- `study`: `compare_methods`, which runs the path its system needs.

The column names of its frames are named once, in `qc_control.studies.columns`.
"""

from __future__ import annotations

from .linear import LADDER_ROUNDS as LADDER_ROUNDS  # public, though not in __all__
from .linear import (
    convergence_study,
    exact_reference,
    method_responses,
    method_timings,
)
from .measures import (
    ConvergencePoint,
    Reference,
    best_time,
    cost_to_reach,
    error_table,
    max_error,
    mode_errors,
    observed_orders,
    ride_comparison,
)
from .nlreference import NonlinearReference, ReferenceBudgetError, nonlinear_reference
from .nonlinear import NONLINEAR_LEVELS
from .problem import (
    DEFAULT_H,
    DEFAULT_METHODS,
    DEFAULT_T_END,
    DEFAULT_X0,
    TOLERANCES,
    ComparisonProblem,
    Provenance,
)
from .result import MethodComparison, NonlinearStudy
from .sampled import sampled_reference
from .study import compare_methods

__all__ = [
    "ReferenceBudgetError",
    "MethodComparison",
    "ComparisonProblem",
    "Provenance",
    "compare_methods",
    "Reference",
    "exact_reference",
    "sampled_reference",
    "method_responses",
    "max_error",
    "error_table",
    "convergence_study",
    "ConvergencePoint",
    "observed_orders",
    "cost_to_reach",
    "mode_errors",
    "ride_comparison",
    "method_timings",
    "best_time",
    "DEFAULT_METHODS",
    "DEFAULT_X0",
    "DEFAULT_T_END",
    "DEFAULT_H",
    "TOLERANCES",
    "NonlinearReference",
    "nonlinear_reference",
    "NonlinearStudy",
    "NONLINEAR_LEVELS",
]
