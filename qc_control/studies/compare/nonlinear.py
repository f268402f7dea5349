"""The comparison of a nonlinear car: a DOP853 reference (`nlreference`), each
method with and without events over the refinements, the linearisation's modes.
"""

from __future__ import annotations

import functools
import math
import time
import warnings
from collections.abc import Callable
from typing import NamedTuple

import control
import numpy as np
import pandas as pd
import scipy
import scipy.signal

from ...models.modal import ModalAnalysis, modal_analysis
from ...models.vehicle import VehicleModel
from ...numerics.integrate import (
    DivergenceWarning,
)
from ...numerics.stability import max_stable_step
from ...responses.timeresp import (
    input_output_response,
)
from .. import columns as col
from .measures import (
    ConvergencePoint,
    Reference,
    Refinement,
    convergence_points,
    observed_orders,
    padded_outputs,
    refined,
    refined_input,
)
from .nlreference import NonlinearReference, nonlinear_reference
from .problem import (
    ROUNDING_FLOOR,
    ComparisonProblem,
)
from .result import Measured, NonlinearStudy

#: Refinements h, h/2, ..., h/2**levels of a nonlinear comparison (each a solve per method
#: with and without events; the observed order is fitted over these three).
NONLINEAR_LEVELS = 2
#: Errors within this factor of the reference's own are not fitted for an order.
_REFERENCE_MARGIN = 10.0
#: Midpoint and Heun "part" where their displacements first differ by more than this [m].
_PARTING = 1e-12


def _switching_labels(sys) -> tuple[str, ...]:
    if getattr(sys, "switching", None) is None:
        return ()
    return tuple(getattr(sys, "switching_labels", ()))


def _linearization(sys, params) -> tuple[control.StateSpace, ModalAnalysis, str]:
    """The system linearised at its static equilibrium, its modes, and what they are."""
    lin = control.linearize(sys, np.zeros(sys.nstates), np.zeros(sys.ninputs))
    lin = control.ss(
        lin.A,
        lin.B,
        lin.C,
        lin.D,
        states=list(sys.state_labels),
        inputs=list(sys.input_labels),
        outputs=list(sys.output_labels),
        name=f"{sys.name} (linearised)",
    )
    note = (
        "Modes, eigenvalues and step limits are those of the linearisation at the static "
        "equilibrium (x = 0, u = 0; control.linearize, a finite-difference Jacobian). They "
        "hold near that point only: a wheel in the air, a stop engaged or a clipped damper "
        "changes the local dynamics, and where a kink sits at the equilibrium (a semi-active "
        "law at zero velocity) the difference takes one side of it."
    )
    try:
        modes = modal_analysis(lin)
    except ValueError:
        if params is None:
            raise
        modes = modal_analysis(params)
        note += (
            " The linearisation is not in vehicle form (it has the controller's states), "
            "so the modes named are the passive car's."
        )
    return lin, modes, note


def _event_signs(sys, T, X0, U, ref: NonlinearReference, switching) -> tuple:
    """Each event's new sign (from the signs at T[0], flipped per crossing), and flights."""
    if not switching:
        return (), ()
    u0 = np.zeros(sys.ninputs) if U is None else U[:, 0]
    start = np.sign(np.atleast_1d(sys.switching(T[0], X0, u0, getattr(sys, "params", {}))))
    sign = {label: int(v) or 1 for label, v in zip(switching, start)}
    signs, flights, lost = [], [], math.nan
    for t, label in zip(ref.t_events, ref.event_labels):
        sign[label] = -sign.get(label, 1)
        signs.append(sign[label])
        if label == "contact":
            if sign[label] < 0:
                lost = float(t)
            elif not math.isnan(lost):
                flights.append((lost, float(t)))
                lost = math.nan
    if not math.isnan(lost):
        flights.append((lost, math.nan))
    return tuple(signs), tuple(flights)


def _run_nonlinear(sys, T, X0, U, tab, substeps, events: bool):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DivergenceWarning)
        return input_output_response(
            sys,
            T,
            0.0 if U is None else U,
            X0,
            method=tab,
            substeps=substeps,
            events=True if events else None,
        )


def _outputs_along(sys, T, x, U) -> np.ndarray:
    """The system's outputs ``(noutputs, N)`` at the states ``x (n, N)`` and inputs on ``T``."""
    u = np.zeros((sys.ninputs, T.size)) if U is None else U
    return np.column_stack([sys.output(t, x[:, k], u[:, k]) for k, t in enumerate(T)])


def _parting(cmp_responses: dict, sys, model: VehicleModel, T) -> tuple[dict, np.ndarray | None]:
    """Where Midpoint and Heun part: their largest displacement difference and when."""
    if not {"midpoint", "heun"} <= set(cmp_responses):
        return {}, None
    metres = [i for i, label in enumerate(sys.output_labels) if model.unit(label) == "m"]
    a = padded_outputs(cmp_responses["midpoint"], T.size)[metres]
    b = padded_outputs(cmp_responses["heun"], T.size)[metres]
    with np.errstate(invalid="ignore"):
        gap = np.nan_to_num(np.max(np.abs(a - b), axis=0), nan=np.inf)
    apart = np.flatnonzero(gap > _PARTING)
    return {
        "pair": ("midpoint", "heun"),
        "max [m]": float(gap.max()),
        "at [s]": float(T[int(np.argmax(gap))]),
        "from [s]": float(T[apart[0]]) if apart.size else math.nan,
    }, gap


def _checked_events(sys, events, switching: tuple[str, ...]) -> bool:
    """Whether the methods step to each switching time: by default, when there are any."""
    if events is None:
        return bool(switching)
    if not isinstance(events, bool):
        raise TypeError(f"events must be None, True or False, got {events!r}")
    if events and not switching:
        raise ValueError(
            f"events=True needs switching functions; system {sys.name!r} has none "
            "(sys.switching, as qc.nonlinear_quarter_car gives)"
        )
    return events


def _checked_levels(levels) -> int:
    levels = NONLINEAR_LEVELS if levels is None else levels
    if isinstance(levels, bool) or not isinstance(levels, int) or not 1 <= levels <= 6:
        raise ValueError(f"levels must be an integer from 1 to 6, got {levels!r}")
    return levels


class _SolvedReference(NamedTuple):
    """The DOP853 reference, and what the comparison reads of it."""

    solution: NonlinearReference  # on T refined 2**levels times
    reference: Reference  # on T: the errors at h and the report's figures
    body: np.ndarray  # the body displacement on the finest grid [m]
    floor: float  # errors below this [m] are not fitted for an order


def _reference_response(sys, T, x, U) -> control.TimeResponseData:
    """The reference's states ``x`` on ``T`` as a response, with the outputs along them."""
    return control.TimeResponseData(
        T,
        _outputs_along(sys, T, x, U),
        x,
        U if U is not None else np.zeros((sys.ninputs, T.size)),
        output_labels=list(sys.output_labels),
        state_labels=list(sys.state_labels),
        input_labels=list(sys.input_labels),
        sysname=sys.name,
        title=f"DOP853 reference for {sys.name}",
        issiso=sys.ninputs == 1 and sys.noutputs == 1,
    )


def _displacement_accuracy(sys, model: VehicleModel, ref: NonlinearReference) -> float:
    """The reference's own error on the displacements [m], which the methods' are measured on."""
    metre_states = [i for i, s in enumerate(sys.state_labels) if model.unit(s) == "m"]
    if metre_states:
        return float(np.max(ref.state_accuracy[metre_states]))
    return ref.accuracy * float(np.max(np.abs(ref.x)))


def _solve_reference(problem: ComparisonProblem, levels: int, switching) -> _SolvedReference:
    """DOP853 once on the finest grid (restarted at each event), timed, with its accuracy."""
    sys, T, U = problem.system, problem.T, problem.U
    fine_T, fine_U = refined(T, levels), refined_input(T, U, levels)
    start = time.perf_counter()
    solution = nonlinear_reference(
        sys,
        fine_T,
        0.0 if fine_U is None else fine_U,
        problem.X0,
        events=True if switching else None,
    )
    seconds = time.perf_counter() - start
    error = _displacement_accuracy(sys, problem.model, solution)
    name = (
        "scipy.integrate.solve_ivp (DOP853, rtol 1e-12, atol 1e-12·max|x_i| per state, "
        f"restarted at every switching event; scipy {scipy.__version__})"
    )
    reference = Reference(
        _reference_response(sys, T, solution.x[:, :: 2**levels], U),
        error,
        "the same solve at rtol and atol 100x tighter",
        name,
        seconds,
    )
    body = list(sys.output_labels).index(problem.model.body_disp)
    fine_body = _outputs_along(sys, fine_T, solution.x, fine_U)[body]
    floor = max(ROUNDING_FLOOR, _REFERENCE_MARGIN * error)
    return _SolvedReference(solution, reference, fine_body, floor)


def _nonlinear_refinement(
    sys,
    X0,
    substeps: int,
    events: bool,
    fine_body,
    levels: int,
    timing: bool,
    tab,
    level,
    T,
    U,
) -> Refinement:
    """A method on a refined grid of a nonlinear system, against the reference's samples there.

    Its time is the run itself (there is no LTI engine to compare with).
    """
    start = time.perf_counter()
    response = _run_nonlinear(sys, T, X0, U, tab, substeps, events)
    seconds = time.perf_counter() - start if timing else math.nan
    return Refinement(response, fine_body[:: 2 ** (levels - level)], seconds)


class _EventConvergence(NamedTuple):
    """The convergence study run with and without events."""

    frame: pd.DataFrame  # long form: method, events, level, h, steps, nfev, time, error, stable
    at_h: dict  # (method, events) -> its response at h


def _event_convergence(
    problem: ComparisonProblem,
    solved: _SolvedReference,
    levels: int,
    ways: tuple[bool, ...],
    eig: np.ndarray,
    timing: bool,
    progress: Callable[[str], None] | None,
) -> _EventConvergence:
    """Every method over h, h/2, ..., h/2**levels, each way of stepping in ``ways``."""
    sys, h = problem.system, problem.h
    body = list(sys.output_labels).index(problem.model.body_disp)
    rows: list[tuple[bool, ConvergencePoint]] = []
    at_h = {}
    for tab in problem.methods:
        h_max = max_stable_step(tab, eig)
        for events in ways:
            if progress:
                with_events = " with events" if events else ""
                progress(f"{tab.name}{with_events}: h = {h:g} s and {levels} halvings")
            run = functools.partial(
                _nonlinear_refinement,
                sys,
                problem.X0,
                problem.substeps,
                events,
                solved.body,
                levels,
                timing,
            )
            points, at_h[tab.name, events] = convergence_points(
                tab, problem.T, problem.U, h, levels, h_max, body, run
            )
            rows += [(events, point) for point in points]
    frame = pd.DataFrame([point for _, point in rows])
    frame.insert(1, col.EVENTS, [events for events, _ in rows])
    return _EventConvergence(frame, at_h)


def _event_orders(convergence: pd.DataFrame, names: list[str], floor: float, levels: int):
    """Per method, the observed order with and without events over every refinement."""
    orders = pd.DataFrame(
        {
            column: observed_orders(
                convergence[convergence[col.EVENTS] == events], levels, floor
            ).reindex(names)
            for events, column in ((True, col.WITH_EVENTS), (False, col.WITHOUT_EVENTS))
        }
    )
    orders.index.name = col.METHOD
    return orders


def _nonlinear_times(convergence: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    """The wall-time columns: each method's run at h; no LTI engine, no exact call."""
    at_h = convergence[convergence[col.LEVEL] == 0].set_index(col.METHOD)
    return pd.DataFrame(
        {
            col.WALL_TIME: 1e3 * at_h[col.TIME].reindex(names),
            col.LTI_ENGINE: math.nan,
            col.PER_CONTROL: math.nan,
        },
        index=names,
    )


def _method_events(at_h: dict, names: list[str], switching) -> dict:
    """Per method, ``(t_events, event_labels)`` of its run at h with events."""
    if not switching:
        return {name: (np.empty(0), ()) for name in names}
    return {name: (at_h[name, True].t_events, at_h[name, True].event_labels) for name in names}


def measure_nonlinear(
    problem: ComparisonProblem, events, levels, timing: bool, progress: Callable[[str], None] | None
) -> Measured:
    """The nonlinear path: a DOP853 reference, each method with and without events."""
    sys, T = problem.system, problem.T
    switching = _switching_labels(sys)
    events = _checked_events(sys, events, switching)
    levels = _checked_levels(levels)
    lin, modes, note = _linearization(sys, problem.params)
    if progress:
        progress("reference: solve_ivp DOP853 at rtol 1e-12 (and 1e-14 for its own accuracy)")
    solved = _solve_reference(problem, levels, switching)
    ways = (True, False) if switching else (False,)
    eig = np.linalg.eigvals(np.asarray(lin.A, dtype=float))
    runs = _event_convergence(problem, solved, levels, ways, eig, timing, progress)
    names = [t.name for t in problem.methods]
    responses = {name: runs.at_h[name, events] for name in names}
    long = runs.frame
    convergence = long[long[col.EVENTS] == events].drop(columns=col.EVENTS).reset_index(drop=True)
    orders = _event_orders(long, names, solved.floor, levels)
    parting, gap = _parting(responses, sys, problem.model, T)
    signs, flights = _event_signs(sys, T, problem.X0, problem.U, solved.solution, switching)
    study = NonlinearStudy(
        events=events,
        switching_labels=switching,
        t_events=solved.solution.t_events,
        event_labels=solved.solution.event_labels,
        event_signs=signs,
        airborne=flights,
        method_events=_method_events(runs.at_h, names, switching),
        convergence=long,
        orders=orders,
        parting=parting,
        parting_gap=gap,
        reference=solved.solution,
        error_floor=solved.floor,
        linearization=lin,
        linearization_note=note,
    )
    main = col.WITH_EVENTS if events else col.WITHOUT_EVENTS
    table_orders = pd.DataFrame(
        {
            col.OBSERVED_ORDER: orders[main],
            col.OBSERVED_ORDER_EVENTS: orders[col.WITH_EVENTS],
            col.OBSERVED_ORDER_NO_EVENTS: orders[col.WITHOUT_EVENTS],
        }
    )
    times = _nonlinear_times(convergence, names)
    return Measured(
        solved.reference, responses, lin, modes, convergence, table_orders, times, None, study
    )
