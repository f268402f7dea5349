"""The one step policy: how large a step is, and how many fit an interval.

Every place that chooses a step asks here, so the responses, the studies,
the controller study and a `Scenario` agree on it:

* `auto_step` — the step an automatic grid allows a method on a system's
  eigenvalues (an accuracy rule and a stability rule);
* `substeps_for` — the fewest equal steps that split an interval into steps
  no longer than a bound;
* `auto_substeps` — the two together: "the automatic step, then substeps",
  for an interval of the output grid;
* `whole_steps` — whether a step divides a span (a grid spacing, an end
  time) into a whole number of steps, and how many;
* `whole_step` — the step nearest a wish that does divide a span;
* `preferred_step` — the largest step of the 1-2-5 series (…, 1, 2, 5,
  10 ms, …) below a limit, the default step a person would write.

None of them knows a vehicle: they read a tableau and numbers.
"""

from __future__ import annotations

import math

import numpy as np

from .checks import positive
from .methods import ButcherTableau, get_method
from .stability import max_stable_step, stability_coefficients

__all__ = [
    "AUTO_STEP_LOCAL_ERROR",
    "AUTO_STEP_STABILITY_FRACTION",
    "WHOLE_STEPS_RTOL",
    "auto_step",
    "auto_substeps",
    "preferred_step",
    "substeps_for",
    "whole_step",
    "whole_steps",
]

#: Local error per step that the automatic step allows: RK4's at h|λ| = 0.1,
#: ``0.1**5 / 5!`` (see `auto_step`).
AUTO_STEP_LOCAL_ERROR = 0.1**5 / math.factorial(5)

#: The automatic step is at most this fraction of the stability limit.
AUTO_STEP_STABILITY_FRACTION = 0.5

#: `substeps_for` counts an interval ``H`` within this fraction of a whole
#: number of steps as that number: ``0.1 / 0.001`` is 100.00000000000001 in
#: binary floating point, and must give 100 steps, not 101.
SUBSTEP_SLACK = 1e-12

#: `whole_steps` accepts ``k`` steps of ``h`` as a span ``S`` when
#: ``|k h - S| <= WHOLE_STEPS_RTOL · S``: far above the rounding of a step
#: typed in decimal (``1e-16`` relative), far below any step a person means
#: to differ (a grid 1e-9 s off over 1 s ends within a nanosecond).
WHOLE_STEPS_RTOL = 1e-9

#: The mantissas of the 1-2-5 series, largest first (`preferred_step`).
_SERIES = (5, 2, 1)


def _error_constant(tab: ButcherTableau) -> tuple[int, float]:
    """``(p, C)`` with ``R(z) - e^z = -C z^{p+1} + O(z^{p+2})`` on the method's R."""
    coef = stability_coefficients(tab)
    p = 0
    while p + 1 < coef.size and abs(coef[p + 1] * math.factorial(p + 1) - 1) <= 1e-12:
        p += 1
    r_next = coef[p + 1] if p + 1 < coef.size else 0.0
    return p, abs(r_next - 1 / math.factorial(p + 1))


def auto_step(method, eigenvalues) -> tuple[float, str]:
    """The step the automatic time grid allows for ``method``, and why.

    Two rules; the step is the smaller:

    * **accuracy** — the local error of one step on the fastest mode is at
      most RK4's at ``h|λ|max = 0.1``. On ``x' = λx`` one step multiplies
      by ``R(hλ)`` instead of ``e^{hλ}``, so the local error is
      ``|R(z) - e^z| ≈ C |z|^{p+1}`` with ``z = hλ``, ``p`` the order and
      ``C`` the error constant (Hairer, Nørsett & Wanner, *Solving ODEs I*,
      §II.3; for the stability function, Hairer & Wanner, *Solving ODEs
      II*, §IV.2: ``R(z) = e^z + O(z^{p+1})``). Setting
      ``C |z|^{p+1} = 0.1⁵/5! ≈ 8.3e-8`` gives

      .. math:: h\\,|\\lambda|_{max} \\le \\Big(\\frac{0.1^5/5!}{C}\\Big)^{1/(p+1)}

      which is 0.1 for RK4 (``C = 1/120``), 7.9e-3 for Midpoint and Heun
      (``C = 1/6``) and 4.1e-4 for Euler (``C = 1/2``). ``p`` and ``C`` are
      read from the tableau's stability polynomial, so a user's tableau
      gets its own bound.
    * **stability** — at most half the method's stability limit
      (`qc_control.max_stable_step`). When no step is stable (an undamped
      mode under Euler, Midpoint or Heun) this rule is dropped, and the
      response reports the growth (``success`` False).

    The local error per step is then the same for every method; the global
    error, about ``(t/h)`` local errors, is not. On the seed vehicle released
    from 5 cm, over python-control's own grid (14.95 s), the states differ
    from the exact response by 7.1e-7 (RK4), 2.0e-5 (Midpoint, Heun) and
    3.7e-4 (Euler) of their largest value.

    Parameters
    ----------
    method : str or ButcherTableau
    eigenvalues : array_like
        The continuous-time system's eigenvalues [1/s].

    Returns
    -------
    h : float
        ``inf`` when neither rule bounds the step (every eigenvalue is 0).
    rule : str
        Which rule set ``h``, in words.

    Examples
    --------
    >>> h, rule = auto_step("rk4", [-1.0 + 10j, -1.0 - 10j])
    >>> round(h * abs(-1 + 10j), 6), rule.split(":")[0]
    (0.1, 'accuracy')
    """
    tab = get_method(method)
    lam = np.atleast_1d(np.asarray(eigenvalues, dtype=complex))
    p, C = _error_constant(tab)
    rho = (AUTO_STEP_LOCAL_ERROR / C) ** (1 / (p + 1)) if C > 0 else math.inf
    lam_max = float(np.max(np.abs(lam))) if lam.size else 0.0
    h_acc = rho / lam_max if lam_max > 0 else math.inf
    h_lim = max_stable_step(tab, lam) if lam_max > 0 else math.inf
    h_stab = AUTO_STEP_STABILITY_FRACTION * h_lim if h_lim > 0 else math.inf
    if h_acc <= h_stab:
        if not math.isfinite(h_acc):
            return math.inf, "none: every eigenvalue is 0, the grid's own spacing is used"
        return h_acc, (
            f"accuracy: h·|λ|max = {rho:.3g} for {tab.name} (order {p}, local error "
            f"{AUTO_STEP_LOCAL_ERROR:.2g} per step on the fastest mode, |λ|max = {lam_max:.4g} 1/s)"
        )
    return h_stab, (
        f"stability: half of {tab.name}'s stability limit {h_lim:.4g} s "
        f"(the accuracy rule allowed {h_acc:.4g} s)"
    )


def substeps_for(H: float, h: float) -> int:
    """The fewest equal steps, at least 1, that split an interval ``H`` into steps ``<= h``.

    .. math:: k = \\max\\big(1, \\lceil (H / h)(1 - 10^{-12}) \\rceil\\big)

    so that ``H / k <= h`` (to rounding): an ``H`` that is ``h`` times an
    integer up to rounding (``0.1 / 0.001``) gives that integer, not one
    more (`SUBSTEP_SLACK`). ``h = inf`` (no bound) gives 1.

    Examples
    --------
    >>> substeps_for(0.01, 0.001), substeps_for(0.01, 0.003)
    (10, 4)
    """
    return max(1, math.ceil(H / h * (1 - SUBSTEP_SLACK)))


def auto_substeps(method, eigenvalues, H: float, substeps: int = 1) -> tuple[int, str]:
    """Substeps of an output interval ``H`` [s] for `auto_step`'s step, and why.

    The automatic grid keeps python-control's output times and refines the
    step inside each interval instead: the fewest substeps (never fewer
    than ``substeps``, what the caller asked) whose step ``H / k`` meets
    `auto_step`'s rule on ``eigenvalues``, ``k = substeps_for(H, h_rule)``.
    The linear responses, `input_output_response` (on the linearisation at
    the initial point) and the controller study all choose their step so.

    Returns
    -------
    substeps : int
    rule : str
        `auto_step`'s words for the rule that set the step.

    Examples
    --------
    RK4 on a mode of 10 rad/s allows ``h = 0.01`` s: an interval of 0.05 s
    takes 5 substeps.

    >>> auto_substeps("rk4", [10j, -10j], 0.05)[0]
    5
    """
    h_rule, rule = auto_step(method, eigenvalues)
    if math.isfinite(h_rule):
        substeps = max(substeps, substeps_for(H, h_rule))
    return substeps, rule


def whole_steps(span: float, h: float, *, at_least: int = 1) -> int | None:
    """How many steps ``h`` make up ``span``, if a whole number (``>= at_least``), else None.

    .. math:: k = \\operatorname{round}(S / h), \\qquad |k h - S| \\le 10^{-9} S

    (`WHOLE_STEPS_RTOL`): a step given in decimal that divides the span up
    to its rounding counts, one a millionth off does not. A step must divide
    a grid's spacing to be its substep (a method comparison at ``h``), and
    an end time to be a `Scenario`'s grid (``at_least=2``: a grid of one
    step has no interior sample).

    Examples
    --------
    >>> whole_steps(10.0, 0.001), whole_steps(10.0, 0.003), whole_steps(0.01, 0.01, at_least=2)
    (10000, None, None)
    """
    if not (h > 0 and span > 0 and math.isfinite(span / h)):
        return None
    k = round(span / h)
    if k < at_least or abs(k * h - span) > WHOLE_STEPS_RTOL * span:
        return None
    return int(k)


def whole_step(span: float, h: float, *, at_least: int = 2) -> float:
    """The step nearest ``h`` that divides ``span`` into a whole number (``>= at_least``)
    of steps: ``span / max(at_least, round(span / h))``.

    A `Scenario` needs its end time to be whole steps (`whole_steps`); the
    explorer's slider moves a step a person chose to the nearest such one.

    Examples
    --------
    >>> whole_step(10.0, 0.0198), whole_step(10.0, 0.001)
    (0.019801980198019802, 0.001)
    """
    return span / max(at_least, round(span / h))


def preferred_step(limit: float) -> float:
    """The largest step of the 1-2-5 series (…, 1, 2, 5, 10 ms, …) not above ``limit`` [s].

    .. math:: h = \\max\\{m \\cdot 10^e \\le \\text{limit} : m \\in \\{1, 2, 5\\}\\}

    A default step lowered below a limit (the road's, a method's stability
    limit) is one a person would have typed, so it is written in reports
    and TOML as ``0.002``, not ``0.0017316``. The series steps by about
    ``10^{1/3}`` (the one oscilloscope time bases use), so the step is
    within a factor 2.5 of the limit.

    Raises
    ------
    ParameterError
        When ``limit`` is not a finite number > 0 s.

    Examples
    --------
    >>> preferred_step(0.0173), preferred_step(0.005), preferred_step(0.0049)
    (0.01, 0.005, 0.002)
    """
    limit = positive("limit", limit, "s")
    e = math.floor(math.log10(limit))
    for exponent in (e + 1, e, e - 1):
        for mantissa in _SERIES:
            # written in decimal, so the step is the double nearest "2e-3", as typed
            step = float(f"{mantissa}e{exponent}")
            if step <= limit:
                return step
    raise AssertionError(f"no 1-2-5 step below {limit!r}")  # pragma: no cover
