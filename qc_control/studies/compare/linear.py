"""The comparison of a linear car: python-control's exact response, each method
at h and refined, the ladder timed in interleaved rounds (`qc_control.studies.timing`).
"""

from __future__ import annotations

import functools
import math
import time
import warnings
from collections.abc import Callable, Sequence

import control
import numpy as np
import pandas as pd
import scipy
import scipy.signal

from ...models.modal import modal_analysis
from ...models.vehicle import VehicleModel
from ...numerics.integrate import (
    DivergenceWarning,
    checked_uniform_step,
)
from ...numerics.lti import is_nonlinear_system
from ...numerics.methods import ButcherTableau
from ...numerics.reference import exact_response
from ...numerics.stability import step_is_stable
from ...responses.timeresp import (
    forced_response,
    initial_response,
)
from ...ride.comfort import transmissibility
from .. import columns as col
from ..timing import interleaved_times
from .measures import (
    Reference,
    Refinement,
    best_time,
    convergence_ladder,
    observed_orders,
    on_road,
    refined,
    refined_input,
)
from .problem import (
    LEVELS,
    ComparisonProblem,
)
from .result import Measured


def _simulate(sys, T, X0, U, method, substeps, engine="auto"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DivergenceWarning)
        if U is None:
            return initial_response(sys, T, X0, method=method, substeps=substeps, engine=engine)
        return forced_response(sys, T, U, X0, method=method, substeps=substeps, engine=engine)


def exact_reference(sys, T, X0, U=None, *, outputs=None, repeats: int = 0) -> Reference:
    """python-control's exact response and its accuracy against an independent one.

    The accuracy is the largest difference over the output labels in
    ``outputs`` (all outputs by default; `compare_methods` measures the
    displacements, in metres).

    Free response: the modal closed form ``C V e^{Λt} V⁻¹ x0`` at every t
    (no recurrence, so no accumulated rounding). Forced response:
    ``scipy.signal.lsim``, an independent implementation of the same exact
    solution for an input linear between samples. ``repeats > 0`` also
    times ``control``'s call (best of ``repeats``).
    """
    reference = exact_response(sys, T, X0, U)
    A, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.C, sys.D))
    if U is None:
        lam, V = np.linalg.eig(A)
        z0 = np.linalg.solve(V, np.asarray(X0, dtype=complex))
        other = C @ (V @ (z0[:, None] * np.exp(np.outer(lam, T - T[0])))).real
        how = "the modal closed form C·V·exp(Λt)·V⁻¹·x0"
    else:
        lti = (A, np.asarray(sys.B, dtype=float), C, D)  # lsim builds its StateSpace from these
        _, y, _ = scipy.signal.lsim(lti, U.T if U.shape[0] > 1 else U[0], T - T[0], X0=X0)
        other = np.atleast_2d(y.T) if y.ndim > 1 else y[None]
        how = "scipy.signal.lsim"
    labels = list(sys.output_labels)
    rows = [labels.index(label) for label in (labels if outputs is None else outputs)]
    ours = np.asarray(reference.outputs).reshape(other.shape)
    error = float(np.max(np.abs(ours[rows] - other[rows])))
    elapsed = best_time(lambda: exact_response(sys, T, X0, U), repeats) if repeats else math.nan
    name = (
        f"control.{'initial' if U is None else 'forced'}_response "
        f"(python-control {control.__version__})"
    )
    return Reference(reference, error, how, name, elapsed)


def method_responses(
    sys,
    T,
    X0,
    U,
    methods: Sequence[ButcherTableau],
    substeps: int = 1,
    progress: Callable[[str], None] | None = None,
) -> dict:
    """Each method's response at the grid's step: ``{name: FixedStepResponse}``."""
    out = {}
    for tab in methods:
        if progress:
            progress(f"{tab.name}: simulating")
        out[tab.name] = _simulate(sys, T, X0, U, tab, substeps)
    return out


def _stepped_by_default(tab: ButcherTableau, T: np.ndarray, substeps: int, eig) -> bool:
    """Whether the responses' default engine steps this run step by step: on a uniform
    grid, exactly when the step is beyond the method's stability limit (the responses'
    own test, `step_is_stable` on ``A``'s eigenvalues), where the LTI engine hands
    the diverging run to the generic stepper."""
    dt = checked_uniform_step(T)
    return dt is not None and not step_is_stable(tab, dt / substeps, eig)


def _linear_refinement(
    sys, X0, substeps: int, body: int, timing: bool, eig, exact_at: dict, tab, level, T, U
) -> Refinement:
    """A method on a refined grid of a linear system, against the exact response there.

    The exact response on each refined grid is the same for every method:
    computed for the first and kept in ``exact_at`` (by level) for the others.
    Its time is a run step by step (``engine='generic'``, whose time follows
    the RHS evaluations), as `method_timings` measures: a second run, unless
    the default engine steps this one step by step itself (a step beyond the
    stability limit), when the one run is that run, timed.
    """
    if level not in exact_at:
        exact_at[level] = np.asarray(exact_response(sys, T, X0, U).outputs)[body]
    exact = exact_at[level]
    if timing and _stepped_by_default(tab, T, substeps, eig):
        start = time.perf_counter()
        response = _simulate(sys, T, X0, U, tab, substeps, "generic")
        return Refinement(response, exact, time.perf_counter() - start)
    response = _simulate(sys, T, X0, U, tab, substeps)
    seconds = (
        best_time(lambda: _simulate(sys, T, X0, U, tab, substeps, "generic"), 1)
        if timing
        else math.nan
    )
    return Refinement(response, exact, seconds)


def convergence_study(
    sys,
    T,
    X0,
    U,
    methods: Sequence[ButcherTableau],
    h: float,
    substeps: int,
    model: VehicleModel,
    *,
    levels: int = LEVELS,
    timing: bool = True,
    progress: Callable[[str], None] | None = None,
) -> pd.DataFrame:
    """Max body-displacement error at h, h/2, ..., h/2**levels, per method (long form).

    Columns (`ConvergencePoint`): method, level, h, steps, nfev, time
    (step-by-step wall time of one run [s], NaN without ``timing``), error
    [m], stable (h within the method's stability limit). The input is
    refined by linear interpolation, which is the same input function.
    """
    eig = np.linalg.eigvals(np.asarray(sys.A, dtype=float))
    body = list(sys.output_labels).index(model.body_disp)
    run = functools.partial(_linear_refinement, sys, X0, substeps, body, timing, eig, {})
    return convergence_ladder(methods, T, U, h, levels, eig, body, run, progress)


def method_timings(
    sys, T, X0, U, methods: Sequence[ButcherTableau], substeps: int, repeats: int
) -> pd.DataFrame:
    """Median wall time [ms] of each method step by step (``engine='generic'``, the
    seed's loop, whose time follows the RHS evaluations) and with the LTI engine,
    over ``repeats`` interleaved rounds (`qc_control.studies.timing`)."""
    runs = {
        (tab.name, engine): functools.partial(_simulate, sys, T, X0, U, tab, substeps, engine)
        for tab in methods
        for engine in ("generic", "auto")
    }
    times = interleaved_times(runs, max(1, repeats))
    return pd.DataFrame.from_dict(
        {
            tab.name: {
                col.WALL_TIME: 1e3 * times[tab.name, "generic"].wall,
                col.LTI_ENGINE: 1e3 * times[tab.name, "auto"].wall,
            }
            for tab in methods
        },
        orient="index",
    )


#: Rounds the convergence ladder is timed in: its 24 runs take a second a round on
#: the seed's grid, and the median of 3 already sets Midpoint and Heun (the same
#: evaluations) within their spread of each other.
LADDER_ROUNDS = 3


def _timed_ladder(
    problem: ComparisonProblem, convergence: pd.DataFrame, rounds: int
) -> pd.DataFrame:
    """The convergence study's runs timed step by step (``engine='generic'``, the
    seed's loop, whose time follows the RHS evaluations), all of them in
    interleaved rounds (`qc_control.studies.timing`): the one measurement the
    cost table (level 0) and the work-precision figure both quote."""
    tabs = {t.name: t for t in problem.methods}
    sys, X0, substeps = problem.system, problem.X0, problem.substeps
    runs = {
        (method, level): functools.partial(
            _simulate, sys, refined(problem.T, level), X0,
            refined_input(problem.T, problem.U, level), tabs[method], substeps, "generic",
        )
        for method, level in zip(convergence[col.METHOD], convergence[col.LEVEL])
    }  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DivergenceWarning)
        # no warm-up: the convergence study has just made each run
        times = interleaved_times(runs, max(1, rounds), warmup=False)
    keyed = [times[key] for key in zip(convergence[col.METHOD], convergence[col.LEVEL])]
    return convergence.assign(
        time=[t.wall for t in keyed],
        time_low=[t.low for t in keyed],
        time_high=[t.high for t in keyed],
        cpu_time=[t.cpu for t in keyed],
    )


def _linear_times(
    problem: ComparisonProblem,
    reference: Reference,
    repeats: int,
    timing: bool,
    convergence: pd.DataFrame,
) -> pd.DataFrame:
    """The wall-time columns of a linear comparison (NaN without ``timing``): the
    step-by-step times are the ladder's at h (`_timed_ladder`), the LTI engine's
    `method_timings`'."""
    names = [t.name for t in problem.methods]
    if not timing:
        return pd.DataFrame(math.nan, index=names, columns=col.TIME_COLUMNS)
    at_h = convergence[convergence[col.LEVEL] == 0].set_index(col.METHOD).reindex(names)
    sys, T, X0, U = problem.system, problem.T, problem.X0, problem.U
    lti = method_timings(sys, T, X0, U, problem.methods, problem.substeps, repeats)[col.LTI_ENGINE]
    times = pd.DataFrame(
        {
            col.WALL_TIME: 1e3 * at_h[col.TIME],
            col.WALL_MIN: 1e3 * at_h[col.TIME_LOW],
            col.WALL_MAX: 1e3 * at_h[col.TIME_HIGH],
            col.CPU_TIME: 1e3 * at_h[col.CPU],
            col.LTI_ENGINE: lti,
        },
        index=names,
    )
    times[col.PER_CONTROL] = times[col.WALL_TIME] / (1e3 * reference.time)
    return times


def measure_linear(
    problem: ComparisonProblem, repeats: int, timing: bool, progress: Callable[[str], None] | None
) -> Measured:
    """The linear path: python-control's exact response, each method at h and refined."""
    sys, model, T, X0, U = problem.system, problem.model, problem.T, problem.X0, problem.U
    modes = modal_analysis(model)  # its corners name the modes of any registered model
    metres = [label for label in sys.output_labels if model.unit(label) == "m"]
    reference = exact_reference(sys, T, X0, U, outputs=metres, repeats=repeats if timing else 0)
    responses = method_responses(sys, T, X0, U, problem.methods, problem.substeps)
    convergence = convergence_study(
        sys,
        T,
        X0,
        U,
        problem.methods,
        problem.h,
        problem.substeps,
        model,
        timing=False,  # timed below, every run of the ladder in turns
        progress=progress,
    )
    if timing:
        convergence = _timed_ladder(problem, convergence, min(repeats, LADDER_ROUNDS))
    else:
        convergence = convergence.assign(time_low=math.nan, time_high=math.nan, cpu_time=math.nan)
    # one road input: the quarter car's transmissibility (a car on several axles
    # needs the speed for its wheelbase delay: qc.transmissibility(model, speed=V))
    one_road = on_road(problem) and len(model.road_inputs()) == 1
    return Measured(
        reference,
        responses,
        sys,
        modes,
        convergence,
        observed_orders(convergence).to_frame(),
        _linear_times(problem, reference, repeats, timing, convergence),
        transmissibility(sys) if one_road and problem.params is not None else None,
    )


def engine_times(problem: ComparisonProblem, convergence: pd.DataFrame) -> pd.DataFrame:
    """The fixed-step ladder timed as a user runs it: a linear car through the LTI engine
    (qc's default for it, the same trajectory), in 3 interleaved rounds
    (`qc_control.studies.timing`, as the comparison times its runs); a nonlinear
    one as stepped.

    A step beyond a method's stability limit is one the default engine steps step
    by step (a diverging run, never among the cheapest): its time is the
    convergence study's, which timed that same run.
    """
    if is_nonlinear_system(problem.system) or convergence[col.TIME].isna().all():
        return convergence
    tabs = {t.name: t for t in problem.methods}
    eig = np.linalg.eigvals(np.asarray(problem.system.A, dtype=float))
    runs: dict[int, Callable[[], object]] = {}
    times = list(convergence[col.TIME])
    for row, (method, level) in enumerate(zip(convergence[col.METHOD], convergence[col.LEVEL])):
        T, U = refined(problem.T, level), refined_input(problem.T, problem.U, level)
        if not _stepped_by_default(tabs[method], T, problem.substeps, eig):
            runs[row] = functools.partial(
                _simulate, problem.system, T, problem.X0, U, tabs[method], problem.substeps
            )
    for row, timing in interleaved_times(runs, 3).items():
        times[row] = timing.wall
    return convergence.assign(time=times)
