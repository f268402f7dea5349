"""qc_control: quarter-car suspension models on python-control.

The quarter car of the seed paper as a `control.StateSpace`, its modal
analysis, the seed's four fixed-step methods (Euler, Midpoint, Heun, RK4)
as python-control-compatible responses measured against the exact response,
fast LTI and sweep engines, ISO 8608 roads and ISO 2631-1 ride metrics.
"""

from . import road
from .compare import MethodComparison, compare_methods
from .integrate import DivergenceWarning, Solution, integrate
from .methods import METHODS, ButcherTableau, get_method
from .modal import ModalAnalysis, Mode, modal_analysis
from .model import OUTPUTS, STATES, QuarterCarParams, load_config, quarter_car, read_config
from .response import (
    FixedStepResponse,
    forced_response,
    impulse_response,
    initial_response,
    step_response,
)
from .ride import (
    Transmissibility,
    ride_metrics,
    ride_metrics_spectral,
    transmissibility,
    wk_filter,
    wk_weighted,
)
from .stability import max_stable_step, numerical_modes, stability_function
from .sweeps import DEFAULT_METRICS, METRICS, SweepChunk, SweepResult, design_grid, sweep

__version__ = "0.1.0"
__all__ = [
    "QuarterCarParams",
    "quarter_car",
    "load_config",
    "read_config",
    "STATES",
    "OUTPUTS",
    "Mode",
    "ModalAnalysis",
    "modal_analysis",
    "ButcherTableau",
    "METHODS",
    "get_method",
    "integrate",
    "Solution",
    "DivergenceWarning",
    "initial_response",
    "forced_response",
    "step_response",
    "impulse_response",
    "FixedStepResponse",
    "stability_function",
    "max_stable_step",
    "numerical_modes",
    "compare_methods",
    "MethodComparison",
    "sweep",
    "SweepResult",
    "SweepChunk",
    "design_grid",
    "METRICS",
    "DEFAULT_METRICS",
    "road",
    "transmissibility",
    "Transmissibility",
    "ride_metrics",
    "ride_metrics_spectral",
    "wk_filter",
    "wk_weighted",
]
