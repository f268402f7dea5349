"""qc_control: quarter-car suspension models on python-control.

The quarter car of the seed paper as a `control.StateSpace`, its modal
analysis, and the seed's four fixed-step methods (Euler, Midpoint, Heun,
RK4) as python-control-compatible responses, measured against the exact
response.
"""
from .integrate import DivergenceWarning, Solution, integrate
from .methods import METHODS, ButcherTableau, get_method
from .modal import ModalAnalysis, Mode, modal_analysis
from .model import OUTPUTS, STATES, QuarterCarParams, load_config, quarter_car, read_config
from .response import FixedStepResponse, forced_response, initial_response
from .stability import max_stable_step, numerical_modes, stability_function
from .compare import MethodComparison, compare_methods
from .sweeps import METRICS, SweepResult, design_grid, sweep

__version__ = "0.1.0"
__all__ = [
    "QuarterCarParams", "quarter_car", "load_config", "read_config", "STATES", "OUTPUTS",
    "Mode", "ModalAnalysis", "modal_analysis",
    "ButcherTableau", "METHODS", "get_method",
    "integrate", "Solution", "DivergenceWarning",
    "initial_response", "forced_response", "FixedStepResponse",
    "stability_function", "max_stable_step", "numerical_modes",
    "compare_methods", "MethodComparison",
    "sweep", "SweepResult", "design_grid", "METRICS",
]
