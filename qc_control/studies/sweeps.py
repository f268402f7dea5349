"""Design sweeps: thousands of vehicle designs, vectorised, chunked, on any executor."""

from __future__ import annotations

import functools
import itertools
import math
import sys
import warnings
from collections.abc import Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from ..models.quarter import SEED_X0, quarter_car_model
from ..models.registry import model_for_params
from ..models.vehicle import BatchedModel, SignalRoles, VehicleModel
from ..numerics.checks import ParameterError, integer
from ..numerics.integrate import check_substeps, check_time_grid, uniform_step
from ..numerics.limits import check_memory
from ..numerics.lti import OutputStream, TailBound, affine_scan, step_matrices
from ..numerics.methods import ButcherTableau, get_method
from ..numerics.stability import step_is_stable
from ..numerics.threads import one_blas_thread
from ..responses.timeresp import check_initial_state, check_input_samples
from ..ride.iso2631 import wk_discrete
from ..ride.metrics import (
    METRICS,
    SWEEP_METRICS,
    WEIGHTED_ACC,
    MetricStream,
    RideSignals,
    metric_columns,
)
from ..ride.road import NoRoad, Road, as_road
from ..ride.spectral import SPECTRAL_METRICS, ISO8608Road, require_linear, spectral_metrics
from .nlsweep import nonlinear_sweep
from .on_road import road_inputs

__all__ = [
    "sweep",
    "SweepResult",
    "SweepChunk",
    "METRICS",
    "DEFAULT_METRICS",
    "design_grid",
    "DASK_WORKER_ENV",
]

#: Environment for Dask workers that run sweeps (glibc's allocator). Dask's
#: nanny sets ``MALLOC_TRIM_THRESHOLD_=65536``, which also fixes the size above
#: which blocks are mapped afresh at 128 kB: every chunk's megabyte-sized
#: arrays then come back as new pages, and their page faults doubled a road
#: sweep's CPU time (benchmarks/RESULTS.md). These keep blocks below 32 MB in
#: the heap and return memory to the system past 128 MB free. Give them to a
#: `LocalCluster` with ``dask.config.set({"distributed.nanny.pre-spawn-environ":
#: {**default, **DASK_WORKER_ENV}})``, or to any worker's environment.
DASK_WORKER_ENV = {"MALLOC_TRIM_THRESHOLD_": 2**27, "MALLOC_MMAP_THRESHOLD_": 2**25}

#: The columns a sweep of the quarter car computes unless told otherwise
#: (`qc_control.ride.metrics.SWEEP_METRICS`).
DEFAULT_METRICS = tuple(METRICS[name].column() for name in SWEEP_METRICS)
#: What a custom metric ``f(chunk) -> (m,)`` receives: `qc_control.ride.metrics.RideSignals`.
SweepChunk = RideSignals


@dataclass(eq=False)
class SweepResult:
    """What `sweep` returns.

    Attributes
    ----------
    metrics : pandas.DataFrame
        One row per design, in input order: the six parameters, ``stable``
        (the method's step map does not amplify at this h), each metric,
        and ``error`` (empty, or why the design was rejected).
    errors : pandas.DataFrame
        The rejected designs: ``index``, ``value`` and ``error``.
    states : ndarray or None
        ``(designs, 4, len(T))`` when asked for (NaN for rejected designs).
    road : qc_control.road.Road or None
        The road the designs drove (``road=``); for a spectral sweep an
        `ISO8608Road`, and then ``T`` and ``method`` are None and ``stable``
        says the design's ``A`` is Hurwitz.
    """

    T: np.ndarray | None
    method: ButcherTableau | None
    metrics: pd.DataFrame
    errors: pd.DataFrame
    states: np.ndarray | None = None
    road: Road | None = None


#: Bytes a sweep holds per design besides its chunks: the design's dict, its
#: parameters, matrices and eigen-decomposition, and its row of the tables.
#: Measured with tracemalloc on a grid of 32,000 designs (peak over the run):
#: 2.5 kB for `design_grid` alone, 2.4 kB for a free sweep, 1.3 kB for one on
#: a road, 1.6 kB for a spectral sweep; the largest is used for all of them.
DESIGN_BYTES = 2560


def _grid_axes(grid: Mapping[str, Sequence], base) -> tuple[list[str], list, int]:
    """``(keys, values per key, number of designs)`` of a grid, without expanding it.

    The count is the product of the axes' lengths (a Python int: no overflow),
    so that a grid too large to build is refused before one design exists.
    """
    if not grid:
        raise ValueError("the design grid is empty: give at least one {'field': [values]}")
    names = list(base.to_dict())
    unknown = sorted(set(grid) - set(names))
    if unknown:
        raise ValueError(f"unknown parameter {unknown[0]!r} in the grid; expected some of {names}")
    keys = list(grid)
    # an axis is read once (a generator could not be read twice), not copied if it has a length
    axes = [
        v if hasattr(v, "__len__") and hasattr(v, "__getitem__") else list(v) for v in grid.values()
    ]
    empty = [k for k, v in zip(keys, axes) if len(v) == 0]
    if empty:
        raise ValueError(f"the grid gives no values for {empty[0]!r}")
    return keys, axes, math.prod(len(v) for v in axes)


def _grid_shape(keys: list[str], axes: list) -> str:
    """``'1000 ks × 1000 cs'``: the axes, for a refusal's message."""
    return " × ".join(f"{len(v)} {k}" for k, v in zip(keys, axes))


def design_grid(grid: Mapping[str, Sequence], base=None) -> list[dict]:
    """The cartesian product of a ``{'field': [values]}`` grid, as dicts.

    Fields not in the grid come from ``base`` (the seed's quarter car by
    default; any parameter dataclass with ``to_dict(changing=...)``). An
    empty grid, an empty list of values or a key that is not a parameter
    raises ``ValueError`` naming it. The designs are counted (the product of
    the axes' lengths) before any is built: a grid whose dicts would not fit
    in memory (`DESIGN_BYTES` each) raises
    `qc_control.numerics.limits.ResourceLimitError` with the count.
    """
    base = quarter_car_model().params if base is None else base
    keys, axes, count = _grid_axes(grid, base)
    check_memory(
        count * DESIGN_BYTES,
        f"a design grid of {count} designs ({_grid_shape(keys, axes)})",
        "use fewer values per parameter, or split the grid into parts",
    )
    base_values = base.to_dict(changing=grid)
    return [
        {**base_values, **dict(zip(keys, combo))}
        for combo in itertools.product(*(list(v) for v in axes))
    ]


def _validate(designs, params_type) -> tuple[list, list]:
    """(params or None per design, [(index, value, message)])."""
    out: list = []
    errors: list = []
    # the whole list checked at once where the type can (QuarterCarParams.from_mappings);
    # the rest, one by one: their errors come from the constructor itself
    many = getattr(params_type, "from_mappings", None)
    checked = many(designs) if many is not None else [None] * len(designs)
    for i, (d, p) in enumerate(zip(designs, checked)):
        try:
            if p is not None:
                out.append(p)
            elif isinstance(d, params_type):
                out.append(d)
            elif isinstance(d, Mapping):
                out.append(params_type.from_mapping(d))
            else:
                raise TypeError(
                    f"a design must be {params_type.__name__} or a dict, got {type(d).__name__}"
                )
        except (TypeError, ValueError) as exc:
            out.append(None)
            errors.append((i, d if isinstance(d, Mapping) else repr(d), str(exc)))
    return out, errors


def _take(batch: BatchedModel, idx) -> BatchedModel:
    return BatchedModel(
        batch.A[idx],
        batch.B[idx],
        batch.C[idx],
        batch.D[idx],
        tuple(k[idx] for k in batch.tire_stiffness),
        tuple(w[idx] for w in batch.static_load),
        None if batch.wheelbase is None else batch.wheelbase[idx],
    )


#: Designs vectorised together inside a chunk: a chunk sent to an executor may
#: be much larger (fewer, bigger tasks), and is computed this many at a time.
VECTOR_DESIGNS = 64
#: Designs vectorised together in a free sweep of registered metrics (the
#: default sweep): its chunks are mostly set-up (power tables, carries, the
#: settling search), whose per-call costs twice as many designs share; its
#: outputs are streamed a fixed number of samples at a time whatever this is.
FREE_VECTOR_DESIGNS = 128


def _vector_designs(U, metric_items, keep_states: bool) -> int:
    """Designs computed together: `FREE_VECTOR_DESIGNS` for a streamed free
    sweep, else `VECTOR_DESIGNS`."""
    streamed = not keep_states and all(isinstance(m, str) for _, m, _ in metric_items)
    return FREE_VECTOR_DESIGNS if U is None and streamed else VECTOR_DESIGNS


@functools.cache
def _keep_heap() -> None:
    """Once per process: let glibc's allocator keep a chunk's freed arrays.

    Each chunk allocates and frees a few MB of arrays (carries, power tables,
    segments). With glibc's default, adaptive thresholds (about 1 MB and 2 MB
    once such arrays have been freed), the free top of the heap is handed
    back to the system after every chunk, and the next chunk touches fresh
    pages again: their page faults were a third of a free sweep's time. A
    16 MB array, mapped and freed once, raises the thresholds the way glibc
    documents (mallopt(3), M_MMAP_THRESHOLD: the threshold follows the
    largest freed mapped block, up to 32 MB, and the trim threshold is twice
    that), as any program that once used such an array would: up to 32 MB
    of freed memory then stay with the process. A no-op where the thresholds
    were set (`DASK_WORKER_ENV`) or under another allocator.
    """
    np.empty(2**21)  # not written to: no page is touched


@dataclass(frozen=True, eq=False)
class _ChunkTask:
    """What every chunk of a linear sweep shares; picklable, for executors.

    ``metric_items`` are ``(column, name or callable, corner)``: registered
    metrics travel by name (their formulas live in this module's imports).
    """

    labels: tuple[str, ...]
    roles: SignalRoles
    T: np.ndarray
    X0: np.ndarray
    U: np.ndarray | None
    method: ButcherTableau
    substeps: int
    metric_items: list
    keep_states: bool

    @property
    def h(self) -> float:
        """The grid's step [s]: ``T`` is uniform (`_sweep_signals`), so its span over
        its intervals, as `qc_control.numerics.integrate.uniform_step` computes it."""
        return (self.T[-1] - self.T[0]) / (self.T.size - 1)


class _ChunkResult(NamedTuple):
    """One chunk's designs: ``stable (m,)``, column -> ``(m,)``, states or None."""

    stable: np.ndarray
    metrics: dict
    states: np.ndarray | None


def _run_chunk(batch: BatchedModel, task: _ChunkTask, *, eig=None) -> _ChunkResult:
    """Simulate one chunk of designs; module level so that executors can pickle it.

    The chunk is computed `VECTOR_DESIGNS` designs at a time (the size at
    which a segment of streamed outputs stays in cache; `FREE_VECTOR_DESIGNS`
    for a streamed free sweep), whatever its size. ``eig``: the designs'
    ``np.linalg.eig(A)``, when the caller has it.
    """
    _keep_heap()
    m = batch.A.shape[0]
    vector = _vector_designs(task.U, task.metric_items, task.keep_states)
    if m <= vector:
        return _run_designs(batch, task, eig=eig)
    parts = [
        _run_designs(
            _take(batch, slice(s, s + vector)),
            task,
            eig=None if eig is None else tuple(e[s : s + vector] for e in eig),
        )
        for s in range(0, m, vector)
    ]
    return _ChunkResult(
        np.concatenate([p.stable for p in parts]),
        {column: np.concatenate([p.metrics[column] for p in parts]) for column in parts[0].metrics},
        None if parts[0].states is None else np.concatenate([p.states for p in parts]),
    )


def _run_designs(batch: BatchedModel, task: _ChunkTask, *, eig=None) -> _ChunkResult:
    """Simulate up to `VECTOR_DESIGNS` designs together.

    Registered metrics without states are streamed (`_stream_chunk`); custom
    metrics and ``states=True`` get whole trajectories. ``eig`` is
    ``np.linalg.eig(A)`` if the caller has it (else computed here).
    """
    metric_items, labels, roles = task.metric_items, task.labels, task.roles
    if not task.keep_states and all(isinstance(metric, str) for _, metric, _ in metric_items):
        items = [(column, METRICS[name], corner) for column, name, corner in metric_items]
        if MetricStream.supports(items, roles):
            return _stream_chunk(batch, task, items, eig=eig)
    # only the outputs the metrics read (a custom metric may read any)
    wanted = _outputs_read(metric_items, roles, labels)
    rows = [labels.index(label) for label in wanted]
    y, x = _trajectories(batch, task, rows)
    T, method, substeps = task.T, task.method, task.substeps
    H = task.h
    with np.errstate(over="ignore", invalid="ignore"):
        lam = np.linalg.eigvals(batch.A) if eig is None else eig[0]
        stable = step_is_stable(method, H / substeps, lam)
        signals = RideSignals(
            T,
            {label: y[:, i] for i, label in enumerate(wanted)},
            roles,
            batch.tire_stiffness,
            batch.static_load,
        )
        metrics = {}
        for column, metric, corner in metric_items:
            if isinstance(metric, str):
                metrics[column] = np.asarray(METRICS[metric].formula(signals, corner))
            else:
                metrics[column] = np.asarray(metric(signals), dtype=float)
    return _ChunkResult(stable, metrics, x)


def _trajectories(batch: BatchedModel, task: _ChunkTask, rows: list[int]):
    """``(y, x)``: the outputs ``rows`` of every design over ``T``, time last, and
    the states when kept (else None), by one blocked scan of the step maps."""
    A, B, C, D = batch.A, batch.B, batch.C[:, rows], batch.D[:, rows]
    T, U, X0 = task.T, task.U, task.X0
    m, n = A.shape[0], A.shape[-1]
    H = task.h
    phi, g0, g1 = step_matrices(task.method, A, B, H, task.substeps)
    W = None
    if U is not None:
        if U.shape[0] == 1:  # one input: a broadcast product beats a matmul of inner size 1
            W = U[0, None, :-1, None] * g0[:, None, :, 0] + U[0, None, 1:, None] * g1[:, None, :, 0]
        else:
            W = U[:, :-1].T @ np.swapaxes(g0, -1, -2) + U[:, 1:].T @ np.swapaxes(g1, -1, -2)
    if task.keep_states:  # observe the states too: [I; C]
        C = np.concatenate([np.broadcast_to(np.eye(n), (m, n, n)), C], axis=1)
    with np.errstate(over="ignore", invalid="ignore"):
        # time last, so that every metric reduces contiguous memory
        y = affine_scan(
            phi,
            np.broadcast_to(X0, (m, n)),
            W,
            T.size,
            block=16 if W is not None else 32,
            C=C,
            time_last=True,
        )
        x = y[:, :n] if task.keep_states else None
        y = y[:, n:] if task.keep_states else y
        if U is not None:  # the feedthrough D u, on the outputs that have one
            through = np.flatnonzero(np.any(D != 0, axis=(0, 2)))
            if through.size:
                y[:, through] += D[:, through] @ U
    return y, x


class _Scan(NamedTuple):
    """The step map and observation a chunk's outputs are streamed from."""

    phi: np.ndarray  # (m, n, n)
    x0: np.ndarray  # (m, n)
    C: np.ndarray  # (m, p, n)
    D: np.ndarray  # (m, p, k)
    g0: np.ndarray  # (m, n, k)
    g1: np.ndarray  # (m, n, k)


def _stream_chunk(batch: BatchedModel, task: _ChunkTask, items, eig=None) -> _ChunkResult:
    """One chunk's registered metrics, streamed (`qc_control.numerics.lti.OutputStream`
    into `qc_control.ride.metrics.MetricStream`): no ``(designs, outputs, samples)``
    array, only a segment of it at a time.

    With ``eig = np.linalg.eig(A)`` (the sweep has it, for its ordering), its
    eigenvalues give ``stable`` and its eigenvectors, which the step map
    ``R(hA)`` shares, the `TailBound`: no decomposition per chunk.
    """
    T, U, labels = task.T, task.U, task.labels
    m, n = batch.A.shape[0], batch.A.shape[-1]
    stream = MetricStream(items, task.roles, T, batch.tire_stiffness, batch.static_load)
    read = list(stream.labels)
    rows = [labels.index(label) for label in read]
    H = task.h
    phi, g0, g1 = step_matrices(task.method, batch.A, batch.B, H, task.substeps)
    scan = _Scan(phi, np.broadcast_to(task.X0, (m, n)), batch.C[:, rows], batch.D[:, rows], g0, g1)
    if stream.weighted:
        scan = _with_wk_filter(scan, batch, labels.index(task.roles.body_acc), task, H)
        read.append(WEIGHTED_ACC)
    with np.errstate(over="ignore", invalid="ignore"):
        out, sums = _output_stream(scan, U, stream, read)
        final = {label: out.final[:, i] for i, label in enumerate(read)}
        stream.start(final, sums)
        rows = [
            i
            for i, label in enumerate(read)
            if stream.kinds(label) - ({"sumsq"} if sums and label in sums else set())
        ]
        if len(rows) < len(read):
            out.keep_rows(rows)
        streamed = [read[i] for i in rows]
        tail = None
        if U is None and streamed:
            # the free response decays: once no later sample can move a peak, a
            # lift-off count or the settling time (TailBound, the modal bound on
            # every later output), the rest of the samples are not needed
            # the car's eigenvectors fit Φ = R(hA) (not the Wk filter's extended Φ)
            vectors = None if eig is None or stream.weighted else eig[1]
            tail = TailBound(scan.phi, scan.C[:, rows], vectors=vectors)
        if _stream_outputs(out, stream, streamed, tail):
            _settle_after_cut(out, stream, streamed, tail, T.size)
        stream.update(np.array([T.size - 1]), {k: v[:, None] for k, v in final.items()})
        lam = np.linalg.eigvals(batch.A) if eig is None else eig[0]
        stable = step_is_stable(task.method, H / task.substeps, lam)
        return _ChunkResult(stable, dict(stream.result()), None)


def _with_wk_filter(scan: _Scan, batch: BatchedModel, acc: int, task: _ChunkTask, H) -> _Scan:
    """The scan with the Wk filter's state carried beside the car's.

    The filter (exact for an input linear between samples,
    `qc_control.ride.iso2631.wk_discrete`) runs inside the scan: its state
    ``x̃`` joins the car's, so it is carried from block to block,

    .. math:: \\begin{bmatrix} x \\\\ \\tilde x \\end{bmatrix}_{k+1} =
              \\begin{bmatrix} Φ & 0 \\\\ \\tilde B C_a & A_d \\end{bmatrix}
              \\begin{bmatrix} x \\\\ \\tilde x \\end{bmatrix}_k + \\dots, \\quad
              a_w = C_w \\tilde x + \\tilde D a, \\quad \\tilde x_0 = -B_1 a_0,

    the same recursion `qc_control.ride.iso2631.wk_weighted` evaluates by FFT;
    its output ``a_w`` is the last row of the observation.
    """
    m, n = scan.x0.shape
    Ca, Da = batch.C[:, acc], batch.D[:, acc]  # (m, n), (m, k)
    Ad, Bt, Cw, Dt, B1 = wk_discrete(round(float(H), 15))
    nw = Ad.shape[0]
    big = np.zeros((m, n + nw, n + nw))
    big[:, :n, :n] = scan.phi
    big[:, n:, :n] = Bt[:, None] * Ca[:, None, :]
    big[:, n:, n:] = Ad
    a0 = Ca @ task.X0 + (Da @ task.U[:, 0] if task.U is not None else 0.0)
    x0 = np.concatenate([scan.x0, -a0[:, None] * B1], axis=1)
    weighted = np.concatenate([Dt * Ca, np.broadcast_to(Cw[0], (m, nw))], axis=1)
    C = np.concatenate([np.pad(scan.C, ((0, 0), (0, 0), (0, nw))), weighted[:, None]], axis=1)
    D = np.concatenate([scan.D, Dt * Da[:, None]], axis=1)
    g0 = np.concatenate([scan.g0, Bt[:, None] * Da[:, None, :]], axis=1)
    g1 = np.pad(scan.g1, ((0, 0), (0, nw), (0, 0)))
    return _Scan(big, x0, C, D, g0, g1)


def _output_stream(scan: _Scan, U, stream: MetricStream, read: list[str]):
    """``(out, sums)``: the `OutputStream` of the scan, and for a free response the
    sums of squares its block Gram form gives without samples (else None)."""
    if U is not None:
        out = OutputStream(scan.phi, scan.x0, stream.T.size, scan.C, D=scan.D, g0=scan.g0,
                           g1=scan.g1, U=U, block=16)  # fmt: skip
        return out, None
    # longer blocks: no input Toeplitz to pay for, fewer scan rounds
    out = OutputStream(scan.phi, scan.x0, stream.T.size, scan.C, block=64)
    # every sum of squares of the free response is the block Gram form
    # (OutputStream.sum_squares): no samples needed for it
    gram = [i for i, label in enumerate(read) if "sumsq" in stream.kinds(label)]
    if not gram:
        return out, None
    total = out.sum_squares()
    first = np.einsum("mra,ma->mr", scan.C, scan.x0)  # y_0 = C x0
    return out, {read[i]: (total[:, i], first[:, i]) for i in gram}


def _stream_outputs(out: OutputStream, stream: MetricStream, streamed, tail) -> bool:
    """Feed the output segments to the metrics; True when `TailBound` proved that no
    later sample can change them and the stream was cut short."""
    for index, y in out:
        stream.update(index, {label: y[:, i] for i, label in enumerate(streamed)})
        if tail is not None and out.carry is not None:
            bound = tail(out.carry)
            done = stream.settled(
                {label: bound[:, i] for i, label in enumerate(streamed)}, band=False
            )
            if done.all():
                return True
    return False


def _settle_after_cut(out: OutputStream, stream: MetricStream, streamed, tail, N: int) -> None:
    """After a cut, each settling time's last excursion, searched backwards (`_last_outside`)."""
    settling = [i for i, label in enumerate(streamed) if "settle" in stream.kinds(label)]
    if not settling:
        return
    carries = out.block_carries()
    for i in settling:
        end, M = stream.settling_state(streamed[i])
        last = _last_outside(out, tail, carries, i, end, 0.02 * M, N)
        stream.set_last_outside(streamed[i], last)


def _last_outside(out: OutputStream, tail: TailBound, carries, row, final, band, N, width=8):
    """Per design, the last sample ``k < N - 1`` with ``|y_k - final| > band``
    (-1 if none) of a free response's streamed output ``row``, searched
    backwards: from the first block after which `TailBound` proves every
    sample inside the band, ``width`` blocks at a time towards the start.
    The same samples, from the same block carries and products, as the
    forward stream (`qc_control.ride.metrics.MetricStream` finds the same index
    going forwards; the test suite checks both against whole trajectories).
    """
    m, L = carries.shape[0], out.L
    nb = carries.shape[-1] - 1
    bound = tail(carries, rows=slice(row, row + 1))[:, 0]  # only the output searched
    reach = (bound + np.abs(final)[:, None]) * (1 + 1e-12)  # (m, blocks)
    quiet = reach <= band[:, None]  # nothing outside from this block's start on
    hi = np.where(quiet.any(axis=-1), np.argmax(quiet, axis=-1), nb)  # blocks < hi to search
    last = np.full(m, -1)
    todo = hi > 0
    designs = np.arange(m)[:, None]
    while todo.any():
        lo = hi - width
        blocks = lo[:, None] + np.arange(width)  # (m, width), some before block 0
        c = carries[designs, :, np.clip(blocks, 0, nb)]  # (m, width, n)
        y = out.free_samples(row, np.swapaxes(c, -1, -2))  # (m, L, width)
        k = blocks[:, None, :] * L + np.arange(L)[None, :, None]  # sample numbers
        dev = np.abs(y - final[:, None, None])
        outside = (dev > band[:, None, None]) & (blocks[:, None, :] >= 0) & (k < N - 1)
        found = todo & outside.any(axis=(1, 2))
        last[found] = np.where(outside, k, -1).max(axis=(1, 2))[found]
        todo &= ~found & (lo > 0)
        hi = lo
    return last


#: The registered metrics that read a half or full car's body rotations (ISO 2631-1's
#: We-weighted pitch and roll, `qc_control.ride.metrics`), and the outputs they read.
_ROTATION_READERS = {
    "a_w_rx": ("roll_acc",),
    "a_w_ry": ("pitch_acc",),
    "a_v": ("roll_acc", "pitch_acc"),
}


def _outputs_read(metric_items, roles: SignalRoles, labels: tuple[str, ...]) -> tuple[str, ...]:
    """The output labels the metrics read, in the model's order: the body's and
    every corner's for registered metrics (and the pitch and roll accelerations
    a car has, for the metrics of `_ROTATION_READERS`), all of them for a custom one."""
    if any(not isinstance(metric, str) for _, metric, _ in metric_items):
        return labels
    read = {roles.body_acc, roles.body_disp}
    read |= {label for c in roles.corners for label in (c.susp_travel, c.tire_defl)}
    read |= {label for _, name, _ in metric_items for label in _ROTATION_READERS.get(name, ())}
    return tuple(label for label in labels if label in read)


def _metric_items(metrics, roles: SignalRoles) -> list:
    """``(column, registered name or callable, corner)`` for each requested metric."""
    if metrics is None:
        metrics = SWEEP_METRICS
    if isinstance(metrics, Mapping):
        bad = [k for k, f in metrics.items() if not callable(f)]
        if bad:
            raise TypeError(f"metric {bad[0]!r} must be a callable f(chunk) -> (m,)")
        return [(name, fn, 0) for name, fn in metrics.items()]
    if isinstance(metrics, str):
        metrics = [metrics]
    return [(col, metric.name, i) for col, metric, i in metric_columns(list(metrics), roles)]


@one_blas_thread
def sweep(
    designs,
    T=None,
    X0=SEED_X0,
    U=None,
    method="rk4",
    metrics=None,
    executor=None,
    states: bool = False,
    *,
    model: VehicleModel | None = None,
    substeps: int = 1,
    chunk_size: int | None = None,
    progress: bool | None = None,
    road: Road | None = None,
    events: bool = False,
) -> SweepResult:
    """Simulate many designs of a vehicle at once and tabulate their metrics.

    Parameters
    ----------
    designs : list of parameters or dicts, or a grid dict
        A list of designs (`QuarterCarParams` or dicts of its fields, for the
        default model), or ``{'ks': [...], 'zeta': [...]}`` for the cartesian
        product over the model's own parameters (see `design_grid`). The
        designs are counted first (a grid: the product of its axes' lengths)
        and a sweep that would not fit in memory, `DESIGN_BYTES` a design
        besides its chunks, raises `qc_control.numerics.limits.ResourceLimitError`
        with the count before any design is built.
    T : array_like
        Uniform time grid [s] (not with ``road``).
    X0 : array_like, default ``(0, 0, 0.05, 0)``
        Initial state, the same for every design (the seed's 5 cm release).
    U : array_like, optional
        Input samples at ``T``: ``(len(T),)`` for one input (the road height
        ``zr`` [m] of ``quarter_car(road=True)``) or ``(ninputs, len(T))``;
        ``None`` for the free response.
    method : str or ButcherTableau, default ``'rk4'``
    metrics : sequence of str or dict of name -> callable, optional
        Names from `qc_control.ride.metrics.METRICS` (default `DEFAULT_METRICS`:
        all but the Wk-weighted ones, which cost as much as the simulation),
        or ``{column: f}`` with ``f(chunk: RideSignals) -> (m,)``; a chunk
        gives each output by label, ``chunk.output('xs')`` of shape ``(m, N)``.
    executor : concurrent.futures.Executor, optional
        Receives chunks of designs (``ProcessPoolExecutor``, a Dask
        client's ``get_executor()``, ...). Default: run here.
    states : bool, default False
        Keep every design's states (memory: designs × nstates × len(T) × 8 B).
    model : VehicleModel, optional
        The vehicle the designs are variants of; default
        ``quarter_car_model(road=U is not None)``. Designs are rebuilt with
        its ``batch`` (vectorised for the quarter car). A nonlinear model
        (`qc_control.nonlinear_quarter_car_model`) is stepped for all
        designs at once with its ``batch_dynamics`` (`qc_control.studies.nlsweep`);
        a nonlinear system without one (`qc_control.closed_loop` with a
        clipped controller) runs one `qc_control.input_output_response` per
        design: the same numbers, as slow as that many responses. For a
        nonlinear model ``stable`` says the state stayed finite and the step
        within the method's stability limit along the trajectory, as a
        single run's ``success`` (`qc_control.studies.nlsweep.beyond_stability`).
    substeps : int, default 1
    chunk_size : int, optional
        Designs per chunk: the unit of work sent to the executor (make it
        large, thousands, for a cluster: fewer tasks). Each chunk is computed
        `VECTOR_DESIGNS` (64) designs at a time, `FREE_VECTOR_DESIGNS` (128)
        for a free sweep of registered metrics; that is also the default
        chunk. Results do not depend on it.
        Registered metrics are streamed: about 3 MB of outputs and carries at
        a time whatever ``len(T)`` (see Notes); custom metrics and
        ``states=True`` hold 64 designs' whole outputs (``64 × 5 × len(T)``
        doubles) at a time.
    progress : bool, optional
        Show a tqdm bar. By default it appears on a terminal when the sweep
        outlasts 1 s, and never when standard error is not a terminal.
    road : qc_control.road.Road, optional
        The road every design drives. With ``T``: sampled on ``T`` under
        every wheel in the model's layout (`qc_control.road.Road.wheel_inputs`,
        the rear wheels a wheelbase later; `qc_control.studies.on_road`) and
        simulated, the same numbers as its samples given as ``U`` (give one
        of ``road`` and ``U``); the default model then has road inputs.
        Without ``T``, an `ISO8608Road` is a spectral sweep instead of a
        simulation: the exact stationary RMS metrics on this road
        (`qc_control.ride.spectral.spectral_metrics`, the Lyapunov equation of
        each design on white road velocity, batched), for a linear model
        with road inputs (default ``quarter_car_model(road=True)``). Give no
        ``U`` or ``X0`` then; ``metrics`` among
        `qc_control.ride.spectral.SPECTRAL_CAPABLE` (default
        `qc_control.ride.spectral.SPECTRAL_METRICS`). Runs here, vectorised
        over all designs (``executor`` is not used).
    events : bool, default False
        Nonlinear models only: locate each kink (contact, stop, damper knee)
        inside its step, for the designs that have one in that step
        (`qc_control.studies.nlsweep`); by default the steps go through the kinks.

    Returns
    -------
    SweepResult

    Notes
    -----
    Each chunk builds every design's step map ``R(hA)`` (`qc_control.numerics.lti`)
    and solves all trajectories together with one blocked scan, so the
    results equal `qc_control.initial_response` (and ``forced_response``)
    for each design to rounding. The metrics are those of
    `qc_control.ride_metrics`, column for column.

    Registered metrics are computed as the scan goes by
    (`qc_control.numerics.lti.OutputStream` into `qc_control.ride.metrics.MetricStream`):
    running sums of squares, peaks, counts and the settling time's last
    excursion, and the Wk filter's state carried inside the scan; no
    ``(designs × outputs × samples)`` array exists. The road ``U``, shared by
    every design, enters each block through one product with a window of
    ``U`` per design, so ``Γ₀u + Γ₁u⁺`` is never formed per design. Custom
    metrics (callables) and ``states=True`` read whole trajectories, and get
    them. A design that fails
    validation (a negative mass, say) is reported in ``errors`` by index
    and value, with NaN metrics; the other designs are unaffected.
    """
    if road is not None:
        road = as_road(road)
        if T is None:
            return _spectral_sweep(designs, U, road, metrics, model)
        model, U = _on_road(road, T, U, model)
    if T is None:
        raise ValueError("give T (a time grid) for a simulated sweep, or road= for a spectral one")
    model = quarter_car_model(road=U is not None) if model is None else model
    tab = get_method(method)
    T, X0, U = _sweep_signals(model.system, T, X0, U)
    substeps = check_substeps(substeps)
    if chunk_size is not None:
        chunk_size = integer("chunk_size", chunk_size, minimum=1)
    metric_items = _metric_items(metrics, model.roles)
    # by default the designs computed together (a nonlinear sweep: VECTOR_DESIGNS)
    nl_chunk = VECTOR_DESIGNS if chunk_size is None else chunk_size
    if chunk_size is None:
        chunk_size = _vector_designs(U, metric_items, states)
    streamed = not states and not isinstance(metrics, Mapping)
    designs = _design_list(
        designs,
        model,
        lambda count, grid: _check_sweep_memory(
            model.system, count, T.size, chunk_size, streamed, states, grid
        ),
    )
    params, errors = _validate(designs, type(model.params))
    if model.is_nonlinear:  # stepped in a batch (qc_control.studies.nlsweep), or one by one
        stable, table, kept = nonlinear_sweep(
            model, params, T, X0, U, tab, substeps, metric_items, states,
            events=events, executor=executor, chunk_size=nl_chunk,
        )  # fmt: skip
    elif events:
        raise ValueError("events=True applies to a nonlinear model; this one is linear")
    else:
        task = _ChunkTask(
            tuple(model.system.output_labels), model.roles, T, X0, U, tab, substeps,
            metric_items, states,
        )  # fmt: skip
        chunks, batch, eig = _linear_chunks(model, params, chunk_size, free=U is None and streamed)
        results = _chunk_results(executor, chunks, batch, task, eig)
        stable, table, kept = _gather(chunks, results, len(designs), task, progress)
    frame, err_frame = _tables(designs, params, errors, model, stable, table)
    return SweepResult(T=T, method=tab, metrics=frame, errors=err_frame, states=kept, road=road)


def _on_road(
    road: Road, T, U, model: VehicleModel | None
) -> tuple[VehicleModel, np.ndarray | None]:
    """``(model, U)`` of a sweep on ``road`` over ``T``: the model (by default the
    quarter car with its road input) and the road's samples in its layout
    (`qc_control.studies.on_road.road_inputs`, the registry's entry for the
    model's parameters), refused beside samples of its own."""
    if U is not None:
        raise ParameterError("road", road, "given alone: the road gives U, its samples on T")
    if model is None:
        model = quarter_car_model(road=not isinstance(road, NoRoad))
    elif not isinstance(road, NoRoad) and not model.road_inputs():
        raise ParameterError(
            "model", model.name, f"a model with road inputs (road=True) to drive {road.noun}"
        )
    samples, _ = road_inputs(road, T, model_for_params(model.params), model.params)
    return model, samples


def _design_list(designs, model: VehicleModel, check) -> list:
    """The designs as a list: a grid dict expanded over the model's parameters.

    ``check(count, grid)`` is called with the number of designs (and the
    grid's axes as text, or '') before a grid is expanded: a grid of a billion
    designs is refused by its count, not by running out of memory building it.
    """
    if isinstance(designs, Mapping):
        keys, axes, count = _grid_axes(designs, model.params)
        check(count, _grid_shape(keys, axes))
        return design_grid(designs, model.params)
    designs = list(designs)
    if not designs:
        raise ValueError("designs is empty: give at least one design")
    check(len(designs), "")
    return designs


def _sweep_signals(system, T, X0, U):
    """``T`` (uniform), ``X0`` and ``U`` (None: the free response) checked as the
    responses check them (`qc_control.responses.timeresp.check_initial_state`,
    ``check_input_samples``)."""
    T = check_time_grid(T, "T")
    if uniform_step(T) is None:
        raise ValueError("T must be uniformly spaced for a sweep")
    X0 = check_initial_state(X0, system.nstates, system.state_labels)
    if U is not None:
        U = check_input_samples(U, system.ninputs, T.size, system.input_labels)
    return T, X0, U


def _check_sweep_memory(
    system, designs: int, N: int, chunk_size, streamed, states, grid=""
) -> None:
    """Refuse a sweep whose designs, chunks (and kept states) would not fit in memory
    (``grid``: the grid's axes, named in the message)."""
    n = system.nstates
    rows = min(chunk_size, designs, VECTOR_DESIGNS) * (system.noutputs + n * states)
    # streamed: a segment of outputs (~1 MB), a run of carries (~2 MB) and the padded
    # input; otherwise a chunk's outputs (and states) with the scan's temporaries,
    # plus every kept trajectory
    per_chunk = (2**22 + 16 * N) if streamed else 3 * rows * N * 8
    check_memory(
        per_chunk + designs * DESIGN_BYTES + states * designs * n * N * 8,
        f"a sweep of {designs} designs"
        + (f" ({grid})" if grid else "")
        + f" over {N} samples"
        + (" keeping their states" if states else ""),
        "use fewer designs or samples, a smaller chunk_size"
        + (" or states=False" if states else ""),
    )


def _linear_chunks(model: VehicleModel, params, chunk_size: int, free: bool):
    """``(chunks, batch, eig)``: the valid designs' matrices, and chunks of them as
    ``(design indices, rows of batch)``; ``eig`` is the batch's decomposition
    when a free sweep orders its designs by decay (else None)."""
    good = [i for i, p in enumerate(params) if p is not None]
    batch = (
        model.batch([params[i] for i in good])
        if good
        else BatchedModel(*(np.zeros((0, 1, 1)),) * 4, (), ())
    )
    order = np.arange(len(good))
    eig = None
    if free and len(good) > VECTOR_DESIGNS:
        # a free chunk stops once its slowest design has decayed past what its
        # metrics can see (TailBound): chunk designs of like decay together,
        # by their slowest mode's decay rate, fastest first (results go back by
        # index, so the order is free); the chunks reuse the decomposition
        eig = np.linalg.eig(batch.A)
        with np.errstate(invalid="ignore"):
            abscissa = eig[0].real.max(axis=-1)
        order = np.argsort(np.nan_to_num(abscissa, nan=np.inf), kind="stable")
    chunks = [
        ([good[i] for i in order[s : s + chunk_size]], order[s : s + chunk_size])
        for s in range(0, len(good), chunk_size)
    ]
    return chunks, batch, eig


def _chunk_results(executor, chunks, batch: BatchedModel, task: _ChunkTask, eig):
    """Each chunk's `_ChunkResult`, in order: computed here, or by ``executor``."""
    if executor is None:
        return (_run_chunk(_take(batch, sl), task, eig=_eig_part(eig, sl)) for _, sl in chunks)
    if isinstance(executor, Executor) or hasattr(executor, "submit"):
        futures = [
            executor.submit(_run_chunk, _take(batch, sl), task, eig=_eig_part(eig, sl))
            for _, sl in chunks
        ]
        return (f.result() for f in futures)
    raise TypeError(
        f"executor must be a concurrent.futures.Executor, got {type(executor).__name__}"
    )


def _gather(chunks, results, ndesigns: int, task: _ChunkTask, progress):
    """``(stable, table, states)`` by design index from the chunks' results,
    with a progress bar on a terminal."""
    quiet = progress is False or (progress is None and not sys.stderr.isatty())
    bar = tqdm(
        results,
        total=len(chunks),
        unit="chunk",
        desc="sweep",
        disable=quiet,
        delay=0 if progress else 1.0,
    )
    table = {column: np.full(ndesigns, np.nan) for column, _, _ in task.metric_items}
    stable = np.zeros(ndesigns, dtype=bool)
    n, N = task.X0.size, task.T.size
    kept = np.full((ndesigns, n, N), np.nan) if task.keep_states else None
    for (idx, _), result in zip(chunks, bar):
        stable[idx] = result.stable
        for column, values in result.metrics.items():
            table[column][idx] = values
        if kept is not None:
            kept[idx] = result.states
    bar.close()
    return stable, table, kept


def _eig_part(eig, idx):
    """The rows ``idx`` of ``np.linalg.eig``'s ``(eigenvalues, eigenvectors)``, or None."""
    return None if eig is None else (eig[0][idx], eig[1][idx])


def _tables(designs, params, errors, model, stable, table) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The result's ``metrics`` and ``errors`` frames; warns about rejected designs."""
    names = list(model.params.to_dict())
    # column by column (one getattr per value, no dict per design), in one frame
    columns: dict = {n: [np.nan if p is None else getattr(p, n) for p in params] for n in names}
    columns["stable"] = stable
    columns.update(table)
    error = [""] * len(params)
    for i, _, message in errors:
        error[i] = message
    columns["error"] = error
    frame = pd.DataFrame(columns)
    err_frame = pd.DataFrame(errors, columns=["index", "value", "error"])
    if errors:
        warnings.warn(
            f"{len(errors)} of {len(designs)} designs were rejected; first: design "
            f"{errors[0][0]}: {errors[0][2]} (see .errors)",
            RuntimeWarning,
            stacklevel=3,
        )
    frame.index.name = "design"
    return frame, err_frame


def _spectral_sweep(designs, U, road: Road, metrics, model) -> SweepResult:
    """`sweep` with ``road=`` and no ``T``: exact stationary RMS metrics, no simulation."""
    if not isinstance(road, ISO8608Road):
        raise ParameterError(
            "road",
            road,
            "an ISO8608Road for a spectral sweep (without T); give T to simulate the designs "
            "on this road",
        )
    if U is not None:
        raise ValueError(
            "a spectral sweep (road= without T) takes no U: its metrics are stationary, "
            "over the unbounded band"
        )
    model = quarter_car_model(road=True) if model is None else model
    require_linear(model)
    designs = _design_list(
        designs,
        model,
        lambda count, grid: check_memory(
            count * DESIGN_BYTES,
            f"a spectral sweep of {count} designs" + (f" ({grid})" if grid else ""),
            "use fewer designs, or sweep them in parts",
        ),
    )
    names = (
        SPECTRAL_METRICS
        if metrics is None
        else ([metrics] if isinstance(metrics, str) else metrics)
    )
    if isinstance(names, Mapping):
        raise TypeError("a spectral sweep computes registered metrics only, not callables")
    columns = [column for column, _, _ in metric_columns(list(names), model.roles)]
    params, errors = _validate(designs, type(model.params))
    good = np.array([i for i, p in enumerate(params) if p is not None], dtype=int)
    table = {column: np.full(len(designs), np.nan) for column in columns}
    stable = np.zeros(len(designs), dtype=bool)
    if good.size:
        batch = model.batch([params[i] for i in good])
        hurwitz = np.linalg.eigvals(batch.A).real.max(axis=-1) < 0
        stable[good] = hurwitz
        keep = np.flatnonzero(hurwitz)
        for start in range(0, keep.size, 4096):  # bounds the Kronecker systems' memory
            part = keep[start : start + 4096]
            values = spectral_metrics(
                model, road.intensity, names, batch=_take(batch, part), speed=road.speed
            )
            for column in columns:
                table[column][good[part]] = values[column]
    frame, err_frame = _tables(designs, params, errors, model, stable, table)
    return SweepResult(T=None, method=None, metrics=frame, errors=err_frame, road=road)
