"""qc_control: quarter-car suspension models on python-control.

Quickstart
----------
The quarter car of the seed paper (Table 1) is a `control.StateSpace`:

>>> import control
>>> import numpy as np
>>> import qc_control as qc
>>> params = qc.QuarterCarParams()
>>> sys = qc.quarter_car(params)
>>> sys.state_labels
['vs', 'vu', 'xs', 'xu']

Its modal analysis names the two modes by their shape:

>>> modes = qc.modal_analysis(sys)
>>> [(mode.name, round(mode.fn, 3), round(mode.zeta, 4)) for mode in modes.modes]
[('body bounce', 1.087, 0.0677), ('wheel hop', 3.997, 0.3802)]

Each of the seed's four fixed-step methods gives a response shaped like
`control.initial_response`'s, here against that exact response (body
released from 5 cm, 0-10 s, h = 0.01 s):

>>> T = np.linspace(0, 10, 1001)
>>> X0 = [0.0, 0.0, 0.05, 0.0]
>>> exact = control.initial_response(sys, T, X0)
>>> xs = list(sys.output_labels).index("xs")
>>> for method in ["euler", "midpoint", "heun", "rk4"]:
...     resp = qc.initial_response(sys, T, X0, method=method)
...     error = np.max(np.abs(resp.outputs[xs] - exact.outputs[xs]))
...     print(f"{method:9s}{error:.2e} m")
euler    1.14e-02 m
midpoint 1.92e-04 m
heun     1.92e-04 m
rk4      2.28e-07 m

`compare_methods` computes every number of the comparison once (errors,
observed orders, cost, stability limits, numerical modes), and
`write_report` turns it into the report (Markdown, HTML, CSV and figures):

>>> comparison = qc.compare_methods(params, repeats=1)
>>> comparison.table["observed order"].round(1).to_dict()
{'euler': 1.2, 'midpoint': 2.0, 'heun': 2.0, 'rk4': 4.0}
>>> qc.write_report(comparison, "report")  # doctest: +SKIP

Beyond the seed: ISO 8608 roads (`qc_control.ride.road`), ISO 2631-1 ride
metrics (`ride_metrics`, `transmissibility`), the LTI engine behind the
responses, and sweeps over thousands of designs (`sweep`). The command
``qc-control report`` writes the same report from the shell.

Names are loaded from their modules on first use, so ``import qc_control``
stays light: it imports neither python-control nor matplotlib until a name
that needs them is used.
"""

from __future__ import annotations

import importlib
import sys as _sys
from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _distribution_version
from types import ModuleType as _ModuleType
from typing import TYPE_CHECKING, Any

from . import _moved

try:
    # The version is written once, in pyproject.toml; this reads it back
    # from the installed distribution's metadata.
    __version__: str = _distribution_version("qc-control")
except PackageNotFoundError:  # pragma: no cover - a source tree that was never installed
    __version__ = "0+unknown"

if TYPE_CHECKING:  # what the lazy names are, for type checkers and editors
    from .models.controllers import (
        HinfDesign,
        add_damper,
        closed_loop,
        groundhook,
        hinf_controller,
        hybrid,
        lqr_controller,
        skyhook,
    )
    from .models.halfcar import (
        FullCarParams,
        HalfCarParams,
        full_car,
        full_car_model,
        half_car,
        half_car_model,
    )
    from .models.modal import ModalAnalysis, Mode, modal_analysis, numerical_modes
    from .models.mpc import MPCController, MPCSolution, mpc_controller, sampled_lqr
    from .models.nonlinear import (
        BumpStop,
        NonlinearQuarterCarBatch,
        PiecewiseDamper,
        nonlinear_quarter_car,
        nonlinear_quarter_car_model,
    )
    from .models.quarter import (
        OUTPUTS,
        STATES,
        QuarterCarParams,
        quarter_car,
        quarter_car_model,
    )
    from .models.registry import (
        DefaultRun,
        ModelEntry,
        ModelOption,
        get_model,
        register_model,
        unregister_model,
    )
    from .models.vehicle import Corner, SignalRoles, VehicleModel
    from .numerics.checks import ParameterError
    from .numerics.integrate import DivergenceWarning, Solution, integrate
    from .numerics.limits import ResourceLimitError
    from .numerics.methods import METHODS, TABLEAUS, ButcherTableau, get_method
    from .numerics.stability import max_stable_step, stability_function
    from .report import write_report
    from .report.plotting import plot_outputs
    from .report.transaction import ReportError
    from .responses.timeresp import (
        FixedStepResponse,
        forced_response,
        impulse_response,
        initial_response,
        input_output_response,
        step_response,
    )
    from .ride import road, spectral
    from .ride.assessment import RideAssessment, ride_assessment
    from .ride.comfort import (
        Transmissibility,
        ride_metrics,
        ride_metrics_spectral,
        transmissibility,
        wk_filter,
        wk_weighted,
    )
    from .ride.iso2631 import weighted, weighting
    from .ride.metrics import Metric, RideSignals
    from .ride.road import ISO8608Road, iso8608_intensity
    from .ride.spectral import (
        lyapunov_variances,
        white_velocity_variances,
    )
    from .studies.compare import MethodComparison, compare_methods
    from .studies.control_study import ControlComparison, compare_controllers
    from .studies.damping import DampingOptimum, ParetoFront, optimal_damping, pareto_front
    from .studies.identification import Identification, identify
    from .studies.measured_comparison import MeasurementComparison, compare_to_measurement
    from .studies.measurement import Measurement
    from .studies.nlsweep import BatchResponse, simulate_batch
    from .studies.scenario import Scenario
    from .studies.scenario_toml import ScenarioError, load_config, read_config
    from .studies.sweeps import (
        DEFAULT_METRICS,
        METRICS,
        SweepChunk,
        SweepResult,
        design_grid,
        sweep,
    )

#: Public name -> the module that defines it, below the package (``"road"``
#: and ``"spectral"`` are modules themselves).
#: ``__all__`` is made from it; tests/test_tooling.py checks that it and the
#: TYPE_CHECKING imports above name the same things.
_LAZY: dict[str, str] = {
    # the fixed-step integrator; lazy too, so that ``import qc_control`` and the
    # command line's --help load no scipy
    "integrate": "numerics.integrate",
    "road": "ride.road",
    "MethodComparison": "studies.compare",
    "compare_methods": "studies.compare",
    "compare_controllers": "studies.control_study",
    "ControlComparison": "studies.control_study",
    "optimal_damping": "studies.damping",
    "pareto_front": "studies.damping",
    "DampingOptimum": "studies.damping",
    "ParetoFront": "studies.damping",
    "closed_loop": "models.controllers",
    "skyhook": "models.controllers",
    "groundhook": "models.controllers",
    "hybrid": "models.controllers",
    "add_damper": "models.controllers",
    "lqr_controller": "models.controllers",
    "hinf_controller": "models.controllers",
    "HinfDesign": "models.controllers",
    "ParameterError": "numerics.checks",
    # the errors a user catches: a run too large for the machine, a report folder refused
    "ResourceLimitError": "numerics.limits",
    "ReportError": "report.transaction",
    "DivergenceWarning": "numerics.integrate",
    "Solution": "numerics.integrate",
    "METHODS": "numerics.methods",
    "TABLEAUS": "numerics.methods",
    "ButcherTableau": "numerics.methods",
    "get_method": "numerics.methods",
    "ModalAnalysis": "models.modal",
    "Mode": "models.modal",
    "modal_analysis": "models.modal",
    "OUTPUTS": "models.quarter",
    "STATES": "models.quarter",
    "QuarterCarParams": "models.quarter",
    "load_config": "studies.scenario_toml",
    "quarter_car": "models.quarter",
    "read_config": "studies.scenario_toml",
    "quarter_car_model": "models.quarter",
    "Metric": "ride.metrics",
    "RideSignals": "ride.metrics",
    "write_report": "report",
    "plot_outputs": "report.plotting",
    "Scenario": "studies.scenario",
    "ScenarioError": "studies.scenario_toml",
    "Corner": "models.vehicle",
    "ModelEntry": "models.registry",
    "ModelOption": "models.registry",
    "DefaultRun": "models.registry",
    "register_model": "models.registry",
    "unregister_model": "models.registry",
    "get_model": "models.registry",
    "SignalRoles": "models.vehicle",
    "VehicleModel": "models.vehicle",
    "FixedStepResponse": "responses.timeresp",
    "forced_response": "responses.timeresp",
    "initial_response": "responses.timeresp",
    "step_response": "responses.timeresp",
    "impulse_response": "responses.timeresp",
    "input_output_response": "responses.timeresp",
    "Transmissibility": "ride.comfort",
    "ride_metrics": "ride.comfort",
    "ride_metrics_spectral": "ride.comfort",
    "transmissibility": "ride.comfort",
    "wk_filter": "ride.comfort",
    # ISO 2631-1's weightings (Annex A): the transfer function, the weighted signal
    "weighting": "ride.iso2631",
    "weighted": "ride.iso2631",
    # ISO 2631-1's assessment of a ride: per axis, a_v, MSDV, comfort, health
    "ride_assessment": "ride.assessment",
    "RideAssessment": "ride.assessment",
    "wk_weighted": "ride.comfort",
    "max_stable_step": "numerics.stability",
    "numerical_modes": "models.modal",
    "stability_function": "numerics.stability",
    "DEFAULT_METRICS": "studies.sweeps",
    "METRICS": "studies.sweeps",
    "SweepChunk": "studies.sweeps",
    "SweepResult": "studies.sweeps",
    "design_grid": "studies.sweeps",
    "sweep": "studies.sweeps",
    "spectral": "ride.spectral",
    "lyapunov_variances": "ride.spectral",
    "white_velocity_variances": "ride.spectral",
    "iso8608_intensity": "ride.road",
    "ISO8608Road": "ride.road",
    "HalfCarParams": "models.halfcar",
    "FullCarParams": "models.halfcar",
    "half_car": "models.halfcar",
    "half_car_model": "models.halfcar",
    "full_car": "models.halfcar",
    "full_car_model": "models.halfcar",
    # nonlinear quarter car
    "nonlinear_quarter_car": "models.nonlinear",
    "nonlinear_quarter_car_model": "models.nonlinear",
    "BumpStop": "models.nonlinear",
    "PiecewiseDamper": "models.nonlinear",
    # batched nonlinear sweeps
    "NonlinearQuarterCarBatch": "models.nonlinear",
    "simulate_batch": "studies.nlsweep",
    "BatchResponse": "studies.nlsweep",
    # sampled-data and predictive control
    "mpc_controller": "models.mpc",
    "sampled_lqr": "models.mpc",
    "MPCController": "models.mpc",
    "MPCSolution": "models.mpc",
    # measured data: identification and simulation against measurement
    "Measurement": "studies.measurement",
    "identify": "studies.identification",
    "Identification": "studies.identification",
    "compare_to_measurement": "studies.measured_comparison",
    "MeasurementComparison": "studies.measured_comparison",
}


if not TYPE_CHECKING:  # hidden from type checkers, so a misspelt name stays an error

    def __getattr__(name: str) -> Any:
        """Import a public name from its module on first use (PEP 562)."""
        try:
            module_name = _LAZY[name]
        except KeyError:
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
        module = importlib.import_module(f"{__name__}.{module_name}")
        # a module's own name (``road``) is the module, unless the module defines
        # it (``integrate``, the function of qc_control.numerics.integrate)
        value = getattr(module, name, module)
        globals()[name] = value  # later lookups find it without this hook
        return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


#: The public API is the one table of lazy names: a name added there is exported.
__all__ = sorted(_LAZY)


class _Package(_ModuleType):
    """The package's module type: importing one of 0.1's module paths
    (`qc_control._moved`) binds that module on the package, as every import of
    a submodule does; where the path is also a public name (``integrate``, the
    function; ``road``, the new module), the public name stays."""

    def __setattr__(self, name: str, value: Any) -> None:
        if (
            name in _LAZY
            and isinstance(value, _ModuleType)
            and value.__name__ == f"{__name__}.{name}"
        ):
            return
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package
_moved.install()
