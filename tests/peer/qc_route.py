"""pytest plugin: route python-control's responses to qc_control, and record who called them.

Loaded with ``-p qc_route`` into a pytest run of python-control's own test
files (see `run_peer.py`). It replaces ``control.initial_response`` and
``control.forced_response`` (with ``QC_PEER_FUNCS=all`` also
``step_response`` and ``impulse_response``); ``QC_PEER_MODE`` chooses what
the replacements do:

``record``
    call python-control itself, and record which tests called them (this
    is how `peer_tests.txt`, the checked-in denominator, is made);
``qc``
    call ``qc_control``'s function of the same name with RK4 at a fine
    step: each interval of ``T`` is split into the fewest substeps with
    ``h·|λ|max <= QC_PEER_HLAM`` (default 0.01), and smaller on long runs,
    so that ``t|λ|·(h|λ|)⁴/120 <= QC_PEER_TARGET`` (default 1e-9).

Both names are replaced in ``control`` and in ``control.timeresp`` (test
files import them from either). ``QC_PEER_SCOPE`` says which calls count:
``direct`` (default) routes and records every call except those from
python-control's other response functions in ``control.timeresp``
(``step_response``, ``impulse_response``, ``initial_response`` are built on
``forced_response``; they keep control's own); ``all`` routes those too.
``QC_PEER_REPORT`` names the JSON file that receives the callers, each
test's outcome, the tests in which a nonlinear system went through
qc_control's nonlinear engine, and each test's largest relative difference
from python-control: from its exact answer for linear systems, from its
answer with solve_ivp at `TIGHT_IVP` for nonlinear ones.

Nonlinear systems: the step is chosen by the same rule, with ``|λ|max``
from the system's Jacobian at the call's initial state and first input
(python-control's ``linearize``).

Random systems: python-control's tests draw them with ``ct.rss`` from
numpy's global generator. The plugin seeds it per test (from the node id),
so every run sees the same systems. About 1 in 4,000 of those random
systems is so non-normal (entries ~1e5, eigenvalues ~20, eigenvector
condition ~3e4) that rounding alone moves python-control's own answer by
1e-4 relative from ``expm(A t) x0``; on such a system no method agrees with
another to 1e-8, and an unseeded run would fail now and then.

Why: RK4's local error on a mode is ``|hλ|⁵/120`` of its size per step,
8.3e-13 at h|λ| = 0.01, and the global error after ``t|λ|`` is about
``t|λ|·(h|λ|)⁴/120``: 8.3e-9 at t|λ| = 100, more on longer runs. Bounding it
by 1e-9 per call keeps the difference from python-control's exact response
well below the 1e-8 the peer test asserts.
"""

from __future__ import annotations

import inspect
import json
import math
import os
import sys
import warnings
import zlib

import control
import control.timeresp as ct_timeresp
import numpy as np
import pytest

import qc_control.responses.timeresp as qc_response
from qc_control import compat

MODE = os.environ.get("QC_PEER_MODE", "qc")
SCOPE = os.environ.get("QC_PEER_SCOPE", "direct")
REPORT = os.environ.get("QC_PEER_REPORT")
H_LAMBDA = float(os.environ.get("QC_PEER_HLAM", "0.01"))
TARGET = float(os.environ.get("QC_PEER_TARGET", "1e-9"))

#: Which functions to route: the two of the issue, or (QC_PEER_FUNCS=all) also
#: step_response and impulse_response, to try qc_control's versions of those.
FUNCS = (
    ["forced_response", "initial_response", "step_response", "impulse_response"]
    if os.environ.get("QC_PEER_FUNCS") == "all"
    else ["forced_response", "initial_response"]
)
_ORIGINAL = {name: getattr(ct_timeresp, name) for name in FUNCS}
_SIGNATURE = {name: inspect.signature(f) for name, f in _ORIGINAL.items()}
_ALIASES = {"timepts": "T", "timepts_num": "T_num"}
#: the module (``control.nlsys`` is also the name of its factory function)
_NLSYS = sys.modules["control.nlsys"]

COMPARE = os.environ.get("QC_PEER_COMPARE", "1") == "1"

_current: str | None = None
_comparing = False
called: set[str] = set()
outcomes: dict[str, str] = {}
nonlinear: set[str] = set()  # tests in which a nonlinear system went to qc's nonlinear engine
errors: dict[str, float] = {}  # largest relative difference from control, per test (LTI calls)
errors_nonlinear: dict[str, float] = {}  # the same for nonlinear calls, from a tight solve_ivp
_in_nonlinear = False  # set by the nonlinear engine's hook during a routed call

#: The reference for a nonlinear call: python-control's own response with
#: solve_ivp at these settings instead of its default (RK45, rtol 1e-3).
TIGHT_IVP = {"method": "DOP853", "rtol": 1e-12, "atol": 1e-12}


def _record_nonlinear(original):
    def engine(sys, *args, **kwargs):
        global _in_nonlinear
        _in_nonlinear = True
        if _current is not None:
            nonlinear.add(_current)
        return original(sys, *args, **kwargs)

    return engine


def _tight(original_iorsp):
    """control.input_output_response with solve_ivp at `TIGHT_IVP`."""

    def iorsp(*args, **kwargs):
        kwargs["solve_ivp_kwargs"] = {**(kwargs.get("solve_ivp_kwargs") or {}), **TIGHT_IVP}
        return original_iorsp(*args, **kwargs)

    return iorsp


def _relative_difference(ours, theirs) -> float:
    """max |ours - control| / max |control|, over outputs and states of every response."""
    pairs = zip(ours, theirs) if isinstance(theirs, list) else [(ours, theirs)]
    worst = 0.0
    for a, b in pairs:
        for name in ("y", "x"):
            va, vb = getattr(a, name, None), getattr(b, name, None)
            if vb is None or np.asarray(vb).size == 0:
                continue
            va, vb = np.asarray(va, dtype=complex), np.asarray(vb, dtype=complex)
            if va.shape != vb.shape:
                return math.inf
            scale = float(np.max(np.abs(vb)))
            diff = float(np.max(np.abs(va - vb)))
            if not math.isfinite(diff):
                return math.inf
            worst = max(worst, diff / scale if scale > 0 else diff)
    return worst


#: control's answers to the calls made so far, by `_call_key`: python-control's
#: tests repeat calls (timeplot_test plots ``step_response(sys)`` of the same two
#: systems in 28 ways each), and the same call gets the same answer. A quarter of
#: the time spent on control's references went to such repeats.
_REFERENCES: dict[tuple, object] = {}


def _encoded(value):
    """``value`` as a tuple of plain values that determine it; TypeError where that is not known."""
    if value is None or isinstance(value, (bool, int, float, complex, str)):
        return value
    if isinstance(value, np.ndarray) and value.dtype.kind in "biufc":
        return ("array", value.dtype.str, value.shape, value.tobytes())
    if isinstance(value, (list, tuple)):
        return (type(value).__name__, *map(_encoded, value))
    if isinstance(value, dict):
        return ("dict", *((k, _encoded(v)) for k, v in value.items()))
    if type(value) is control.StateSpace:
        return ("ss", value.dt, *map(_encoded, (value.A, value.B, value.C, value.D)))
    raise TypeError(type(value))


def _call_key(name: str, args, kwargs) -> tuple | None:
    """What control's answer to a call on linear systems depends on: the function, its
    arguments and control's defaults (``squeeze``, ``return_x``, ... that tests edit);
    None for an argument that `_encoded` does not know (that call is not remembered)."""
    try:
        return (name, _encoded(args), _encoded(kwargs), repr(control.config.defaults))
    except TypeError:
        return None


def _compare(original, ours_result, args, kwargs, is_nonlinear: bool) -> None:
    """Run control's own function on the same call and keep the difference.

    On a nonlinear system control's answer is solve_ivp's at its default
    tolerances (RK45, rtol 1e-3), not an exact one: the call is then run
    with solve_ivp at `TIGHT_IVP`, and the difference kept apart. On linear
    systems a repeated call reuses control's answer (`_REFERENCES`).
    """
    key = None if is_nonlinear else _call_key(original.__name__, args, kwargs)
    if key is not None and key in _REFERENCES:
        _record(ours_result, _REFERENCES[key], is_nonlinear)
        return
    global _comparing
    _comparing = True
    saved = _NLSYS.input_output_response
    if is_nonlinear:
        _NLSYS.input_output_response = _tight(saved)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            theirs = original(*args, **kwargs)
    except Exception:
        return
    finally:
        _comparing = False
        _NLSYS.input_output_response = saved
    if key is not None:
        _REFERENCES[key] = theirs
    _record(ours_result, theirs, is_nonlinear)


def _record(ours_result, theirs, is_nonlinear: bool) -> None:
    """Keep the current test's largest difference from control's answer."""
    err = _relative_difference(ours_result, theirs)
    table = errors_nonlinear if is_nonlinear else errors
    if _current is not None:
        table[_current] = max(table.get(_current, 0.0), err)


def _argument(name: str, args, kwargs, key: str):
    """The value of control's parameter ``key`` (or its alias) in this call."""
    bound = _SIGNATURE[name].bind_partial(*args, **kwargs).arguments
    if key in bound:
        return bound[key]
    extra = bound.get("kwargs", {})
    return extra.get(key, extra.get(_ALIASES.get(key, key)))


def _h_lambda(t_lambda: float) -> float:
    """h·|λ|max for a run spanning ``t·|λ|max = t_lambda``: H_LAMBDA, or less on long runs.

    RK4's global error on a mode after ``t|λ|`` is about ``t|λ|·(h|λ|)⁴/120``
    of the mode; this keeps it at TARGET (default 1e-9) or below.
    """
    if not (math.isfinite(t_lambda) and t_lambda > 0):
        return H_LAMBDA
    return min(H_LAMBDA, (120 * TARGET / t_lambda) ** 0.25)


def _jacobian(system, name: str, args, kwargs) -> np.ndarray:
    """A nonlinear system's Jacobian at the call's initial state and first input.

    python-control's own `linearize` (forward differences); an empty array
    when it cannot be had (then the grid's own step is used).
    """
    try:
        X0 = _argument(name, args, kwargs, "initial_state")
        x0, _ = compat.process_vector_argument(0.0 if X0 is None else X0, "X0", system.nstates)
        U = _argument(name, args, kwargs, "inputs")
        u = np.asarray(0.0 if U is None else U, dtype=float)
        # the first sample: U is (ninputs, N), (N,) for one input, or a number
        u0 = u[:, 0] if u.ndim == 2 else (u[:1] if u.ndim == 1 else np.full(system.ninputs, u))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            params = _argument(name, args, kwargs, "params")
            lin = system.linearize(x0, u0 if system.ninputs else None, params=params)
        return np.asarray(lin.A, dtype=float)
    except Exception:
        return np.zeros((0, 0))


def _fine_substeps(name: str, args, kwargs) -> int:
    """Fewest substeps with h·|λ|max <= `_h_lambda` on every continuous system in the call."""
    sysdata = _argument(name, args, kwargs, "sysdata")
    systems = sysdata if isinstance(sysdata, (list, tuple)) else [sysdata]
    T = _argument(name, args, kwargs, "timepts")
    if T is None or np.ndim(T) == 0 or np.size(T) == 1:
        if name == "forced_response":
            return 1
        try:
            T = compat.default_time_vector(
                sysdata,
                N=_argument(name, args, kwargs, "timepts_num"),
                tfinal=T,
                is_step=name == "step_response",
            )
        except Exception:
            return 1  # qc_control raises control's own error for this call
    try:
        T = np.asarray(T, dtype=float).reshape(-1)
        H, span = float(np.max(np.diff(T))), float(T[-1] - T[0])
    except (TypeError, ValueError):
        return 1
    need = 1
    for system in systems:
        if not isinstance(system, control.InputOutputSystem) or not control.isctime(
            system, strict=True
        ):
            continue
        if isinstance(system, control.LTI):
            A = np.asarray(control.ss(system).A, dtype=float)
        else:
            A = _jacobian(system, name, args, kwargs)
        if A.size and np.all(np.isfinite(A)) and math.isfinite(H) and H > 0:
            lam = float(np.max(np.abs(np.linalg.eigvals(A))))
            need = max(need, math.ceil(H * lam / _h_lambda(span * lam)))
    return need


def _routed(name: str):
    original = _ORIGINAL[name]
    ours = getattr(qc_response, name)

    def call(*args, **kwargs):
        caller = sys._getframe(1).f_globals.get("__name__", "")
        if _comparing or (SCOPE == "direct" and caller == "control.timeresp"):
            # control's own run of a call, for the comparison; or python-control's
            # step/impulse/initial responses built on forced_response
            return original(*args, **kwargs)
        if _current is not None:
            called.add(_current)
        if MODE == "record":
            return original(*args, **kwargs)
        global _in_nonlinear
        substeps = _fine_substeps(name, args, kwargs)
        _in_nonlinear = False
        result = ours(*args, method="rk4", substeps=substeps, **kwargs)
        if COMPARE:
            _compare(original, result, args, kwargs, _in_nonlinear)
        return result

    call.__name__ = call.__qualname__ = name
    call.__doc__ = original.__doc__
    call.__wrapped__ = original
    return call


def pytest_configure(config):
    # control's rss draws from numpy's legacy global generator: seed that one
    np.random.seed(0)  # noqa: NPY002  (systems drawn while collecting)
    qc_response._nonlinear_response = _record_nonlinear(qc_response._nonlinear_response)
    for name in _ORIGINAL:
        routed = _routed(name)
        setattr(control, name, routed)
        setattr(ct_timeresp, name, routed)


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    # python-control's tests draw random systems (ct.rss) from numpy's global
    # generator; a seed per test makes every run use the same systems.
    np.random.seed(zlib.crc32(item.nodeid.encode()))  # noqa: NPY002


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    global _current
    _current = item.nodeid
    yield
    _current = None


def pytest_runtest_logreport(report):
    if report.failed:
        outcomes[report.nodeid] = "failed"
    elif report.skipped and hasattr(report, "wasxfail"):
        outcomes.setdefault(report.nodeid, "xfailed")
    elif report.skipped:
        outcomes.setdefault(report.nodeid, "skipped")
    elif report.when == "call":
        outcomes.setdefault(report.nodeid, "passed")


def pytest_sessionfinish(session, exitstatus):
    if REPORT:
        with open(REPORT, "w", encoding="utf-8") as f:
            json.dump(
                {
                    "mode": MODE,
                    "scope": SCOPE,
                    "h_lambda": H_LAMBDA,
                    "called": sorted(called),
                    "outcomes": outcomes,
                    "nonlinear": sorted(nonlinear),
                    "relative_difference": errors,
                    "relative_difference_nonlinear": errors_nonlinear,
                },
                f,
                indent=0,
            )
