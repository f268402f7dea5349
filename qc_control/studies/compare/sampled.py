"""The comparison of a sampled-data loop (a car closed by a controller on a
clock): the exact loop tick by tick, each method at h and refined.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import control
import numpy as np
import pandas as pd

from ...models.modal import modal_analysis
from ...numerics.clocked import ClockedLoop, exact_clocked
from ...numerics.sampled import linear_input
from ...responses.timeresp import (
    input_output_response,
)
from .. import columns as col
from .measures import (
    Reference,
    Refinement,
    best_time,
    convergence_ladder,
    observed_orders,
)
from .problem import (
    LEVELS,
    ComparisonProblem,
)
from .result import Measured


def is_sampled(sys) -> bool:
    """Whether ``sys`` is a car closed by a controller on a clock (`numerics.clocked`)."""
    return isinstance(sys, ClockedLoop)


def _road_samples(sys: ClockedLoop, T: np.ndarray, U) -> np.ndarray:
    """The loop's external inputs on ``T`` (zeros for a free response)."""
    return (
        np.zeros((sys.ninputs, T.size)) if U is None else np.asarray(U, float).reshape(-1, T.size)
    )


def _sampled_response(sys: ClockedLoop, T, U, x: np.ndarray, title: str):
    """States ``x`` of the loop on ``T`` as a response, with the loop's outputs along them."""
    W = _road_samples(sys, T, U)
    return control.TimeResponseData(
        T,
        sys.outputs_of(x, W),
        x,
        W,
        output_labels=list(sys.output_labels),
        state_labels=list(sys.state_labels),
        input_labels=list(sys.input_labels),
        sysname=sys.name,
        title=title,
        issiso=False,
    )


def _exact_sampled(sys: ClockedLoop, T, X0, U, substeps: int) -> np.ndarray:
    """The exact loop's states on ``T`` (`exact_clocked`): plant, controller, hold."""
    run = exact_clocked(sys, T, _road_samples(sys, T, U), X0, substeps)
    return np.vstack([run.x, run.xc, run.held])


def _tickwise_control(sys: ClockedLoop, T, X0, U) -> np.ndarray:
    """The loop's plant states on ``T`` by python-control: ``control.forced_response``
    of the car over each tick interval, its move held, the law updated at each tick
    from the state python-control reached (an evaluation independent of
    `exact_clocked`'s steps)."""
    A, Bw, Bu, *_ = sys.plant_matrices
    n, nc, _ = sys.sizes
    car = control.ss(A, np.hstack([Bw, Bu]), np.eye(n), 0)
    W = _road_samples(sys, T, U)
    road = linear_input(T, W)
    Cm, Dmw = sys.measured
    law, d, dt = sys.law, sys.delay, sys.period
    law.reset()
    x, xc = np.array(X0[:n], float), np.array(X0[n : n + nc], float)
    queue = np.array(X0[n + nc :], float).reshape(d + 1, sys.nu)
    X = np.empty((n, T.size))
    ticks = int(math.floor((T[-1] - T[0]) / dt * (1 + 1e-12))) + 1
    for k in range(ticks):
        t0 = T[0] + k * dt
        y = Cm @ x + Dmw @ road(t0) + sys.measured_move @ queue[0]
        ahead = road.at(np.minimum(t0 + dt * np.arange(law.preview_ticks + 1), T[-1])).T
        u, xc = law.tick(t0, xc, y, ahead)
        queue = np.vstack([queue[1:], np.reshape(u, (1, -1))])
        t1 = min(t0 + dt, T[-1]) if k < ticks - 1 else T[-1]
        inside = (T >= t0 - 1e-9 * dt) & (T < t1 - 1e-9 * dt) | (k == ticks - 1) & (T >= t0)
        times = np.sort(np.concatenate([[t0], T[inside], [t1]]))
        # a sample within rounding of a tick is that tick (no sliver of an interval)
        times = times[np.concatenate([[True], np.diff(times) > 1e-9 * dt])]
        held = np.repeat(queue[0][:, None], times.size, axis=1)
        inputs = np.vstack([road.at(times).T, held])
        r = control.forced_response(car, times - t0, inputs, x) if times.size > 1 else None
        states = x[:, None] if r is None else np.asarray(r.states).reshape(n, -1)
        X[:, inside] = states[:, np.searchsorted(times, T[inside] - 1e-9 * dt)]
        x = states[:, -1]
    return X


def sampled_reference(sys: ClockedLoop, T, X0, U=None, *, substeps: int = 1, outputs=None,
                      repeats: int = 0) -> Reference:  # fmt: skip
    """The exact response of a sampled-data loop, and its accuracy.

    The reference is `qc_control.numerics.clocked.exact_clocked`: the car's
    exact (matrix-exponential) step between the ticks, the move held, the
    law updated at each tick. Its accuracy is the largest difference over
    the output labels in ``outputs`` (all by default) from
    ``control.forced_response`` run tick interval by tick interval.
    ``repeats > 0`` also times the reference (best of ``repeats``).
    """
    T = np.asarray(T, dtype=float)
    x = _exact_sampled(sys, T, X0, U, substeps)
    response = _sampled_response(sys, T, U, x, f"Tick-by-tick exact response of {sys.name}")
    n = sys.sizes[0]
    other = x.copy()
    other[:n] = _tickwise_control(sys, T, X0, U)
    W = _road_samples(sys, T, U)
    labels = list(sys.output_labels)
    rows = [labels.index(label) for label in (labels if outputs is None else outputs)]
    error = float(np.max(np.abs(sys.outputs_of(x, W)[rows] - sys.outputs_of(other, W)[rows])))
    run = functools.partial(_exact_sampled, sys, T, X0, U, substeps)
    elapsed = best_time(run, repeats) if repeats else math.nan
    name = (
        f"the car's exact step (matrix exponential) between clock ticks, the move held, "
        f"the controller updated every {sys.period:g} s (delay {sys.delay} samples)"
    )
    how = (
        "control.forced_response tick interval by tick interval "
        f"(python-control {control.__version__})"
    )
    return Reference(response, error, how, name, elapsed)


def _run_sampled(sys, T, X0, U, tab, substeps):
    """A method's run of the loop, its steps landing on every tick."""
    return input_output_response(sys, T, 0.0 if U is None else U, X0, method=tab, substeps=substeps)


def _sampled_refinement(sys, X0, substeps: int, body: int, timing: bool, tab, level, T, U):
    """A method on a refined grid of a sampled loop, against the exact loop there."""
    exact = sys.outputs_of(_exact_sampled(sys, T, X0, U, substeps), _road_samples(sys, T, U))
    response = _run_sampled(sys, T, X0, U, tab, substeps)
    run = functools.partial(_run_sampled, sys, T, X0, U, tab, substeps)
    seconds = best_time(run, 1) if timing else math.nan
    return Refinement(response, exact[body], seconds)


def _sampled_car(sys: ClockedLoop) -> control.StateSpace:
    """The car inside the loop: between ticks it moves with its own modes."""
    A, Bw, Bu, C, Dw, Du = sys.plant_matrices
    n = sys.sizes[0]
    return control.ss(
        A,
        np.hstack([Bw, Bu]),
        C,
        np.hstack([Dw, Du]),
        states=list(sys.state_labels[:n]),
        name=f"{sys.name} (the car between ticks)",
    )


def measure_sampled(
    problem: ComparisonProblem, repeats: int, timing: bool, progress: Callable[[str], None] | None
) -> Measured:
    """The sampled-data path: the tick-by-tick exact loop, each method at h and refined.

    Modes, step limits and numerical modes are the car's own: the controller
    acts only at the ticks and does not move them between.
    """
    sys, model, T, X0, U = problem.system, problem.model, problem.T, problem.X0, problem.U
    car = _sampled_car(sys)
    metres = [label for label in sys.output_labels if model.unit(label) == "m"]
    if progress:
        progress("reference: the exact loop, tick by tick")
    reference = sampled_reference(
        sys, T, X0, U, substeps=problem.substeps, outputs=metres,
        repeats=repeats if timing else 0,
    )  # fmt: skip
    responses = {
        tab.name: _run_sampled(sys, T, X0, U, tab, problem.substeps) for tab in problem.methods
    }
    eig = np.linalg.eigvals(np.asarray(car.A, dtype=float))
    body = list(sys.output_labels).index(model.body_disp)
    run = functools.partial(_sampled_refinement, sys, X0, problem.substeps, body, timing)
    convergence = convergence_ladder(
        problem.methods, T, U, problem.h, LEVELS, eig, body, run, progress
    )
    return Measured(
        reference,
        responses,
        car,
        modal_analysis(car),
        convergence,
        observed_orders(convergence).to_frame(),
        _sampled_times(problem, convergence, reference),
    )


def _sampled_times(
    problem: ComparisonProblem, convergence: pd.DataFrame, reference
) -> pd.DataFrame:
    """The wall-time columns: each method's run at h against the exact loop's."""
    names = [t.name for t in problem.methods]
    at_h = convergence[convergence[col.LEVEL] == 0].set_index(col.METHOD)[col.TIME].reindex(names)
    return pd.DataFrame(
        {
            col.WALL_TIME: 1e3 * at_h,
            col.LTI_ENGINE: math.nan,
            col.PER_CONTROL: at_h / reference.time,
        },
        index=names,
    )
