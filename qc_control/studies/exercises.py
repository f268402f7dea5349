"""The course notebook's exercise checks, with their expected values hidden.

Each check accepts the right answer within the accuracy the route the
exercise gives can reach, refuses the common wrong answers with a hint that
names the mistake, and answers a wrong type with the form it expects. The
expected values are computed here, from the seed's car, so that the
notebook's check cells show no formula to copy.

`check` prints one line, ``Exercise N: correct``, ``Exercise N: not yet.
<hint>`` or ``Exercise N: not answered yet``, and returns True, False or None.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from numbers import Real

import numpy as np

from ..models.quarter import QuarterCarParams, quarter_car
from ..numerics.reference import exact_response
from ..responses.timeresp import initial_response
from ..ride.comfort import ride_metrics_spectral
from ..ride.road import ISO8608Road

__all__ = ["EXERCISES", "Exercise", "check"]

#: The notebook's free response: the body released 5 cm up, over 10 s.
_X0 = (0.0, 0.0, 0.05, 0.0)
_SPAN = 10.0
#: Exercise 6's accuracy target on the body displacement, in metres.
_TARGET = 1e-3
#: Exercise 5's grid of nominal damping ratios and road.
_ZETAS = np.round(np.arange(0.10, 1.01, 0.05), 2)
_ROAD = ISO8608Road("C", speed=20.0)
#: Exercise 5 accepts a ratio whose Wk RMS is within this fraction of the
#: lowest: 0.3 % is one pixel of Section 5's plot (its axis spans about 0.38
#: m/s² over about 250 px), so anything a student can tell apart on the plot
#: from the minimum is refused, and what the plot cannot is accepted.
_COMFORT_PLATEAU = 0.003
#: Exercise 6 accepts a step from this fraction of the largest RK4 step that
#: reaches 1 mm up to that step: within 10 % of the least cost.
_STEP_SLACK = 0.9


class _WrongType(Exception):
    """The answer is not of the form the exercise asks for."""


@dataclass(frozen=True)
class Exercise:
    """One exercise: its question, the route to its answer, and its judge.

    Attributes
    ----------
    number : int
    question : str
        What is asked, with units.
    route : str
        How a student reaches the answer, and so the accuracy accepted.
    judge : callable
        ``judge(answer) -> str | None``: None when right, else the hint.
    """

    number: int
    question: str
    route: str
    judge: Callable[[object], str | None]


def _seed_eigenvalues() -> np.ndarray:
    return np.linalg.eigvals(quarter_car(QuarterCarParams()).A)


def _upper_modes() -> tuple[complex, complex]:
    """The body-bounce and wheel-hop eigenvalues (upper half plane), by frequency."""
    lam = _seed_eigenvalues()
    body, wheel = sorted(lam[lam.imag > 0], key=abs)
    return complex(body), complex(wheel)


def _number(answer, form: str = "one number (a float)") -> float:
    if isinstance(answer, bool) or not isinstance(answer, Real | np.number | np.ndarray):
        raise _WrongType(f"give {form}, not a {type(answer).__name__}.")
    array = np.asarray(answer, dtype=float)
    if array.size != 1:
        raise _WrongType(f"give {form}, not an array of {array.size} values.")
    value = float(array.reshape(()))
    if not math.isfinite(value):
        raise _WrongType(f"give a finite number, not {value}.")
    return value


def _near(value: float, target: float, rel: float) -> bool:
    return abs(value - target) <= rel * abs(target)


def _nominal_zeta() -> float:
    """The seed's nominal damping ratio cs / (2·√(ks·ms)), which assumes a rigid tire."""
    p = QuarterCarParams()
    cs = float(p.cs) if p.cs is not None else math.nan  # resolved from ζ when made
    return cs / (2 * math.sqrt(p.ks * p.ms))


def _first_hint(value: float, wrong: list[tuple[float, float, str]]) -> str | None:
    """The hint of the first listed wrong answer ``(value, rel, hint)`` that matches."""
    for target, rel, hint in wrong:
        if _near(value, target, rel):
            return hint
    return None


def _judge_1(answer) -> str | None:
    # |λ|/2π, read from modal_analysis (4 digits) or the eigenvalues: both
    # land within 0.01 %. The damped frequency Im λ/2π is 0.23 % lower, so
    # the tolerance of 0.1 % separates them.
    value = _number(answer)
    body, wheel = _upper_modes()
    if _near(value, abs(body) / (2 * math.pi), 1e-3):
        return None
    p = QuarterCarParams()
    wrong = [
        (body.imag / (2 * math.pi), 1e-3, "that is the damped frequency Im λ/2π; asked is |λ|/2π."),
        (
            math.sqrt(p.ks / p.ms) / (2 * math.pi),
            2e-3,
            "that is √(ks/ms)/2π, which ignores the tire; asked is the mode's |λ|/2π.",
        ),
        (abs(body), 1e-2, "that is in rad/s; divide by 2π for Hz."),
        (abs(wheel) / (2 * math.pi), 1e-2, "that is the wheel-hop mode; the body bounces slower."),
    ]
    return (
        _first_hint(value, wrong)
        or "Which mode has the lower frequency? qc.modal_analysis names them."
    )


def _euler_limits() -> np.ndarray:
    # |1 + hλ| ≤ 1  ⇔  h ≤ −2·Re λ / |λ|², one bound per eigenvalue pair
    lam = np.array(_upper_modes())
    return -2 * lam.real / np.abs(lam) ** 2


def _judge_2(answer) -> str | None:
    # A closed form or qc.max_stable_step: both exact to rounding, and the
    # notebook prints five digits (0.01982). 0.2 % accepts that and refuses
    # the guess 0.02 s, 0.9 % above the limit.
    value = _number(answer)
    limits = _euler_limits()
    if _near(value, limits.min(), 2e-3):
        return None
    wrong = [
        (limits.max(), 1e-2, "that is the limit of the other mode; every mode must be stable."),
        (
            2 / abs(_upper_modes()[1]),
            1e-2,
            "2/|λ| holds on the real axis only; these λ are complex.",
        ),
    ]
    return _first_hint(value, wrong) or (
        "|1 + hλ|² = 1 has one root h > 0 per eigenvalue; the smallest one limits."
    )


def _heun_error(h: float) -> float:
    sys = quarter_car(QuarterCarParams())
    T = np.linspace(0.0, _SPAN, round(_SPAN / h) + 1)
    run = initial_response(sys, T, _X0, method="heun")
    exact = exact_response(sys, T, _X0)
    xs = list(sys.output_labels).index("xs")
    return float(np.max(np.abs(np.asarray(run.outputs)[xs] - np.asarray(exact.outputs)[xs])))


@functools.cache
def _heun_errors() -> tuple[float, float]:
    return _heun_error(0.01), _heun_error(0.005)


def _pair(answer, form: str) -> tuple:
    if isinstance(answer, str) or not isinstance(answer, tuple | list) or len(answer) != 2:
        raise _WrongType(f"give a pair {form}.")
    return tuple(answer)


def _judge_3(answer) -> str | None:
    # The error is measured the same way by every route (same grid, same
    # exact response), so 1 % only absorbs a value copied from a print-out;
    # the order to ±0.01 is what two such errors give.
    form = "(error at h = 0.005 s in m, observed order), e.g. (1.2e-4, 1.5)"
    err, order = (_number(v, form) for v in _pair(answer, form))
    e_coarse, e_fine = _heun_errors()
    if not _near(err, e_fine, 1e-2):
        if _near(err, e_coarse, 1e-2):
            return "that error is the one at h = 0.01 s; asked is the one at h = 0.005 s."
        return (
            "the error is not yet right: use the same T grid for the method "
            "and for control.initial_response."
        )
    if abs(order - math.log2(e_coarse / e_fine)) > 0.01:
        return "the order is log2(e_0.01 / e_0.005), from your two measured errors."
    return None


def _euler_zeta_h(h: float = 0.01) -> float:
    body, _ = _upper_modes()
    lam_h = np.log(1 + h * body) / h  # the eigenvalue Euler's step sees
    return float(-lam_h.real / abs(lam_h))


def _judge_4(answer) -> str | None:
    # Closed form or qc.numerical_modes: exact to rounding; 1 % for copying.
    # The question asks "more or less than exact?" too: a pair (ζ_h, "less")
    # answers both, and ζ_h alone the first part.
    body, _ = _upper_modes()
    exact = -body.real / abs(body)
    if isinstance(answer, tuple | list):
        form = '(ζ_h, "less" or "more"), e.g. (0.2, "more")'
        value, word = _pair(answer, form)
        value = _number(value, form)
        if not isinstance(word, str) or word.strip().lower() not in ("less", "more"):
            raise _WrongType(f"give a pair {form}.")
        truth = "less" if _euler_zeta_h() < exact else "more"
        if _near(value, _euler_zeta_h(), 1e-2) and word.strip().lower() != truth:
            return f"ζ_h is right; compare it with the exact modal ζ = {exact:.4f} again."
        answer = value
    value = _number(answer)
    if _near(value, _euler_zeta_h(), 1e-2):
        return None
    wrong = [
        (exact, 1e-2, "that is the exact modal ζ; asked is the ζ_h Euler's step gives."),
        (
            _nominal_zeta(),
            1e-2,
            "that is the nominal ζ of the parameters; asked is Euler's ζ_h.",
        ),
    ]
    return _first_hint(value, wrong) or (
        "λ_h = ln R(hλ)/h, and ζ_h = −Re λ_h/|λ_h|; qc.numerical_modes has it too."
    )


def _wk_rms(zeta: float) -> float:
    metrics = ride_metrics_spectral(QuarterCarParams(zeta=zeta), _ROAD)
    return float(metrics[[k for k in metrics.index if "wk" in k.lower()][0]])


@functools.cache
def _lowest_wk_rms() -> float:
    return min(_wk_rms(z) for z in _ZETAS)


def _judge_5(answer) -> str | None:
    value = _number(answer)
    if not _ZETAS[0] <= value <= _ZETAS[-1]:
        return f"give one of the ratios {_ZETAS[0]:.2f}, {_ZETAS[1]:.2f}, …, {_ZETAS[-1]:.2f}."
    if _wk_rms(value) <= _lowest_wk_rms() * (1 + _COMFORT_PLATEAU):
        return None
    if _near(value, _nominal_zeta(), 1e-3):
        return "that is the seed's own damping ratio; find the lowest point of Section 5's curve."
    if _near(value, 1 / math.sqrt(2), 1e-2):
        return "1/√2 is the textbook optimum of a one-mass system; this car's curve says otherwise."
    return "Section 5 plots exactly this curve: which ratio gives its lowest point?"


def _rk4_error(steps: int) -> float:
    sys = quarter_car(QuarterCarParams())
    T = np.linspace(0.0, _SPAN, steps + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a trial step beyond the limit is part of the search
        run = initial_response(sys, T, _X0, method="rk4")
    exact = exact_response(sys, T, _X0)
    xs = list(sys.output_labels).index("xs")
    return float(np.max(np.abs(np.asarray(run.outputs)[xs] - np.asarray(exact.outputs)[xs])))


@functools.cache
def _rk4_fewest_steps() -> int:
    """The fewest RK4 steps over 10 s that keep the xs error within 1 mm (bisection)."""
    few, many = 1, 4096  # the error falls monotonically with the step in between
    while many - few > 1:
        mid = (few + many) // 2
        few, many = (few, mid) if _rk4_error(mid) <= _TARGET else (mid, many)
    return many


def _judge_6(answer) -> str | None:
    form = '(method name, step in s), e.g. ("euler", 0.001)'
    method, step = _pair(answer, form)
    if not isinstance(method, str):
        raise _WrongType(f"give a pair {form}; the method as a string.")
    step = _number(step, form)
    if method.lower() != "rk4":
        return (
            f"count {method}'s cost against the others': RHS evaluations = stages × steps "
            "at the largest step that reaches 1 mm."
        )
    if not 0 < step <= _SPAN:
        return f"give a step between 0 and {_SPAN:g} s."
    steps = round(_SPAN / step)
    error = _rk4_error(steps)
    if error > _TARGET:
        return f"at h = {step:g} s RK4's xs error is {error * 1e3:.2f} mm, over 1 mm."
    if _SPAN / steps < _STEP_SLACK * _SPAN / _rk4_fewest_steps():
        return (
            f"at h = {step:g} s RK4 reaches 1 mm, but a larger step does it for fewer evaluations."
        )
    return None


EXERCISES = {
    1: Exercise(
        1, "natural frequency |λ|/2π of body bounce [Hz]", "qc.modal_analysis or eigvals", _judge_1
    ),
    2: Exercise(
        2, "Euler's largest stable step [s]", "closed form or qc.max_stable_step", _judge_2
    ),
    3: Exercise(
        3, "Heun: (error at 0.005 s [m], order)", "two runs against the exact response", _judge_3
    ),
    4: Exercise(
        4, "Euler's ζ_h of body bounce at h = 0.01 s", "closed form or qc.numerical_modes", _judge_4
    ),
    5: Exercise(5, "ζ of lowest Wk RMS on class C at 20 m/s", "Section 5's curve", _judge_5),
    6: Exercise(6, "cheapest method to 1 mm, and its step [s]", "runs at trial steps", _judge_6),
}


def check(number: int, answer) -> bool | None:
    """Check the answer to one of the course notebook's exercises, and say so.

    Parameters
    ----------
    number : int
        The exercise's number, 1 to 6.
    answer : object
        The student's answer; None while not answered.

    Returns
    -------
    bool or None
        True when right, False when not (a hint is printed), None when
        ``answer`` is None.

    Raises
    ------
    ValueError
        If there is no exercise ``number``.
    """
    if number not in EXERCISES:
        raise ValueError(f"no exercise {number!r}; the exercises are {sorted(EXERCISES)}")
    name = f"Exercise {number}"
    if answer is None:
        print(f"{name}: not answered yet")
        return None
    try:
        hint = EXERCISES[number].judge(answer)
    except _WrongType as wrong:
        hint = str(wrong)
    print(f"{name}: correct" if hint is None else f"{name}: not yet. {hint}")
    return hint is None
