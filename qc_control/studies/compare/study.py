"""`compare_methods`: the problem checked, the path of its system measured
(linear, nonlinear or sampled-data), and the `MethodComparison` built once.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import control
import numpy as np
import pandas as pd

from ...numerics.checks import ParameterError
from ...numerics.lti import is_nonlinear_system
from ...ride.assessment import RideAssessment, ride_assessment
from ...ride.road import Road
from .. import columns as col
from ..confirm import confirmed_costs
from ..on_road import road_problem
from ..peers import RTOLS, WorkPrecision, check_solvers, work_precision
from .linear import (
    engine_times,
    measure_linear,
)
from .measures import (
    coincident,
    cost_to_reach,
    error_table,
    mode_errors,
    on_road,
    ride_comparison,
)
from .nonlinear import measure_nonlinear
from .problem import (
    DEFAULT_METHODS,
    DEFAULT_X0,
    ComparisonProblem,
    as_model,
    checked_problem,
    default_grid,
)
from .result import Measured, MethodComparison
from .sampled import is_sampled, measure_sampled


def _cost_columns(problem: ComparisonProblem, responses: dict) -> pd.DataFrame:
    """Each method's order, stages, step and what its run at h cost."""
    tabs, names = problem.methods, [t.name for t in problem.methods]
    return pd.DataFrame(
        {
            col.ORDER: [t.order for t in tabs],
            col.STAGES: [t.stages for t in tabs],
            col.STEP: problem.h,
            col.STEPS: [responses[n].steps for n in names],
            col.RHS_EVALS: [responses[n].nfev for n in names],
        },
        index=names,
    )


def _comparison(
    problem: ComparisonProblem,
    measured: Measured,
    input_description: str,
    comfort: dict | None = None,
    **added: Any,
) -> MethodComparison:
    """The comparison from what either path measured: errors, modes, cost, ride; ``added``:
    the fields a path computed besides (the peers' study, a sampled loop's car), each
    before the result is built (it is frozen)."""
    reference, responses, tabs = measured.reference, measured.responses, problem.methods
    numerical, stability = mode_errors(tabs, problem.h, measured.linear, measured.modes)
    span = float(problem.T[-1] - problem.T[0])
    cost, cost_kind = cost_to_reach(
        measured.convergence, tabs, span, stability[col.H_MAX].to_dict()
    )
    checks = None
    if isinstance(problem.system, control.StateSpace):  # an exact reference to run against
        cost, cost_kind, checks = confirmed_costs(
            problem.system, problem.T, problem.X0, problem.U, tabs, cost, cost_kind,
            problem.model.body_disp, runs=measured.convergence,
        )  # fmt: skip
    table = pd.concat(
        [
            _cost_columns(problem, responses),
            measured.times,
            error_table(responses, reference, problem.model),
            measured.orders,
            stability,
        ],
        axis=1,
    )
    table.index.name = col.METHOD
    ride, ride_error = (
        ride_comparison(reference, responses, problem.model) if on_road(problem) else (None, None)
    )
    if comfort is not None:
        added["comfort"] = _comfort(problem, reference.response, comfort)
    return MethodComparison(
        **vars(problem),
        **added,
        table=table,
        modes=measured.modes,
        numerical_modes=numerical,
        convergence=measured.convergence,
        cost=cost,
        cost_kind=cost_kind,
        cost_checks=checks,
        coincident=coincident(responses),
        reference=reference.response,
        reference_error=reference.error,
        reference_time=reference.time,
        reference_description=reference.description,
        reference_name=reference.name,
        responses=responses,
        eigenvalues=np.linalg.eigvals(np.asarray(measured.linear.A, dtype=float)),
        input_description=input_description,
        ride=ride,
        ride_error=ride_error,
        transmissibility=measured.transmissibility,
        nonlinear=measured.nonlinear,
    )


def compare_methods(
    sys,
    T=None,
    X0=DEFAULT_X0,
    *,
    road: Road | None = None,
    U=None,
    methods: Sequence = DEFAULT_METHODS,
    h: float | None = None,
    repeats: int = 5,
    timing: bool = True,
    progress: Callable[[str], None] | None = None,
    input_description: str = "",
    params: Any = None,
    events: bool | None = None,
    levels: int | None = None,
    solvers: Sequence[str] | None = None,
    rtols: Sequence[float] = RTOLS,
    comfort: bool | Mapping[str, Any] = False,
) -> MethodComparison:
    """Compare fixed-step methods with python-control's exact response.

    The comparison is composed of steps that can be run alone:
    `exact_reference`, `method_responses`, `error_table`,
    `convergence_study`, `observed_orders`, `cost_to_reach`, `mode_errors`,
    `ride_comparison` and (optionally) `method_timings`.

    Parameters
    ----------
    sys : control.StateSpace, control.NonlinearIOSystem, VehicleModel, or parameters
        The vehicle. The parameters of a registered model
        (`QuarterCarParams`, `HalfCarParams`, `FullCarParams`, or a model
        added with `qc_control.register_model`) build it through its
        registry entry, with its road inputs when ``U`` is given; a half or
        full car then needs ``X0`` of its 8 or 14 states. A bare system with
        the signals of a registered model gets that model's roles. A
        `VehicleModel` whose ``system`` is a `control.NonlinearIOSystem`
        (`qc_control.nonlinear_quarter_car_model`, or `closed_loop` with a
        semi-active controller), or such a bare system, is compared against
        a tight ``solve_ivp`` (see Notes); a sampled-data loop against its
        exact response tick by tick.
    T : array_like, optional
        Uniform output grid [s]; default 0-10 s at 0.01 s.
    X0 : array_like, default ``(0, 0, 0.05, 0)``
        Initial state [m/s, m/s, m, m].
    road : qc_control.road.Road, optional
        The road the car drives, sampled on ``T`` under every wheel in the
        car's layout (`qc_control.studies.on_road.road_problem`: the rear
        wheels a wheelbase later). It gives ``U`` and
        ``input_description``; give it instead of them.
    U : array_like, optional
        Input samples on ``T`` (python-control's shapes); ``None`` for the
        free response.
    methods : sequence of str or ButcherTableau
    h : float, optional
        Step [s]; it must divide the spacing of ``T``. Default: the spacing.
    repeats : int, default 5
        Wall times are the best of this many runs: ``wall time`` of the
        step-by-step stepper (``engine='generic'``, the seed's loop, whose
        time follows the RHS evaluations) and ``LTI engine`` of the default
        engine, which gives the same trajectory.
    timing : bool, default True
        Measure wall times at all; without, the time columns are NaN and
        the comparison's numbers do not depend on the machine.
    progress : callable, optional
        Called with a short message as each step starts.
    input_description : str, optional
        What the input is (e.g. "ISO 8608 class C road at 20 m/s"), for
        the report.
    params : parameters of a registered model, optional
        The vehicle behind a bare ``sys`` (the ride metrics need its masses
        for the static wheel load); the model they build must have the
        system's inputs and outputs, or ``ValueError`` says which differ.
    events : bool, optional
        Nonlinear systems only: whether the methods step to each switching
        time (``qc.input_output_response(..., events=True)``). Default: when
        the system has switching functions (``sys.switching``). The
        convergence study runs both ways regardless.
    levels : int, optional
        Nonlinear systems only: refinements h, h/2, ..., h/2**levels of the
        convergence study (default `NONLINEAR_LEVELS`, 2; a linear
        comparison always refines 5 times).
    solvers : sequence of str, optional
        Peers to run beside the methods (`qc_control.studies.peers.SOLVERS`:
        ``'RK45'``, ``'DOP853'``, ``'LSODA'``, ``'Radau'``, ``'BDF'`` through
        ``solve_ivp``, ``'control'`` through ``control.input_output_response``
        at its defaults), each over ``rtols``, measured against the same
        reference; ``cmp.peers`` holds the work–precision study.
    rtols : sequence of float, default 1e-3, 1e-4, ..., 1e-10
        The peers' tolerance ladder (and the embedded qc pairs').
    comfort : bool or mapping, default False
        On a road: assess the exact reference's ride to ISO 2631-1:1997
        into ``cmp.comfort`` (`qc_control.ride_assessment` of it as the
        car's response). A mapping gives its ``seat`` (the seat's height
        above a half or full car's pitch and roll axes [m], for the
        fore-aft and lateral axes) and ``duration`` (the daily exposure [s]
        of Annex B's health guidance, 10 min to 24 h).

    Returns
    -------
    MethodComparison

    Notes
    -----
    The reference is ``control.initial_response`` (or ``forced_response``),
    the exact solution for an input linear between samples, via the matrix
    exponential. Errors are the largest (``max``) and root-mean-square
    (``rms``) differences over ``T`` of every output, and the difference
    of the body displacement at the last time. The observed order is the
    least-squares slope of log max-error against log h over h, h/2 and
    h/4, leaving out errors below 1e-13 m (rounding). Each mode's error is
    ``numerical_modes`` at the chosen h. Under a road input the comparison
    also holds `qc_control.ride_metrics` of the reference and of each
    method, and the transmissibility.

    **Nonlinear systems.** There is no exact solution: the reference is
    `nonlinear_reference` (DOP853 at rtol 1e-12, restarted at each
    switching event), computed once on the finest grid, with its own error
    estimated against a solve at 100x tighter tolerances. The methods run
    through `qc_control.input_output_response` (with ``events=True`` when
    the system has switching functions). The convergence study runs every
    method with and without events over h, h/2, ..., h/2**levels and fits
    an observed order to each (``table`` columns ``observed order
    (events)`` and ``(no events)``), leaving out errors within 10x of the
    reference's own. Modes, step limits and numerical modes are those of
    the linearisation at the static equilibrium (`control.linearize`).
    Wall times are one run each (no LTI engine); ``nonlinear`` holds the
    event times, the orders and where Midpoint and Heun part.

    **Sampled-data loops** (`qc_control.closed_loop` with a discrete
    controller). The reference is `sampled_reference`: between two ticks
    the car is linear with its move held, so the exact loop is the car's
    matrix-exponential step interval by interval, the law updated at each
    tick from that exact state (its own accuracy: against
    ``control.forced_response`` run tick interval by tick interval). The
    car's step ``h`` must land on every tick. Modes, step limits and
    numerical modes are the car's own (``sampled_car``): the controller
    acts only at the ticks. Wall times are one run each (no LTI engine);
    ``solvers``, ``events`` and ``levels`` do not apply.
    """
    if road is not None:
        if U is not None or input_description:
            raise ParameterError(
                "road", road, "given alone: the road gives U and input_description"
            )
        T = default_grid() if T is None else T
        sys, U, input_description = road_problem(sys, road, T, params)
    sys, model, params = as_model(sys, U, params)
    problem = checked_problem(sys, model, params, T, X0, U, methods, h, repeats)
    assess = _comfort_request(problem, comfort, input_description)
    peers = check_solvers(solvers)
    if is_sampled(sys):
        if events is not None or levels is not None or peers:
            raise ValueError(
                "events, levels and solvers do not apply to a sampled-data loop: its car is "
                "linear between the ticks, refined five times, and no solve_ivp peer knows "
                "the clock"
            )
        measured = measure_sampled(problem, repeats, timing, progress)
        return _comparison(
            problem, measured, input_description, assess, sampled_car=measured.linear
        )
    elif is_nonlinear_system(sys):
        measured = measure_nonlinear(problem, events, levels, timing, progress)
    else:
        if events is not None or levels is not None:
            raise ValueError(
                "events and levels apply to nonlinear systems only: a linear comparison has "
                "no switching and always refines h five times"
            )
        measured = measure_linear(problem, repeats, timing, progress)
    study = _peer_study(problem, measured, peers, rtols, progress) if peers else None
    return _comparison(problem, measured, input_description, assess, peers=study)


#: What ``compare_methods(comfort={...})`` passes on to `ride_assessment`.
_COMFORT_KEYS = ("seat", "duration")


def _comfort_request(problem: ComparisonProblem, comfort, input_description: str) -> dict | None:
    """``comfort`` checked before any work: None (no assessment) or the keyword
    arguments of `ride_assessment`. An assessment needs a road under the car: its
    samples (``U`` on the road inputs), or a car that reads its road itself as a
    function of time (the nonlinear car: no ``U``, the road in ``input_description``)."""
    if comfort is False or comfort is None:
        return None
    if comfort is True:
        comfort = {}
    if not isinstance(comfort, Mapping) or set(comfort) - set(_COMFORT_KEYS):
        raise ParameterError(
            "comfort", comfort, f"True, or a mapping of {' and '.join(_COMFORT_KEYS)}"
        )
    if not (on_road(problem) or (problem.U is None and input_description)):
        raise ParameterError(
            "comfort", True, "a road under the car: ISO 2631-1 assesses a ride (give road=)"
        )
    return dict(comfort)


def _comfort(problem: ComparisonProblem, response, request: dict) -> RideAssessment:
    """The exact reference's ride, assessed as the car's (its model's roles)."""
    return ride_assessment(response, model=problem.model, **request)


def _peer_study(
    problem: ComparisonProblem, measured: Measured, solvers, rtols, progress
) -> WorkPrecision:
    """The work–precision study: the peers beside the methods' convergence ladder."""
    sys = problem.system
    return work_precision(
        sys,
        problem.T,
        problem.X0,
        problem.U,
        measured.reference.response,
        list(sys.output_labels).index(problem.model.body_disp),
        engine_times(problem, measured.convergence),
        methods=problem.methods,
        solvers=solvers,
        rtols=rtols,
        reference_name=measured.reference.name,
        progress=progress,
    )
