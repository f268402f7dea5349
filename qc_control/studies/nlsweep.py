"""Batched nonlinear sweeps: every design stepped at once, loop over steps only.

A nonlinear model (`qc_control.nonlinear_quarter_car_model`) gives its
right-hand side over arrays of designs (``VehicleModel.batch_dynamics``, a
`qc_control.NonlinearQuarterCarBatch`). This module steps it with any
explicit tableau for ``m`` designs together: the Python loop runs over the
steps, NumPy over the designs. One step is the stage loop's
(`qc_control.numerics.stepper.rk_steps`, on the ``(n, m)`` batch)

.. math::

    k_i = f\\big(t + c_i h,\\; x + h \\textstyle\\sum_{j<i} a_{ij} k_j,\\;
          u(t + c_i h)\\big), \\qquad
    x \\leftarrow x + h \\textstyle\\sum_i b_i k_i ,

with ``x`` of shape ``(n, m)``, the same stage times
(`qc_control.numerics.integrate.stage_times`) and the input interpolated linearly
between its samples as python-control interpolates it
(`qc_control.numerics.sampled.linear_input`), so that each design's trajectory is
`qc_control.input_output_response`'s on that design to rounding.

**Compiled steps.** A batch that offers them
(``dynamics.compiled_stepper()``: for `nonlinear_quarter_car`, the same step
compiled with numba: `qc_control.models.nlkernel`'s right-hand side in
`qc_control.numerics.compiled_stepper.stage_loop`) is stepped by them, a block of
samples per call, instead of by NumPy calls: a dozen NumPy calls a stage
cost about a microsecond each whatever the number of designs, which made
the Python loop most of the time. The NumPy path stays for what has no
compiled form (user callables) and to locate events.

The registered metrics are reduced as the samples go by
(`qc_control.ride.metrics.MetricStream`, a block of samples at a time), so no
``(designs, samples, outputs)`` array is formed; a metric that needs the
last sample before it can read the others (the settling time) keeps its one
signal, ``(designs, samples)``.

**Events in a batch.** Without ``events`` the batch steps through the kinks
(contact lost or regained, a stop engaged, a damper knee) as the plain
stepper does: the trajectory is `input_output_response`'s without events,
and near a kink the method loses its order (RK4 falls to about order 1-2 on
a lift-off, see the README's nonlinear section). With ``events=True``, after
each step the designs whose switching functions changed sign inside it
(and only those) take the step again alone with `qc_control.numerics.integrate`'s
event location (root finding on the method's own step, stepping to the
kink exactly): each design's trajectory is then `input_output_response`'s
with ``events=True`` to rounding, at the price of a Python call per event.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np

from ..models.vehicle import SignalRoles, VehicleModel
from ..numerics.integrate import (
    DivergenceWarning,
    check_substeps,
    check_time_grid,
    integrate,
    stage_times,
    uniform_step,
)
from ..numerics.limits import check_memory
from ..numerics.methods import ButcherTableau, get_method
from ..numerics.sampled import linear_input
from ..numerics.stepper import GridSteps, rk_steps
from ..numerics.trajectory_stability import (
    TrajectoryWatch,
    growth_limit,
    jacobians,
    unstable_designs,
)
from ..responses.timeresp import (
    check_initial_state,
    check_input_samples,
    forcing_samples,
    input_output_response,
)
from ..ride.metrics import METRICS, Metric, MetricStream, RideSignals

__all__ = ["simulate_batch", "BatchResponse", "nonlinear_sweep", "beyond_stability", "BLOCK"]

#: Samples per block: the states of a block, ``(n, m, BLOCK)``, are turned into
#: outputs and reduced together (a few MB for a thousand designs).
BLOCK = 64
#: Designs stepped together when no executor splits them: large enough that
#: NumPy's per-call cost is spread over many designs, small enough for the cache.
NL_VECTOR_DESIGNS = 2048


@dataclass(eq=False)
class BatchResponse:
    """What `simulate_batch` returns.

    Attributes
    ----------
    t : ndarray (N,)
    states : ndarray (m, n, N)
    outputs : dict label -> ndarray (m, N)
    success : ndarray of bool (m,)
        Whether each design's state stayed finite (a design that blows up
        becomes NaN from there on; the others are unaffected) and its step
        stayed within the method's stability limit along its trajectory
        (`beyond_stability`).
    t_events : list of ndarray
        Per design, the located event times (empty without ``events``).
    """

    t: np.ndarray
    states: np.ndarray
    outputs: dict
    success: np.ndarray
    t_events: list


def _inputs(dynamics, T: np.ndarray, U) -> np.ndarray:
    """The input samples ``(k, N)`` (`qc_control.responses.timeresp.check_input_samples`:
    python-control's shapes; None is zero)."""
    return check_input_samples(U, len(dynamics.input_labels), T.size)


def _march(dynamics, T, X0, U, tab, substeps, events, t_events, block=BLOCK):
    """Step every design; yield ``(start, states (n, m, L))`` for the samples
    ``start .. start + L - 1`` of ``T`` (sample 0 is ``X0``)."""
    m, n = dynamics.size, len(dynamics.state_labels)
    if tab.implicit:  # the batched and compiled loops evaluate stages one after another
        raise ValueError(
            f"method {tab.name!r} is implicit; batched nonlinear runs step explicit tableaus "
            f"only: step a design with qc.input_output_response(..., method={tab.name!r})"
        )
    dt = uniform_step(T)
    if dt is None:
        raise ValueError("T must be uniformly spaced for a batched nonlinear run")
    ts = stage_times(T, tab, substeps=substeps)  # (steps, s): the stepper's own times
    u_of = linear_input(T, U)
    x = np.array(np.broadcast_to(np.asarray(X0, dtype=float)[:, None], (n, m)))
    # a batch that has compiled steps (`NonlinearQuarterCarBatch.compiled_stepper`)
    # takes them, except to locate events (a Python call per event)
    compiled = None if events else getattr(dynamics, "compiled_stepper", lambda: None)()
    if compiled is not None:
        advance = _compiled_advance(compiled, tab, dt / substeps, substeps, u_of.at(ts))
    else:
        advance = _NumpySteps(dynamics, T, x, tab, substeps, dt, ts, u_of, events, t_events)
    buf = np.empty((n, block, m))  # a sample's states are contiguous rows: cheap to store
    buf[:, 0] = x
    filled, done, total = 1, 0, T.size - 1
    while done < total:
        count = min(block - filled, total - done)
        x = advance(x, buf, filled, count, done)
        filled += count
        done += count
        if filled == block or done == total:
            yield done + 1 - filled, np.swapaxes(buf[:, :filled], 1, 2)
            filled = 0


def _compiled_advance(compiled, tab, h, substeps, stage_u):
    """``advance(x, buf, first, count, done)`` by the batch's compiled steps.

    ``stage_u`` ``(steps, s, k)``: the inputs at every stage time.
    """
    a_h, b_h = np.ascontiguousarray(tab.a * h), np.ascontiguousarray(tab.b * h)
    stage_u = np.ascontiguousarray(stage_u)

    def advance(x, buf, first, count, done):
        compiled(x, buf, first, count, done * substeps, substeps, a_h, b_h, stage_u)
        return x

    return advance


class _NumpySteps:
    """``advance(x, buf, first, count, done)`` by the stage loop on the batch's ``rhs``.

    The samples ``done + 1 .. done + count`` into ``buf[:, first ..]``:
    `qc_control.numerics.stepper`'s loop over the ``(n, m)`` batch, the
    inputs at the stage times precomputed (`stage_times`: the loop's own
    times) and looked up by time. With events, step by step: the designs
    whose switching functions changed sign in a step take it again alone
    (`_locate`).
    """

    def __init__(self, dynamics, T, x0, tab, substeps, dt, ts, u_of, events, t_events):
        self.grid = GridSteps(tab, T.tolist(), substeps, dt)
        self.dynamics, self.tab, self.u_of, self.t_events = dynamics, tab, u_of, t_events
        self.events, self.substeps = events, substeps
        known = dict(zip(ts.reshape(-1).tolist(), u_of.at(ts.reshape(-1))))
        rhs = dynamics.rhs

        def f(t, x):
            u = known.get(t)
            return rhs(t, x, u_of(t) if u is None else u)

        self.f = f
        self.ends = np.append(ts[1:, 0], T[-1]).tolist()  # each step's end
        # the switching functions at the last step's end
        self._g = dynamics.switching(float(T[0]), x0, u_of(float(T[0]))) if events else None

    def __call__(self, x, buf, first, count, done):
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            if not self.events:
                out = np.empty((count + 1,) + x.shape)
                x = self.grid.run(self.f, x, out, done, done + count)
                buf[:, first : first + count] = np.swapaxes(out[1:], 0, 1)
                return x
            for sample in range(done, done + count):
                ts, rows = self.grid.steps(sample, sample + 1)
                for q in range(self.substeps):
                    x = self._event_step(sample * self.substeps + q, ts[q], rows[q], x)
                buf[:, first + sample - done] = x
        return x

    def _event_step(self, step, ta, row, x):
        """One step from ``(ta, x)``; the designs with a sign change inside it located."""
        out = np.empty((2,) + x.shape)
        x_new = rk_steps(self.f, [ta], [row], x, out, self.grid.plan)
        tb = self.ends[step]
        ub = self.u_of(tb)
        sw = self.dynamics.switching
        g_b = sw(tb, x_new, ub)
        s_b = np.sign(g_b)
        hit = np.flatnonzero(np.any((s_b != np.sign(np.asarray(self._g))) & (s_b != 0), axis=0))
        if hit.size:
            _locate(self.dynamics, hit, float(ta), tb, x, x_new, self.tab, self.u_of, self.t_events)
            g_b = sw(tb, x_new, ub)
        self._g = g_b
        return x_new


def _locate(dynamics, hit, ta, tb, x_a, x_b, tab, u_of, t_events):
    """Take the step ``ta -> tb`` again for the designs ``hit`` alone, with
    `qc_control.numerics.integrate`'s event location; write their ends into ``x_b``."""
    for j in hit.tolist():
        one = dynamics.take(np.array([j]))

        def f(t, x, one=one):
            return one.rhs(t, x[:, None], u_of(t))[:, 0]

        def g(t, x, one=one):
            return one.switching(t, x[:, None], u_of(t))[:, 0]

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DivergenceWarning)
            sol = integrate(f, [ta, tb], x_a[:, j], tab, events=g)
        x_b[:, j] = sol.x[:, -1] if sol.success else np.nan
        if t_events is not None and sol.t_events.size:
            t_events[j] = np.concatenate([t_events[j], sol.t_events])


def _time_free(dynamics) -> bool:
    """Whether the batch's right-hand side depends on time only through its
    inputs, so that each design's Jacobian can take its own inputs in one call.

    A batch with compiled steps has no time-dependent law (the compiled step
    takes the inputs at the stage times, never the time).
    """
    return getattr(dynamics, "compiled_stepper", lambda: None)() is not None


def _batch_jacobians(dynamics, T, U, index: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Each design's Jacobian ``(m, n, n)`` at its own sample ``index`` ``(m,)``, state
    ``x`` ``(n, m)``: one set of calls when the batch is `_time_free`, else one per
    distinct sample (the designs there taken alone, ``dynamics.take``)."""
    if _time_free(dynamics) or np.all(index == index[0]):
        return jacobians(dynamics.rhs, float(T[index[0]]), x, U[:, index])
    J = np.empty((x.shape[1],) + (x.shape[0],) * 2)
    for k in np.unique(index).tolist():
        at = np.flatnonzero(index == k)
        J[at] = jacobians(dynamics.take(at).rhs, float(T[k]), x[:, at], U[:, [k] * at.size])
    return J


def beyond_stability(dynamics, T, U, tab, substeps: int, watch: TrajectoryWatch) -> np.ndarray:
    """``(m,)`` bool: the designs whose step exceeds the method's stability limit
    of their Jacobian at the start, at the end or right after any state's
    fastest change (`qc_control.numerics.trajectory_stability`), as
    `qc_control.input_output_response` checks a single run."""
    m = watch.first.shape[1]
    h = float(T[1] - T[0]) / substeps if T.size > 1 else 0.0
    if h == 0.0:
        return np.zeros(m, dtype=bool)
    n = watch.first.shape[0]
    J0 = _batch_jacobians(dynamics, T, U, np.zeros(m, dtype=int), watch.first)
    bad = unstable_designs(tab, h, J0)
    bad |= watch.departure > growth_limit(J0, _forcing_peak(dynamics, T, U, watch.first))
    points = [(np.full(m, T.size - 1), watch.prev)]
    points += [(watch.index[i], watch.states[:, i]) for i in range(n)]
    for index, x in points:
        bad |= unstable_designs(tab, h, _batch_jacobians(dynamics, T, U, index, x))
    if not tab.implicit and _time_free(dynamics):
        for i in range(n):
            bad |= _stages_unstable(dynamics, T, U, tab, substeps, watch, i)
    return bad


def _stages_unstable(dynamics, T, U, tab, substeps: int, watch: TrajectoryWatch, i: int):
    """``(m,)`` bool: each design's interval into state ``i``'s fastest change taken
    again (`integrate` on the batch, each design from its own sample), judged at
    the stage state where the design moves fastest.

    As `qc_control.input_output_response`'s stage check: a stiff branch visited
    only inside an interval has its stages there. A `_time_free` batch only (each
    design's inputs at its own stage times, one set of calls).
    """
    m = watch.first.shape[1]
    dt = float(T[1] - T[0])
    t0 = T[np.maximum(watch.index[i], 1) - 1]  # (m,) each design's interval start
    u_of = linear_input(T, U)
    seen: list = []

    def f(tau, X):
        u = u_of.at(t0 + tau).T  # (k, m)
        dx = np.asarray(dynamics.rhs(float(T[0]), np.ascontiguousarray(X.T), u))
        seen.append((tau, X.T.copy(), np.linalg.norm(dx, axis=0)))
        return dx.T

    with warnings.catch_warnings(), np.errstate(over="ignore", invalid="ignore"):
        warnings.simplefilter("ignore")  # a diverging replay warns again
        integrate(f, [0.0, dt], watch.before[:, i].T, tab, substeps=substeps)
    rates = np.nan_to_num(np.stack([r for _, _, r in seen]), nan=np.inf)  # (S, m)
    pick = np.argmax(rates, axis=0)
    xs = np.stack([x for _, x, _ in seen])[pick, :, np.arange(m)].T  # (n, m)
    taus = np.array([tau for tau, _, _ in seen])[pick]
    J = jacobians(dynamics.rhs, float(T[0]), xs, u_of.at(t0 + taus).T)
    return unstable_designs(tab, dt / substeps, J)


def _forcing_peak(dynamics, T, U, x0: np.ndarray) -> np.ndarray:
    """``sup‖f(t, x0, u(t))‖₂`` per design (`growth_limit`'s forcing).

    A `_time_free` batch's forcing depends on the inputs only: it is bounded
    by ``‖f(x0, u0)‖ + ‖B‖₂ max‖u - u0‖₂`` with ``B = ∂f/∂u`` at the start (by
    differences), one set of calls; otherwise it is evaluated at the samples
    `qc_control.responses.timeresp.forcing_samples` picks, as for a single run.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        if not _time_free(dynamics):
            rows = [
                np.linalg.norm(dynamics.rhs(float(T[k]), x0, U[:, [k] * x0.shape[1]]), axis=0)
                for k in forcing_samples(U).tolist()
            ]
            return np.max(rows, axis=0)
        u0 = np.repeat(U[:, :1], x0.shape[1], axis=1)
        f0 = np.asarray(dynamics.rhs(float(T[0]), x0, u0))
        if U.shape[0] == 0:
            return np.linalg.norm(f0, axis=0)
        B = jacobians(lambda t, uu, _: dynamics.rhs(t, x0, uu), float(T[0]), u0, None)
        gain = np.linalg.norm(B, ord=2, axis=(1, 2))
        return np.linalg.norm(f0, axis=0) + gain * float(
            np.max(np.linalg.norm(U - U[:, :1], axis=0))
        )


def _check(dynamics, T, X0, U, method, substeps):
    tab = get_method(method)
    T = check_time_grid(T, "T")
    substeps = check_substeps(substeps)
    X0 = check_initial_state(X0, len(dynamics.state_labels))
    return tab, T, X0, _inputs(dynamics, T, U), substeps


def simulate_batch(
    dynamics, T, X0, U=None, method="rk4", *, substeps: int = 1, events: bool = False
) -> BatchResponse:
    """Every design's trajectory, stepped together (whole outputs kept).

    Parameters
    ----------
    dynamics : NonlinearQuarterCarBatch (or an object with its interface)
        E.g. ``model.batch_dynamics(designs)``.
    T : array_like (N,)
        Uniform time grid [s].
    X0 : array_like (n,)
        The initial state of every design.
    U : array_like (N,) or (k, N), optional
        Input samples at ``T`` (the road ``zr`` [m]), linear in between;
        None: zero.
    method : str or ButcherTableau, default ``'rk4'``
    substeps : int, default 1
    events : bool, default False
        Locate the kinks of the designs whose switching functions change
        sign inside a step (see the module docstring).

    Returns
    -------
    BatchResponse
        Memory ``m × (n + outputs) × N × 8`` bytes: for many designs use
        `qc_control.sweep`, which reduces the metrics as it goes.
    """
    tab, T, X0, U, substeps = _check(dynamics, T, X0, U, method, substeps)
    m, n = dynamics.size, len(dynamics.state_labels)
    p = len(dynamics.output_labels)
    watch = TrajectoryWatch(np.broadcast_to(X0[:, None], (n, m)))
    check_memory(
        m * (n + p) * T.size * 8.0,
        f"a batch of {m} designs over {T.size} samples",
        "use fewer designs or samples (qc.sweep streams the metrics)",
    )
    states = np.empty((m, n, T.size))
    outputs = {label: np.empty((m, T.size)) for label in dynamics.output_labels}
    t_events: list = [np.empty(0) for _ in range(m)]
    for start, xb in _march(dynamics, T, X0, U, tab, substeps, events, t_events):
        sl = slice(start, start + xb.shape[-1])
        states[:, :, sl] = np.moveaxis(xb, 0, 1)
        watch.update(start, xb)
        with np.errstate(over="ignore", invalid="ignore"):
            for label, y in dynamics.outputs(T[sl], xb, U[:, sl]).items():
                outputs[label][:, sl] = y
    success = np.asarray(np.isfinite(states).all(axis=(1, 2)))
    success &= ~beyond_stability(dynamics, T, U, tab, substeps, watch)
    return BatchResponse(T, states, outputs, success, t_events)


def _run_vectorised(
    factory, params, T, X0, U, tab, substeps, metric_items, roles: SignalRoles, keep, events
):
    """One chunk of designs: ``({'stable': ..., column: ...}, states or None)``.

    Module level, so that an executor can pickle it (``factory`` is the
    model's ``batch_dynamics``, a picklable partial).
    """
    dynamics = factory(params)
    m, n = dynamics.size, len(dynamics.state_labels)
    items = [
        (column, METRICS[metric] if isinstance(metric, str) else metric, corner)
        for column, metric, corner in metric_items
    ]
    args = (roles, T, dynamics.tire_stiffness, dynamics.static_load)
    registered = all(isinstance(metric, Metric) for _, metric, _ in items)
    streamed = registered and not keep and MetricStream.supports(items, roles)
    if streamed:
        streamed = not MetricStream(items, *args).weighted  # the Wk filter: whole signals
    if streamed:
        # a metric reading the last sample during the stream (the settling time)
        # is reduced afterwards, from its one kept signal
        late = [
            it
            for it in items
            if any(kind == "settle" for kind, _ in MetricStream([it], *args).needs)
        ]
        now = [it for it in items if it not in late]
        stream = MetricStream(now, *args) if now else None
        kept_labels = MetricStream(late, *args).labels if late else ()
    else:
        late, stream = [], None
        kept_labels = tuple(dynamics.output_labels)
    check_memory(
        (len(kept_labels) + n * keep) * m * T.size * 8.0 + 8.0 * n * m * BLOCK * 4,
        f"a nonlinear sweep chunk of {m} designs over {T.size} samples",
        "use fewer samples, a smaller chunk_size or states=False",
    )
    kept = {label: np.empty((m, T.size)) for label in kept_labels}
    x_all = np.empty((m, n, T.size)) if keep else None
    final: dict = {}  # filled with the last samples once known; read only by result()
    if stream is not None:
        stream.start(final)
    ys: dict = {}
    watch = TrajectoryWatch(np.broadcast_to(np.asarray(X0, dtype=float)[:, None], (n, m)))
    for start, xb in _march(dynamics, T, X0, U, tab, substeps, events, None):
        watch.update(start, xb)
        L = xb.shape[-1]
        sl = slice(start, start + L)
        if x_all is not None:
            x_all[:, :, sl] = np.moveaxis(xb, 0, 1)
        with np.errstate(over="ignore", invalid="ignore"):
            ys = dynamics.outputs(T[sl], xb, U[:, sl])
            if stream is not None:
                stream.update(np.arange(start, start + L), {lb: ys[lb] for lb in stream.labels})
        for label in kept_labels:
            kept[label][:, sl] = ys[label]
    final.update({label: np.array(y[:, -1]) for label, y in ys.items()})
    # a state that was ever non-finite stays so (x + h Σ b_i k_i keeps an inf or a nan)
    finite = np.asarray(np.isfinite(xb[..., -1]).all(axis=0))
    result: dict = {"stable": finite & ~beyond_stability(dynamics, T, U, tab, substeps, watch)}
    with np.errstate(over="ignore", invalid="ignore"):
        if streamed:
            if stream is not None:
                result.update(stream.result())
            if late:  # on the kept signals, whole (the registry's formula), by slices
                for column, metric, corner in late:  # of designs (cache-sized temporaries)
                    result[column] = np.concatenate(
                        [
                            np.asarray(metric.formula(_rows(T, kept, roles, args, sl), corner))
                            for sl in _slices(m)
                        ]
                    )
        else:
            signals = RideSignals(T, kept, roles, *args[2:])
            for column, metric, corner in items:
                if isinstance(metric, Metric):
                    result[column] = np.asarray(metric.formula(signals, corner))
                else:
                    result[column] = np.asarray(metric(signals), dtype=float)
    return result, x_all


def _slices(m: int, size: int = 128) -> list[slice]:
    return [slice(s, s + size) for s in range(0, m, size)]


def _rows(T, kept, roles, args, sl) -> RideSignals:
    """The kept signals of the designs ``sl``, as a `RideSignals`."""
    return RideSignals(
        T,
        {label: y[sl] for label, y in kept.items()},
        roles,
        tuple(k[sl] for k in args[2]),
        tuple(w[sl] for w in args[3]),
    )


def _run_responses(model, params, T, X0, U, tab, substeps, metric_items, keep, events):
    """The fallback: one `qc_control.input_output_response` per design."""
    rows: list[dict] = []
    states = []
    for p in params:
        one = model.rebuild(p)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DivergenceWarning)
            r = input_output_response(
                one.system,
                T,
                0.0 if U is None else U,
                X0,
                method=tab,
                substeps=substeps,
                events=True if events else None,
            )
        y = np.full((len(r.output_labels), T.size), np.nan)
        y[:, : r.time.size] = np.asarray(r.outputs).reshape(len(r.output_labels), -1)
        signals = RideSignals(
            T,
            {label: y[i][None] for i, label in enumerate(r.output_labels)},
            one.roles,
            tuple(np.array([c.tire_stiffness]) for c in one.corners),
            tuple(np.array([c.static_load]) for c in one.corners),
        )
        row = {"stable": np.array([bool(r.success)])}
        with np.errstate(over="ignore", invalid="ignore"):
            for column, metric, corner in metric_items:
                if isinstance(metric, str):
                    row[column] = np.asarray(METRICS[metric].formula(signals, corner))
                else:
                    row[column] = np.asarray(metric(signals), dtype=float)
        rows.append(row)
        if keep:
            x = np.full((len(r.state_labels), T.size), np.nan)
            x[:, : r.time.size] = np.asarray(r.states).reshape(len(r.state_labels), -1)
            states.append(x)
    result = {key: np.concatenate([np.ravel(r[key]) for r in rows]) for key in rows[0]}
    return result, (np.stack(states) if keep else None)


def nonlinear_sweep(
    model: VehicleModel,
    params: Sequence,
    T: np.ndarray,
    X0: np.ndarray,
    U,
    tab: ButcherTableau,
    substeps: int,
    metric_items,
    keep_states: bool,
    *,
    events: bool = False,
    executor=None,
    chunk_size: int = 64,
):
    """`qc_control.sweep`'s path for a nonlinear model (its arguments already checked).

    ``params`` holds one validated parameter object per design, or None for
    a rejected one. With ``model.batch_dynamics`` the designs are stepped
    together (`NL_VECTOR_DESIGNS` at a time, or ``chunk_size`` per task of
    an ``executor``); without it (e.g. `qc_control.closed_loop` with a
    clipped semi-active controller, or a callable force law that does not
    vectorise) each design runs through `qc_control.input_output_response`
    in this process: correct, the same numbers, but about as slow as that
    many single responses.

    Returns
    -------
    (stable, table, states)
        ``stable (designs,)``: the state stayed finite and the step within
        the method's stability limit along the trajectory
        (`beyond_stability`); ``table``: column ->
        ``(designs,)`` (NaN for rejected designs); ``states`` ``(designs, n,
        N)`` or None.
    """
    good = [i for i, p in enumerate(params) if p is not None]
    chosen = [params[i] for i in good]
    n = model.system.nstates
    columns = [column for column, _, _ in metric_items]
    stable = np.zeros(len(params), dtype=bool)
    table = {column: np.full(len(params), np.nan) for column in columns}
    kept = np.full((len(params), n, T.size), np.nan) if keep_states else None
    if not good:
        return stable, table, kept
    factory = model.batch_dynamics
    size = chunk_size if executor is not None else NL_VECTOR_DESIGNS
    parts = [(good[s : s + size], chosen[s : s + size]) for s in range(0, len(good), size)]
    if factory is None:
        results = (
            _run_responses(model, ps, T, X0, U, tab, substeps, metric_items, keep_states, events)
            for _, ps in parts
        )
    else:
        U = _inputs(factory(chosen[:1]), T, U)
        args = (T, X0, U, tab, substeps, metric_items, model.roles, keep_states, events)
        if executor is None:
            results = (_run_vectorised(factory, ps, *args) for _, ps in parts)
        elif isinstance(executor, Executor) or hasattr(executor, "submit"):
            futures = [executor.submit(_run_vectorised, factory, ps, *args) for _, ps in parts]
            results = (f.result() for f in futures)
        else:
            raise TypeError(
                f"executor must be a concurrent.futures.Executor, got {type(executor).__name__}"
            )
    for (idx, _), (result, x) in zip(parts, results):
        stable[idx] = result["stable"]
        for column in columns:
            table[column][idx] = result[column]
        if kept is not None:
            kept[idx] = x
    return stable, table, kept
