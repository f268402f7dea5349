"""Compare fixed-step methods against python-control's exact response.

`compare_methods` computes every number of the comparison once; the
report writers in `qc_control.report` only format them.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import control
import numpy as np
import pandas as pd
import scipy.signal

from .integrate import DivergenceWarning, check_time_grid, uniform_step
from .methods import ButcherTableau, get_method
from .modal import ModalAnalysis, modal_analysis
from .model import QuarterCarParams, quarter_car
from .response import _initial_state, _input_samples, forced_response, initial_response
from .stability import max_stable_step, numerical_modes

__all__ = [
    "MethodComparison",
    "compare_methods",
    "DEFAULT_METHODS",
    "DEFAULT_X0",
    "DEFAULT_T_END",
    "DEFAULT_H",
    "TOLERANCES",
]

#: The default scenario: the seed's vehicle, body released from 5 cm, 0-10 s, h = 0.01 s.
DEFAULT_METHODS = ("euler", "midpoint", "heun", "rk4")
DEFAULT_X0 = (0.0, 0.0, 0.05, 0.0)
DEFAULT_T_END = 10.0
DEFAULT_H = 0.01
#: Accuracies [m] at which the report names the cheapest method.
TOLERANCES = (1e-3, 1e-6, 1e-9)
#: Refinements h, h/2, ..., h/2**_LEVELS for convergence and work-precision.
_LEVELS = 5
#: Errors below this [m] are rounding, not truncation: left out of order fits.
_ROUNDING_FLOOR = 1e-13


@dataclass(eq=False)
class MethodComparison:
    """The numbers of a method comparison. See `compare_methods`.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per method (index: method name); columns with units.
    modes : ModalAnalysis
        The exact modes (damping per mode).
    numerical_modes : dict[str, pandas.DataFrame]
        Per method, each mode's frequency and damping as the method sees it.
    convergence : pandas.DataFrame
        Long form: method, h, steps, nfev, time, error, for h, h/2, ..., h/32.
    cost : pandas.DataFrame
        RHS evaluations needed to reach each accuracy in `TOLERANCES`
        (index, max |xs error| in m) per method (columns).
    cost_kind : pandas.DataFrame
        For each entry of `cost`: ``'interpolated'`` (log-log, between two
        refinements that bracket it) or ``'extrapolated'`` (``e = C h^p``
        with the method's order p from the nearest refinement, and never
        a step beyond ``h_max``).
    coincident : dict
        ``{(a, b): max |x_a - x_b|}`` [m] over the states, for each pair of
        methods whose trajectories agree to 1e-12 m (e.g. Midpoint and
        Heun on linear systems).
    reference : control.TimeResponseData
        python-control's exact response on the grid.
    reference_error : float
        The reference's own accuracy [m]: its largest difference from an
        independent exact evaluation (see `compare_methods`).
    responses : dict[str, FixedStepResponse]
        Each method's response at the chosen h.
    ride : pandas.DataFrame or None
        Under a road input: `qc_control.ride_metrics` of the reference
        (first row) and of each method.
    ride_error : pandas.DataFrame or None
        Each method's ride metrics against the reference's [%].
    transmissibility : Transmissibility or None
        Under a road input: the road-to-ride frequency responses.
    """

    system: control.StateSpace
    params: QuarterCarParams | None
    T: np.ndarray
    X0: np.ndarray
    U: np.ndarray | None
    h: float
    substeps: int
    methods: tuple[ButcherTableau, ...]
    table: pd.DataFrame
    modes: ModalAnalysis
    numerical_modes: dict
    convergence: pd.DataFrame
    cost: pd.DataFrame
    cost_kind: pd.DataFrame
    coincident: dict
    reference: control.TimeResponseData
    reference_error: float
    reference_time: float
    reference_description: str
    reference_name: str
    responses: dict
    eigenvalues: np.ndarray
    input_description: str = ""
    ride: pd.DataFrame | None = None
    ride_error: pd.DataFrame | None = None
    transmissibility: object | None = None

    def summary(self) -> pd.DataFrame:
        """The headline columns of `table`, for a terminal."""
        cols = [
            "order",
            "RHS evals",
            "wall time [ms]",
            "max |xs err| [m]",
            "max |xu err| [m]",
            "observed order",
            "h_max [s]",
        ]
        return self.table[cols]

    def write(
        self,
        out_dir,
        formats=("md", "html", "csv"),
        *,
        command: str | None = None,
        overwrite: bool = True,
    ):
        """Write the report to ``out_dir``; see `qc_control.report.write_report`."""
        from .report import write_report

        return write_report(self, out_dir, formats=formats, command=command, overwrite=overwrite)


def best_time(fn: Callable[[], object], repeats: int, warmup: bool = False) -> float:
    """Best wall time [s] of ``repeats`` calls of ``fn``: the least disturbed one.

    ``warmup`` makes one untimed call first (caches, fresh memory pages).
    """
    if warmup:
        fn()
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def _grid(T: np.ndarray, h: float | None) -> tuple[float, int]:
    """The step h and the substeps per interval of the uniform grid T."""
    dt = uniform_step(T)
    if dt is None:
        raise ValueError("T must be uniformly spaced for a method comparison")
    if h is None:
        return dt, 1
    if not (isinstance(h, (int, float)) and math.isfinite(h) and h > 0):
        raise ValueError(f"h must be a finite step > 0 s, got {h!r}")
    k = round(dt / h)
    if k < 1 or abs(k * h - dt) > 1e-9 * dt:
        raise ValueError(f"h = {h!r} s must divide the grid spacing {dt!r} s of T")
    return dt / k, int(k)


def _refined(T: np.ndarray, level: int) -> np.ndarray:
    return np.linspace(T[0], T[-1], (T.size - 1) * 2**level + 1)


def _refined_input(T, U, level):
    """U on the refined grid: linear interpolation keeps the same input function."""
    if U is None:
        return None
    Tf = _refined(T, level)
    return np.vstack([np.interp(Tf, T, row) for row in U])


def _simulate(sys, T, X0, U, method, substeps, engine="auto"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DivergenceWarning)
        if U is None:
            return initial_response(sys, T, X0, method=method, substeps=substeps, engine=engine)
        return forced_response(sys, T, U, X0, method=method, substeps=substeps, engine=engine)


def _exact(sys, T, X0, U):
    if U is None:
        return control.initial_response(sys, T, X0)
    return control.forced_response(sys, T, U, X0)


def _reference_accuracy(sys, T, X0, U, reference) -> tuple[float, str]:
    """The reference's error against an independent exact evaluation [m].

    Free response: the modal closed form ``V e^{Λt} V⁻¹ x0`` at every t
    (no recurrence, so no accumulated rounding). Forced response:
    ``scipy.signal.lsim``, an independent implementation of the same
    exact (input linear between samples) solution.
    """
    n = 2  # the displacement outputs xs, xu
    if U is None:
        A = np.asarray(sys.A, dtype=float)
        lam, V = np.linalg.eig(A)
        z0 = np.linalg.solve(V, np.asarray(X0, dtype=complex))
        x = (V @ (z0[:, None] * np.exp(np.outer(lam, T - T[0])))).real
        other = np.asarray(sys.C)[:n] @ x
        how = "the modal closed form V·exp(Λt)·V⁻¹·x0"
    else:
        lti = scipy.signal.StateSpace(
            np.asarray(sys.A), np.asarray(sys.B), np.asarray(sys.C)[:n], np.asarray(sys.D)[:n]
        )
        _, y, _ = scipy.signal.lsim(lti, U.T if U.shape[0] > 1 else U[0], T - T[0], X0=X0)
        other = np.atleast_2d(y.T) if y.ndim > 1 else y[None]
        how = "scipy.signal.lsim"
    return float(np.max(np.abs(reference.outputs[:n] - other))), how


def _observed_order(hs, errors) -> float:
    hs, errors = np.asarray(hs), np.asarray(errors)
    ok = np.isfinite(errors) & (errors > _ROUNDING_FLOOR)
    if ok.sum() < 2:
        return math.nan
    return float(np.polyfit(np.log(hs[ok]), np.log(errors[ok]), 1)[0])


def _cost_to_reach(conv: pd.DataFrame, method: ButcherTableau, span: float, h_max: float) -> dict:
    """RHS evaluations for max |xs error| = tol, for each tolerance.

    Inside the refinements: log-log interpolation between the two levels
    that bracket the tolerance ('interpolated'). Outside: the error model
    ``e = C h^p`` with the method's order p through the nearest level,
    never beyond the stability limit ('extrapolated').
    """
    rows = conv[
        (conv["method"] == method.name)
        & conv["stable"]
        & np.isfinite(conv["error"])
        & (conv["error"] > _ROUNDING_FLOOR)
    ].sort_values("nfev")
    result = {}
    if rows.empty:
        return {tol: (math.nan, "unreached") for tol in TOLERANCES}
    log_n, log_e = np.log(rows["nfev"].to_numpy(float)), np.log(rows["error"].to_numpy())
    fewest = method.stages * math.ceil(span / h_max) if h_max > 0 else math.inf
    for tol in TOLERANCES:
        lt = math.log(tol)
        if log_e[-1] <= lt <= log_e[0] and len(rows) > 1:
            # errors fall as nfev grows: interpolate on the reversed (increasing) arrays
            n = math.exp(np.interp(lt, log_e[::-1], log_n[::-1]))
            kind = "interpolated"
        else:
            i = 0 if lt > log_e[0] else -1
            n = math.exp(log_n[i] + (log_e[i] - lt) / method.order)
            kind = "extrapolated"
        result[tol] = (int(max(math.ceil(n), fewest)), kind)
    return result


def _coincident(responses: dict) -> dict:
    names, pairs = list(responses), {}
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            xa, xb = responses[a].states, responses[b].states
            if xa.shape == xb.shape:
                gap = float(np.max(np.abs(xa - xb)))
                if gap <= 1e-12:
                    pairs[(a, b)] = gap
    return pairs


def _limiting_mode(method, modes: ModalAnalysis) -> str:
    """The mode whose eigenvalue sets the method's step limit."""
    limits = {
        m.name: max_stable_step(method, [m.eigenvalue, m.eigenvalue.conjugate()])
        for m in modes.modes
    }
    return min(limits, key=limits.get)


def compare_methods(
    sys,
    T=None,
    X0=DEFAULT_X0,
    *,
    U=None,
    methods: Sequence = DEFAULT_METHODS,
    h: float | None = None,
    repeats: int = 5,
    progress: Callable[[str], None] | None = None,
    input_description: str = "",
    params: QuarterCarParams | None = None,
) -> MethodComparison:
    """Compare fixed-step methods with python-control's exact response.

    Parameters
    ----------
    sys : control.StateSpace or QuarterCarParams
        A quarter car (states ``[vs, vu, xs, xu]``). Parameters build
        ``quarter_car(params, road=U is not None)``.
    T : array_like, optional
        Uniform output grid [s]; default 0-10 s at 0.01 s.
    X0 : array_like, default ``(0, 0, 0.05, 0)``
        Initial state [m/s, m/s, m, m].
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
    progress : callable, optional
        Called with a short message as each method starts.
    input_description : str, optional
        What the input is (e.g. "ISO 8608 class C road at 20 m/s"), for
        the report.
    params : QuarterCarParams, optional
        The vehicle behind ``sys`` when ``sys`` is a system: the ride
        metrics need its masses for the static wheel load.

    Returns
    -------
    MethodComparison

    Notes
    -----
    The reference is ``control.initial_response`` (or ``forced_response``),
    the exact solution for an input linear between samples, via the matrix
    exponential. Errors are the largest (``max``) and root-mean-square
    (``rms``) differences over ``T``, and the difference at the last time.
    The observed order is the least-squares slope of log max-error against
    log h over h, h/2 and h/4, leaving out errors below 1e-13 m (rounding).
    Each mode's error is ``numerical_modes`` at the chosen h. Under a road
    input (``'zr'``) the comparison also holds `qc_control.ride_metrics`
    of the reference and of each method, and the transmissibility.
    """
    if sys is None or isinstance(sys, (QuarterCarParams, dict)):
        params = sys if isinstance(sys, QuarterCarParams) else QuarterCarParams(**(sys or {}))
        sys = quarter_car(params, road=U is not None)
    if not isinstance(sys, control.StateSpace):
        raise TypeError(
            f"sys must be a control.StateSpace or QuarterCarParams, got {type(sys).__name__}"
        )
    T = check_time_grid(np.linspace(0, DEFAULT_T_END, 1001) if T is None else T, "T")
    h, substeps = _grid(T, h)
    tabs = tuple(get_method(m) for m in methods)
    if not tabs:
        raise ValueError("methods must name at least one method")
    names = [t.name for t in tabs]
    if len(set(names)) != len(names):
        raise ValueError(f"methods must be distinct, got {names}")
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"repeats must be a positive integer, got {repeats!r}")
    X0 = _initial_state(X0, sys.nstates)
    if U is not None:
        U = _input_samples(U, sys.ninputs, T.size)

    modes = modal_analysis(sys)
    eig = np.linalg.eigvals(np.asarray(sys.A, dtype=float))
    reference = _exact(sys, T, X0, U)
    reference_time = best_time(lambda: _exact(sys, T, X0, U), repeats)
    reference_error, how = _reference_accuracy(sys, T, X0, U, reference)
    exact_levels = {
        lvl: _exact(sys, _refined(T, lvl), X0, _refined_input(T, U, lvl)).outputs
        for lvl in range(_LEVELS + 1)
    }

    rows, conv_rows, responses, nm = {}, [], {}, {}
    span = float(T[-1] - T[0])
    for tab in tabs:
        if progress:
            progress(f"{tab.name}: h = {h:g} s and {_LEVELS} refinements")
        h_max = max_stable_step(tab, eig)
        resp = _simulate(sys, T, X0, U, tab, substeps)
        responses[tab.name] = resp
        # The method's cost is its step-by-step time; the LTI engine's is shown beside it
        # (it computes the same trajectory, to rounding, in nearly the same time for all).
        wall = best_time(lambda: _simulate(sys, T, X0, U, tab, substeps, "generic"), repeats)
        wall_lti = best_time(lambda: _simulate(sys, T, X0, U, tab, substeps), repeats)
        n = resp.time.size
        err = resp.outputs - reference.outputs[:, :n]
        if n < T.size:  # diverged: the missing samples count as infinitely wrong
            err = np.concatenate([err, np.full((err.shape[0], T.size - n), np.inf)], axis=1)

        for lvl in range(_LEVELS + 1):
            Tl = _refined(T, lvl)
            r = (
                resp
                if lvl == 0
                else _simulate(sys, Tl, X0, _refined_input(T, U, lvl), tab, substeps)
            )
            t_run = (
                wall
                if lvl == 0
                else best_time(
                    lambda: _simulate(
                        sys, Tl, X0, _refined_input(T, U, lvl), tab, substeps, "generic"
                    ),
                    1,
                )
            )
            e = r.outputs[0] - exact_levels[lvl][0, : r.time.size]
            error = float(np.max(np.abs(e))) if r.time.size == Tl.size else math.inf
            conv_rows.append(
                {
                    "method": tab.name,
                    "level": lvl,
                    "h": h / 2**lvl,
                    "steps": r.steps,
                    "nfev": r.nfev,
                    "time": t_run,
                    "error": error,
                    "stable": h / 2**lvl <= h_max,
                }
            )
        conv = pd.DataFrame(conv_rows)
        mine = conv[(conv["method"] == tab.name) & (conv["level"] <= 2)]
        order = _observed_order(mine["h"], mine["error"]) if mine["stable"].all() else math.nan

        nm[tab.name] = numerical_modes(tab, h, modes)
        row = {
            "order": tab.order,
            "stages": tab.stages,
            "h [s]": h,
            "steps": resp.steps,
            "RHS evals": resp.nfev,
            "wall time [ms]": 1e3 * wall,
            "LTI engine [ms]": 1e3 * wall_lti,
            "time / control": wall / reference_time,
        }
        for i, name, unit in ((0, "xs", "m"), (1, "xu", "m"), (4, "body_acc", "m/s²")):
            row[f"max |{name} err| [{unit}]"] = float(np.max(np.abs(err[i])))
            row[f"rms {name} err [{unit}]"] = float(np.sqrt(np.mean(err[i] ** 2)))
        row["final |xs err| [m]"] = float(abs(err[0, -1]))
        row["observed order"] = order
        row["h_max [s]"] = h_max
        row["limited by"] = _limiting_mode(tab, modes)
        row["stable"] = bool(h <= h_max)
        for mode_name, mrow in nm[tab.name].iterrows():
            row[f"{mode_name} freq err [%]"] = mrow["freq error [%]"]
            row[f"{mode_name} zeta err"] = mrow["zeta error"]
        rows[tab.name] = row

    table = pd.DataFrame.from_dict(rows, orient="index")
    table.index.name = "method"
    convergence = pd.DataFrame(conv_rows)
    ride, ride_error, trans = None, None, None
    if U is not None and "zr" in sys.input_labels and sys.ninputs == 1 and params is not None:
        from .ride import ride_metrics, transmissibility

        ride = pd.DataFrame(
            {
                "reference": ride_metrics(reference, params),
                **{m: ride_metrics(r, params) for m, r in responses.items()},
            }
        ).T
        ride.index.name = "response"
        trans = transmissibility(sys)
        numeric = ride.drop(columns=["lift-off", "lift-off time [s]"]).astype(float)
        ref = numeric.loc["reference"]
        ride_error = 100 * (numeric.drop(index="reference") - ref) / ref.where(ref != 0)
        ride_error.columns = [c.split(" [")[0] + " [% off]" for c in ride_error.columns]
    reach = {
        tab.name: _cost_to_reach(convergence, tab, span, rows[tab.name]["h_max [s]"])
        for tab in tabs
    }
    cost = pd.DataFrame({m: {tol: v[0] for tol, v in r.items()} for m, r in reach.items()})
    cost_kind = pd.DataFrame({m: {tol: v[1] for tol, v in r.items()} for m, r in reach.items()})
    cost.index.name = cost_kind.index.name = "tolerance [m]"
    return MethodComparison(
        system=sys,
        params=params,
        T=T,
        X0=X0,
        U=U,
        h=h,
        substeps=substeps,
        methods=tabs,
        table=table,
        modes=modes,
        numerical_modes=nm,
        convergence=convergence,
        cost=cost,
        cost_kind=cost_kind,
        coincident=_coincident(responses),
        reference=reference,
        reference_error=reference_error,
        reference_time=reference_time,
        reference_description=how,
        responses=responses,
        eigenvalues=eig,
        reference_name=(
            f"control.{'initial' if U is None else 'forced'}_response "
            f"(python-control {control.__version__})"
        ),
        input_description=input_description,
        ride=ride,
        ride_error=ride_error,
        transmissibility=trans,
    )
