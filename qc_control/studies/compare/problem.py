"""The problem every method of a comparison solves: its defaults, and its arguments checked.

`checked_problem` turns what a user passes `compare_methods` (a system, a
VehicleModel or parameters; a grid, a start, an input, a step, the methods)
into one `ComparisonProblem`, each error naming the value and what was expected.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import control
import numpy as np

from ...models.quarter import SEED_X0, as_params
from ...models.registry import MODELS, model_for_params, model_for_system
from ...models.vehicle import VehicleModel
from ...numerics import checks
from ...numerics.integrate import (
    check_time_grid,
    uniform_step,
)
from ...numerics.limits import check_memory
from ...numerics.lti import is_nonlinear_system
from ...numerics.methods import ButcherTableau, get_method
from ...responses.timeresp import (
    check_initial_state,
    check_input_samples,
)

#: The default scenario: the seed's vehicle, body released from 5 cm, 0-10 s, h = 0.01 s.
DEFAULT_METHODS = ("euler", "midpoint", "heun", "rk4")
DEFAULT_X0 = SEED_X0
DEFAULT_T_END = 10.0
DEFAULT_H = 0.01
#: Accuracies [m] at which the report names the cheapest method.
TOLERANCES = (1e-3, 1e-6, 1e-9)
#: Refinements h, h/2, ..., h/2**LEVELS for convergence and work-precision.
LEVELS = 5
#: Errors below this [m] are rounding, not truncation: left out of order fits.
ROUNDING_FLOOR = 1e-13


@runtime_checkable
class Provenance(Protocol):
    """The run a comparison came from, as a report records it.

    Whatever set the run up (the command line's Scenario is one) can say
    the command that redoes it and its whole setting as TOML; the report
    prints the one and saves the other as ``scenario.toml``.
    """

    def command(self) -> str:
        """The command that redoes the run."""
        ...

    def to_toml(self) -> str:
        """The run's whole setting: vehicle, initial state, input, time span, step, methods."""
        ...


@dataclass(frozen=True, eq=False)
class ComparisonProblem:
    """What every method of a comparison solves, as `compare_methods` checked it.

    Attributes
    ----------
    system : control.StateSpace or control.NonlinearIOSystem
        The vehicle's system.
    params : object
        The parameters the vehicle was built from (None for a bare system).
    model : VehicleModel
        The vehicle's description (signal roles, units).
    T : ndarray
        The uniform output grid [s].
    X0 : ndarray
        The initial state.
    U : ndarray or None
        The input samples on ``T``; None for the free response.
    h : float
        The step [s]; ``substeps`` of it per interval of ``T``.
    substeps : int
    methods : tuple of ButcherTableau
    """

    system: control.NonlinearIOSystem
    params: Any
    model: VehicleModel
    T: np.ndarray
    X0: np.ndarray
    U: np.ndarray | None
    h: float
    substeps: int
    methods: tuple[ButcherTableau, ...]


def _grid(T: np.ndarray, h: float | None) -> tuple[float, int]:
    """The step h and the substeps per interval of the uniform grid T."""
    dt = uniform_step(T)
    if dt is None:
        raise ValueError("T must be uniformly spaced for a method comparison")
    if h is None:
        return dt, 1
    if isinstance(h, bool) or not isinstance(h, (int, float)) or not (math.isfinite(h) and h > 0):
        raise checks.ParameterError("h", h, "a finite step > 0 s")
    k = round(dt / h)
    if k < 1 or abs(k * h - dt) > 1e-9 * dt:
        raise checks.ParameterError(
            "h",
            h,
            f"a step dividing the grid spacing {dt!r} s of T",
            message=f"h = {h!r} s must divide the grid spacing {dt!r} s of T",
        )
    return dt / k, int(k)


def as_model(sys, U, params) -> tuple[control.NonlinearIOSystem, VehicleModel | None, Any]:
    """(system, model, params) from a system, parameters, a model, or None.

    Parameters are built by their registry entry (`qc_control.models.registry`);
    a bare system gets the roles of the registered model whose signals it has.
    """
    if isinstance(sys, VehicleModel):
        return sys.system, sys, sys.params
    if is_nonlinear_system(sys):
        model = _nonlinear_model(sys, params)
        return sys, model, None if model is None else model.params
    if sys is None or isinstance(sys, dict):
        sys = as_params(sys)
    entry = model_for_params(sys)
    if entry is not None:
        model = entry.model(sys, road=U is not None)
        return model.system, model, model.params
    if not isinstance(sys, control.StateSpace):
        raise TypeError(
            f"sys must be a control.StateSpace, a control.NonlinearIOSystem, a VehicleModel "
            f"or the parameters of a registered model ({', '.join(MODELS)}), "
            f"got {type(sys).__name__}"
        )
    if params is not None:  # the vehicle behind the system is given
        p = as_params(params) if isinstance(params, dict) else params
        like = model_for_params(p)
    else:  # the labels give the roles even without the parameters
        p, like = None, model_for_system(sys)
    if like is None:
        return sys, None, None
    model = _model_like(like, p, sys)
    if model is None and params is not None:
        raise ValueError(
            f"params ({type(params).__name__}) do not describe system {sys.name!r}: no "
            f"{like.name} model has its inputs {list(sys.input_labels)} and outputs "
            f"{list(sys.output_labels)}"
        )
    return sys, model, None if model is None else params


def _model_like(entry, params, sys) -> VehicleModel | None:
    """The entry's model (of ``params``) with exactly the system's inputs and
    outputs, with or without its road and actuator inputs; None if none has."""
    signals = (list(sys.input_labels), list(sys.output_labels))
    for road, actuator in itertools.product((False, True), repeat=2):
        try:
            model = entry.model(params, road=road, actuator=actuator)
        except (TypeError, ValueError):  # a model without that input
            continue
        same = (list(model.system.input_labels), list(model.system.output_labels)) == signals
        # and the same states: a model option (a damper top mount) may add one
        if same and model.system.nstates == sys.nstates:
            return model
    return None


def _tableaus(methods: Sequence) -> tuple[ButcherTableau, ...]:
    """The methods by name or tableau: at least one, each once."""
    tabs = tuple(get_method(m) for m in methods)
    if not tabs:
        raise ValueError("methods must name at least one method")
    names = [t.name for t in tabs]
    if len(set(names)) != len(names):
        raise ValueError(f"methods must be distinct, got {names}")
    return tabs


def default_grid() -> np.ndarray:
    """The comparison's time grid unless one is given: 0-10 s at 0.01 s."""
    return np.linspace(0, DEFAULT_T_END, 1001)


def checked_problem(
    sys, model, params, T, X0, U, methods: Sequence, h, repeats
) -> ComparisonProblem:
    """The comparison's arguments checked, each error naming the value and what was expected."""
    if model is None:
        raise ValueError(
            f"system {sys.name!r} is not a known vehicle: pass a VehicleModel "
            "(e.g. qc.quarter_car_model(params, road=True)) so that the "
            "comparison knows which output is which"
        )
    T = check_time_grid(default_grid() if T is None else T, "T")
    h, substeps = _grid(T, h)
    tabs = _tableaus(methods)
    checks.integer("repeats", repeats, minimum=1)
    X0 = check_initial_state(X0, sys.nstates)
    if U is not None:
        U = check_input_samples(U, sys.ninputs, T.size)
    # the finest refinement holds 2**levels times the samples, states and outputs, in the
    # method's response and the exact one, with the scans' temporaries
    finest = (T.size - 1) * 2**LEVELS + 1
    check_memory(
        6 * finest * (sys.nstates + sys.noutputs + sys.ninputs) * 8,
        f"a method comparison over {T.size - 1} steps (refined down to h/{2**LEVELS})",
        "use a shorter run or a larger step",
    )
    return ComparisonProblem(sys, params, model, T, X0, U, h, substeps, tabs)


def _bare_rebuild(name: str, params) -> VehicleModel:
    raise ValueError(
        f"system {name!r} was passed bare: build it as a VehicleModel "
        "(qc.nonlinear_quarter_car_model, qc.closed_loop) to rebuild it from other parameters"
    )


def _nonlinear_model(sys, params) -> VehicleModel | None:
    """Roles for a bare NonlinearIOSystem with the signals of a registered model
    (the nonlinear car's, or the quarter car's closed loop)."""
    entry = model_for_system(sys)
    if entry is None:
        return None
    if params is None:
        own = getattr(sys, "params", None) or {}
        names = [k for k in entry.keys() if k in own and k != "zeta"]  # cs states the damping
        params = {k: own[k] for k in names} or None
    if isinstance(params, dict):
        params = entry.params.from_mapping(params)
    p = entry.params() if params is None else params
    like = entry.model(p, road=True)  # the car whose labels these are, with or without road
    if not set(like.road_inputs()) <= set(sys.input_labels):
        like = entry.model(p)
    units = {**like.units, "fa": "N"}
    units.update({s: units.get(s, "-") for s in sys.state_labels})
    units.update({u: units.get(u, "-") for u in sys.input_labels})
    return VehicleModel(sys, p, units, like.roles, functools.partial(_bare_rebuild, sys.name))
