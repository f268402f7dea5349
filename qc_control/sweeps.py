"""Design sweeps: thousands of quarter cars, vectorised, chunked, on any executor."""

from __future__ import annotations

import itertools
import warnings
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, fields

import numpy as np
import pandas as pd

from .compare import DEFAULT_X0
from .integrate import check_substeps, check_time_grid, uniform_step
from .lti import affine_scan, step_matrices
from .methods import ButcherTableau, get_method
from .model import QuarterCarParams, seed_matrices
from .stability import amplification

__all__ = ["sweep", "SweepResult", "SweepChunk", "METRICS", "DEFAULT_METRICS", "design_grid"]

_PARAM_NAMES = [f.name for f in fields(QuarterCarParams)]


@dataclass(eq=False)
class SweepChunk:
    """What a metric sees: one chunk of ``m`` designs.

    Attributes
    ----------
    T : ndarray, shape (N,)
    y : ndarray, shape (m, 5, N)
        Outputs in the order of `qc_control.OUTPUTS` (xs, xu, susp_travel,
        tire_defl, body_acc), time last.
    design : dict[str, ndarray]
        ``ms``, ``mu``, ``ks``, ``ku``, ``cs`` of each design, shape (m,).
    """

    T: np.ndarray
    y: np.ndarray
    design: dict
    _weighted: np.ndarray | None = None

    @property
    def weighted_acc(self) -> np.ndarray:
        """ISO 2631-1 Wk-weighted body acceleration (m, N), computed once."""
        if self._weighted is None:
            from .ride import wk_weighted

            self._weighted = wk_weighted(self.y[:, 4], self.T)
        return self._weighted


def _peak(v):
    """max |v| along time without an |v| temporary."""
    return np.maximum(v.max(axis=-1), -v.min(axis=-1))


def _mean_square(v, T):
    """Trapezoidal mean of v² on the sweep's uniform grid: (Σv² - (v₀² + v_N²)/2)/(N - 1)."""
    squares = np.einsum("ij,ij->i", v, v) - 0.5 * (v[:, 0] ** 2 + v[:, -1] ** 2)
    return squares / (T.size - 1)


def _peak_travel(c):
    """Largest |xs - xu| [m]: the rattle space the design needs."""
    return _peak(c.y[:, 2])


def _rms_body_acc(c):
    """RMS of xs'' [m/s²] (trapezoidal mean square): unweighted comfort."""
    return np.sqrt(_mean_square(c.y[:, 4], c.T))


def _settling_time(c):
    """First time [s] after which xs stays within 2% of its largest excursion
    from its final value (the 2% settling criterion)."""
    T, y = c.T, c.y
    dev = np.abs(y[:, 0, ::-1] - y[:, 0, -1:])  # time reversed, stored contiguous
    outside = dev > 0.02 * np.max(dev, axis=-1, keepdims=True)
    from_end = np.argmax(outside, axis=-1)  # first sample outside, from the end
    settle = np.minimum(np.where(outside.any(axis=-1), T.size - from_end, 0), T.size - 1)
    return T[settle]


def _peak_tire_defl(c):
    """Largest |xu - zr| [m]: dynamic tire deflection."""
    return _peak(c.y[:, 3])


def _static_load(c):
    from .ride import STANDARD_GRAVITY

    return (c.design["ms"] + c.design["mu"]) * STANDARD_GRAVITY


def _rms_tire_load(c):
    """RMS dynamic tire load ku·(zr - xu) over the static wheel load (ms + mu)·g."""
    return c.design["ku"] * np.sqrt(_mean_square(c.y[:, 3], c.T)) / _static_load(c)


def _lift_off_time(c):
    """Time [s] the dynamic load unloads the tire by more than the static load."""
    lifted = c.y[:, 3] > (_static_load(c) / c.design["ku"])[:, None]  # ku·defl > static
    return np.count_nonzero(lifted, axis=-1) * (c.T[1] - c.T[0])


def _rms_body_acc_wk(c):
    """ISO 2631-1 Wk-weighted RMS body acceleration [m/s²]."""
    return np.sqrt(_mean_square(c.weighted_acc, c.T))


def _vdv(c):
    """Vibration dose value (∫ a_w⁴ dt)^{1/4} [m/s^1.75] (ISO 2631-1, 6.3.2)."""
    a4 = c.weighted_acc**4
    return (np.trapezoid(a4, c.T, axis=-1)) ** 0.25


#: Metrics by name: ``f(chunk: SweepChunk) -> (m,)``. The ride metrics are
#: those of `qc_control.ride_metrics` (same formulas).
METRICS: dict[str, Callable] = {
    "peak_travel [m]": _peak_travel,
    "rms_body_acc [m/s²]": _rms_body_acc,
    "settling_time [s]": _settling_time,
    "peak_tire_defl [m]": _peak_tire_defl,
    "rms_tire_load / static [-]": _rms_tire_load,
    "lift_off_time [s]": _lift_off_time,
    "rms_body_acc_wk [m/s²]": _rms_body_acc_wk,
    "vdv [m/s^1.75]": _vdv,
}
#: Computed unless ``metrics`` says otherwise. The Wk-weighted metrics cost
#: an FFT convolution per design (about 0.2 ms on 10,001 samples, as much as
#: the simulation itself), so they are computed when asked for by name.
DEFAULT_METRICS = tuple(m for m in METRICS if m not in ("rms_body_acc_wk [m/s²]", "vdv [m/s^1.75]"))


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
    """

    T: np.ndarray
    method: ButcherTableau
    metrics: pd.DataFrame
    errors: pd.DataFrame
    states: np.ndarray | None = None


def design_grid(grid: Mapping[str, Sequence], base: QuarterCarParams | None = None) -> list:
    """The cartesian product of a ``{'field': [values]}`` grid, as dicts.

    Fields not in the grid come from ``base`` (the seed's car by default).
    A key that is not a parameter raises ``ValueError`` naming it.
    """
    unknown = sorted(set(grid) - set(_PARAM_NAMES))
    if unknown:
        raise ValueError(
            f"unknown parameter {unknown[0]!r} in the grid; expected some of {_PARAM_NAMES}"
        )
    base_values = (base or QuarterCarParams()).to_dict()
    # cs in the grid is the damping; otherwise zeta (the grid's or the base's)
    # sets it, so that cs follows ks and ms along the grid
    base_values.pop("zeta" if "cs" in grid else "cs")
    keys = list(grid)
    return [
        {**base_values, **dict(zip(keys, combo))}
        for combo in itertools.product(*(list(grid[k]) for k in keys))
    ]


def _validate(designs) -> tuple[list, list]:
    """(params or None per design, [(index, value, message)])."""
    out, errors = [], []
    for i, d in enumerate(designs):
        try:
            if isinstance(d, QuarterCarParams):
                out.append(d)
            elif isinstance(d, Mapping):
                out.append(QuarterCarParams.from_mapping(d))
            else:
                raise TypeError(
                    f"a design must be QuarterCarParams or a dict, got {type(d).__name__}"
                )
        except (TypeError, ValueError) as exc:
            out.append(None)
            errors.append((i, d if isinstance(d, Mapping) else repr(d), str(exc)))
    return out, errors


def _matrices(values: np.ndarray, road: bool):
    """Batched A (m,4,4) and B (m,4,k) from rows of ms, mu, ks, ku, cs."""
    A, b_road, _ = seed_matrices(*values.T)
    B = b_road[:, :, None] if road else np.zeros((values.shape[0], 4, 0))
    return A, B


def _run_chunk(
    values: np.ndarray,
    T: np.ndarray,
    X0: np.ndarray,
    U: np.ndarray | None,
    method: ButcherTableau,
    substeps: int,
    metric_items,
    keep_states: bool,
):
    """Simulate one chunk of designs; module level so executors can pickle it."""
    A, B = _matrices(values, U is not None)
    H = (T[-1] - T[0]) / (T.size - 1)
    phi, g0, g1 = step_matrices(method, A, B, H, substeps)
    W = None
    if U is not None:
        W = U[None, :-1, None] * g0[:, None, :, 0] + U[None, 1:, None] * g1[:, None, :, 0]
    m = values.shape[0]
    # outputs xs, xu, xs - xu, xu (- zr below), body_acc = A[0] x (+ B[0] zr, zero)
    C = np.zeros((m, 5, 4))
    C[:, 0, 2] = C[:, 1, 3] = C[:, 2, 2] = C[:, 3, 3] = 1.0
    C[:, 2, 3] = -1.0
    C[:, 4] = A[:, 0]
    if keep_states:  # observe the states too: [I; C]
        C = np.concatenate([np.broadcast_to(np.eye(4), (m, 4, 4)), C], axis=1)
    with np.errstate(over="ignore", invalid="ignore"):
        # time last, so that every metric reduces contiguous memory
        y = affine_scan(
            phi,
            np.broadcast_to(X0, (m, 4)),
            W,
            T.size,
            block=16 if W is not None else 32,
            C=C,
            time_last=True,
        )
        x = y[:, :4] if keep_states else None
        y = y[:, 4:] if keep_states else y
        if U is not None:
            y[:, 3] -= U[None, :]
        stable = amplification(method, H / substeps, np.linalg.eigvals(A)) <= 1 + 1e-12
        result = {"stable": stable}
        chunk = SweepChunk(T, y, dict(zip(("ms", "mu", "ks", "ku", "cs"), values.T)))
        for name, fn in metric_items:
            result[name] = np.asarray(fn(chunk), dtype=float)
    return result, x


def sweep(
    designs,
    T,
    X0=DEFAULT_X0,
    U=None,
    method="rk4",
    metrics=None,
    executor=None,
    states: bool = False,
    *,
    substeps: int = 1,
    chunk_size: int = 16,
    progress: bool | None = None,
) -> SweepResult:
    """Simulate many quarter-car designs at once and tabulate their metrics.

    Parameters
    ----------
    designs : list of QuarterCarParams or dict, or a grid dict
        A list of designs, or ``{'ks': [...], 'zeta': [...]}`` for the
        cartesian product over the seed's car (see `design_grid`).
    T : array_like
        Uniform time grid [s].
    X0 : array_like, default ``(0, 0, 0.05, 0)``
        Initial state, the same for every design.
    U : array_like, optional
        Road height ``zr`` [m] at ``T`` (``quarter_car(road=True)``);
        ``None`` for the free response.
    method : str or ButcherTableau, default ``'rk4'``
    metrics : sequence of str or dict of name -> callable, optional
        Names from `METRICS` (default `DEFAULT_METRICS`: all but the two
        Wk-weighted ones, which cost as much as the simulation), or
        ``{name: f}`` with ``f(chunk: SweepChunk) -> (m,)``.
    executor : concurrent.futures.Executor, optional
        Receives chunks of designs (``ProcessPoolExecutor``, a Dask
        client's ``get_executor()``, ...). Default: run here.
    states : bool, default False
        Keep every design's states (memory: designs × 4 × len(T) × 8 B).
    substeps : int, default 1
    chunk_size : int, default 16
        Designs per chunk: the unit of vectorisation, of memory and of work
        sent to the executor. Results do not depend on it. 16 keeps a chunk's
        outputs (16 × 5 × len(T) doubles) near the cache on 10,001 samples.
    progress : bool, optional
        Show a tqdm bar; by default it appears when the sweep outlasts 1 s.

    Returns
    -------
    SweepResult

    Notes
    -----
    Each chunk builds every design's step map ``R(hA)`` (`qc_control.lti`)
    and solves all trajectories together with one blocked scan, so the
    results equal `qc_control.initial_response` (and ``forced_response``)
    for each design to rounding. A design that fails validation (a
    negative mass, say) is reported in ``errors`` by index and value, with
    NaN metrics; the other designs are unaffected.
    """
    if isinstance(designs, Mapping):
        designs = design_grid(designs)
    designs = list(designs)
    if not designs:
        raise ValueError("designs is empty")
    tab = get_method(method)
    T = check_time_grid(T, "T")
    if uniform_step(T) is None:
        raise ValueError("T must be uniformly spaced for a sweep")
    substeps = check_substeps(substeps)
    X0 = np.asarray(X0, dtype=float)
    if X0.shape != (4,) or not np.all(np.isfinite(X0)):
        raise ValueError(f"X0 must be 4 finite numbers [vs, vu, xs, xu], got {X0.tolist()}")
    if U is not None:
        U = np.asarray(U, dtype=float).reshape(-1)
        if U.shape != T.shape or not np.all(np.isfinite(U)):
            raise ValueError(
                f"U must be {T.size} finite road heights matching T, got shape {np.shape(U)}"
            )
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1:
        raise ValueError(f"chunk_size must be a positive integer, got {chunk_size!r}")
    if metrics is None:
        metric_items = [(m, METRICS[m]) for m in DEFAULT_METRICS]
    elif isinstance(metrics, Mapping):
        metric_items = list(metrics.items())
    else:
        unknown = [m for m in metrics if m not in METRICS]
        if unknown:
            raise ValueError(f"unknown metric {unknown[0]!r}; known: {', '.join(METRICS)}")
        metric_items = [(m, METRICS[m]) for m in metrics]

    params, errors = _validate(designs)
    good = [i for i, p in enumerate(params) if p is not None]
    values = np.array(
        [[params[i].ms, params[i].mu, params[i].ks, params[i].ku, params[i].cs] for i in good]
    ).reshape(-1, 5)
    chunks = [
        (good[s : s + chunk_size], values[s : s + chunk_size])
        for s in range(0, len(good), chunk_size)
    ]
    args = (T, X0, U, tab, substeps, metric_items, states)
    if executor is None:
        results = (_run_chunk(v, *args) for _, v in chunks)
    elif isinstance(executor, Executor) or hasattr(executor, "submit"):
        futures = [executor.submit(_run_chunk, v, *args) for _, v in chunks]
        results = (f.result() for f in futures)
    else:
        raise TypeError(
            f"executor must be a concurrent.futures.Executor, got {type(executor).__name__}"
        )

    from tqdm.auto import tqdm

    bar = tqdm(
        results,
        total=len(chunks),
        unit="chunk",
        desc="sweep",
        disable=progress is False,
        delay=0 if progress else 1.0,
    )
    table = {name: np.full(len(designs), np.nan) for name, _ in metric_items}
    stable = np.zeros(len(designs), dtype=bool)
    kept = np.full((len(designs), 4, T.size), np.nan) if states else None
    for (idx, _), (result, x) in zip(chunks, bar):
        stable[idx] = result["stable"]
        for name, _ in metric_items:
            table[name][idx] = result[name]
        if states:
            kept[idx] = x
    bar.close()

    frame = pd.DataFrame(
        [p.to_dict() if p is not None else dict.fromkeys(_PARAM_NAMES) for p in params]
    )
    frame["stable"] = stable
    for name, column in table.items():
        frame[name] = column
    frame["error"] = ""
    for i, _, message in errors:
        frame.loc[i, "error"] = message
    err_frame = pd.DataFrame(errors, columns=["index", "value", "error"])
    if errors:
        warnings.warn(
            f"{len(errors)} of {len(designs)} designs were rejected; first: design "
            f"{errors[0][0]}: {errors[0][2]} (see .errors)",
            RuntimeWarning,
            stacklevel=2,
        )
    frame.index.name = "design"
    return SweepResult(T=T, method=tab, metrics=frame, errors=err_frame, states=kept)
