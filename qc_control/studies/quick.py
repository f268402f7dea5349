"""The comparison at one step, fast enough to redo on every move of a slider.

`compare_methods` measures everything a report needs, the convergence study
over h/2 ... h/32 and the wall times included: seconds on the seed's
scenario. A page that redraws as a student drags the step needs the part
that depends on h alone, within a fraction of a second:
`quick_comparison` runs the same steps of the comparison (python-control's
exact response, `method_responses`, `error_table`, `mode_errors`) at one
step and keeps the error signals that the report reduces to a number.
`error_ladder` gives each method's error over a fixed ladder of steps,
independent of the current h, so that it is computed once per vehicle and
start and the current step is marked on it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import control
import numpy as np
import pandas as pd

from ..models.modal import ModalAnalysis, modal_analysis
from ..models.vehicle import VehicleModel
from ..numerics.exact import exact_outputs
from ..numerics.integrate import uniform_step
from ..numerics.methods import get_method
from ..numerics.reference import exact_response
from ..numerics.stability import step_verdict
from . import columns as col
from .compare import Reference, error_table, max_error, method_responses, mode_errors
from .compare.measures import padded_outputs

__all__ = ["QuickComparison", "quick_comparison", "error_ladder", "ladder_steps"]

#: The ladder's finest grid holds at most this many samples: the ladder is
#: redone whenever the vehicle or the start changes, and at about a microsecond a
#: sample for the exact response and each method it stays near a tenth of a second.
LADDER_SAMPLES = 20_000


@dataclass(eq=False)
class QuickComparison:
    """The methods at one step against python-control's exact response.

    Made by `quick_comparison`; every curve is on the grid ``T``.

    Attributes
    ----------
    h : float
        The step [s].
    T : ndarray
        The output grid [s].
    reference : control.TimeResponseData
        python-control's exact response on ``T``.
    responses : dict[str, FixedStepResponse]
        Each method's response (cut short where it overflowed).
    outputs : dict[str, ndarray]
        Per method, every output on ``T``, shape ``(outputs, T.size)``; ``inf``
        after a run overflowed (its response stops there).
    errors : dict[str, ndarray]
        Per method, ``|y - y_exact|`` of every output, shape ``(outputs, T.size)``,
        in the outputs' units; ``inf`` after a run overflowed.
    table : pandas.DataFrame
        Per method: ``order``, ``RHS evals``, the `error_table` columns,
        ``h_max [s]``, ``limited by``, ``stable``, each mode's frequency and
        damping error (`mode_errors`) and the ``verdict`` in words
        (`qc_control.numerics.stability.step_verdict`).
    modes : ModalAnalysis
        The exact modes.
    numerical_modes : dict[str, pandas.DataFrame]
        Per method, each mode as the method sees it at h
        (`qc_control.numerics.stability.numerical_modes`).
    scaled_eigenvalues : ndarray
        ``hλ`` of each mode (the eigenvalue with Im >= 0), the points on
        the stability regions.
    """

    h: float
    T: np.ndarray
    reference: control.TimeResponseData
    responses: dict
    outputs: dict
    errors: dict
    table: pd.DataFrame
    modes: ModalAnalysis
    numerical_modes: dict
    scaled_eigenvalues: np.ndarray


def quick_comparison(
    model: VehicleModel, T, X0, U=None, methods: Sequence = ("euler", "midpoint", "heun", "rk4")
) -> QuickComparison:
    """Each method at the grid's step, against python-control's exact response.

    The parts of `qc_control.compare_methods` that depend on the step:
    the reference (``control.initial_response`` or ``forced_response``),
    each method's response, the `error_table`, the step limits and each
    mode's numerical frequency and damping (`mode_errors`). Not measured:
    the convergence study (see `error_ladder`), wall times, the reference's
    own accuracy and ride metrics.

    Parameters
    ----------
    model : VehicleModel
        A linear vehicle (its ``system`` a `control.StateSpace`).
    T : array_like
        Uniform output grid [s]; its spacing is the step.
    X0 : array_like
        Initial state, in the model's state order.
    U : array_like, optional
        Input samples on ``T``; None for the free response.
    methods : sequence of str or ButcherTableau

    Returns
    -------
    QuickComparison
    """
    sys = model.system
    if not isinstance(sys, control.StateSpace):
        raise TypeError(
            f"quick_comparison takes a linear vehicle (a control.StateSpace), got a "
            f"{type(sys).__name__}"
        )
    T = np.asarray(T, dtype=float)
    h = uniform_step(T)
    if h is None:
        raise ValueError("T must be a uniform grid: its spacing is the step")
    X0 = np.asarray(X0, dtype=float)
    tabs = tuple(get_method(m) for m in methods)
    exact = exact_response(sys, T, X0, U)
    reference = Reference(exact, math.nan, "", f"python-control {control.__version__}")
    responses = method_responses(sys, T, X0, U, tabs)
    modes = modal_analysis(model)
    numerical, stability = mode_errors(tabs, h, sys, modes)
    ref = np.asarray(exact.outputs).reshape(sys.noutputs, -1)
    outputs = {name: padded_outputs(r, T.size) for name, r in responses.items()}
    with np.errstate(invalid="ignore", over="ignore"):  # an overflowed run's error is inf
        errors = {name: np.nan_to_num(np.abs(y - ref), nan=np.inf) for name, y in outputs.items()}
    cost = pd.DataFrame(
        {
            col.ORDER: [t.order for t in tabs],
            col.RHS_EVALS: [responses[t.name].nfev for t in tabs],
        },
        index=[t.name for t in tabs],
    )
    table = pd.concat([cost, error_table(responses, reference, model), stability], axis=1)
    table["verdict"] = [step_verdict(h, hm) for hm in table[col.H_MAX]]
    table.index.name = col.METHOD
    return QuickComparison(
        h=h,
        T=T,
        reference=exact,
        responses=responses,
        outputs=outputs,
        errors=errors,
        table=table,
        modes=modes,
        numerical_modes=numerical,
        scaled_eigenvalues=h * np.array([m.eigenvalue for m in modes.modes]),
    )


def ladder_steps(
    t_end: float, h_range: tuple[float, float] = (1e-4, 0.2), points: int = 12
) -> list[int]:
    """Step counts over ``t_end`` for `error_ladder`: about ``points`` steps
    spaced evenly in log h over ``h_range`` [s], each a whole number of steps
    (at least 2), the finest grid within `LADDER_SAMPLES`.

    Examples
    --------
    >>> ladder_steps(10.0, points=4)
    [50, 368, 2714, 19999]
    """
    if not (math.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end must be a finite time > 0 s, got {t_end!r}")
    most = min(t_end / h_range[0], LADDER_SAMPLES - 1)
    least = max(2.0, t_end / h_range[1])
    counts = np.geomspace(least, max(most, least), points)
    return sorted({int(round(n)) for n in counts})


def error_ladder(
    model: VehicleModel,
    t_end: float,
    X0,
    inputs: Callable[[np.ndarray], np.ndarray | None],
    methods: Sequence,
    steps: Sequence[int],
) -> pd.DataFrame:
    """Each method's largest body-displacement error at several steps.

    On each grid ``0, t_end/n, ..., t_end`` (``n`` in ``steps``) the
    reference is the exact response (`qc_control.numerics.exact`: the
    matrix-exponential solution for an input linear between samples, mode
    by mode; it agrees with python-control's to rounding) and every method
    runs on the same samples.

    Parameters
    ----------
    model : VehicleModel
        A linear vehicle.
    t_end : float
        End time [s].
    X0 : array_like
        Initial state.
    inputs : callable
        ``inputs(T)``: the input samples on the grid ``T``, or None.
    methods : sequence of str or ButcherTableau
    steps : sequence of int
        Step counts over ``t_end`` (`ladder_steps`).

    Returns
    -------
    pandas.DataFrame
        Long form: ``method``, ``h`` [s], ``nfev``, ``error`` [m] (inf once a
        run overflowed).
    """
    sys = model.system
    body = list(sys.output_labels).index(model.body_disp)
    A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    tabs = tuple(get_method(m) for m in methods)
    X0 = np.asarray(X0, dtype=float)
    rows = []
    for n in steps:
        T = np.linspace(0.0, t_end, int(n) + 1)
        U = inputs(T)
        samples = np.zeros((sys.ninputs, T.size)) if U is None else np.atleast_2d(U)
        exact = exact_outputs(A, B, C, D, t_end / n, samples, X0)[body]
        for name, response in method_responses(sys, T, X0, U, tabs).items():
            y = np.asarray(response.outputs).reshape(len(response.output_labels), -1)[body]
            error = max_error(y, exact, T.size)  # a run that blew up: inf
            rows.append(
                {col.METHOD: name, col.H: t_end / n, col.NFEV: response.nfev, col.ERROR: error}
            )
    return pd.DataFrame(rows)
