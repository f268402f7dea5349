"""The one step policy (`qc_control.numerics.steps`) against closed forms.

Each rule is checked on numbers whose answer is known without the code: a
step that divides 10 s into whole steps, the fewest substeps with
``H / k <= h``, the 1-2-5 series, and the automatic step's local error on
the method's own stability function ``R(z)``.
"""

import math
import warnings

import numpy as np
import pytest

import qc_control as qc
from qc_control.numerics import steps
from qc_control.numerics.checks import ParameterError


@pytest.mark.parametrize(
    "method, C, p",
    [("rk4", 1 / 120, 4), ("midpoint", 1 / 6, 2), ("heun", 1 / 6, 2), ("euler", 0.5, 1)],
)
def test_auto_step_accuracy_rule(method, C, p):
    """h|λ|max = (ε/C)^(1/(p+1)), ε = 0.1⁵/5!: the local error per step is ε.

    Checked on R(z) itself: at z = -h|λ|max the local error |R(z) - e^z|
    equals ε to within its next Taylor term (≤ 2% at RK4's z = -0.1).
    """
    lam = np.array([-3 + 40j, -3 - 40j, -0.5])
    h, rule = steps.auto_step(method, lam)
    rho = (steps.AUTO_STEP_LOCAL_ERROR / C) ** (1 / (p + 1))
    assert h * abs(lam[0]) == pytest.approx(rho, rel=1e-12)
    assert rule.startswith("accuracy")
    z = -h * abs(lam[0])
    local = abs(qc.stability_function(method)(z) - math.exp(z))
    assert local == pytest.approx(steps.AUTO_STEP_LOCAL_ERROR, rel=0.02)
    assert {"rk4": 0.1, "midpoint": 7.94e-3, "heun": 7.94e-3, "euler": 4.08e-4}[method] == (
        pytest.approx(rho, rel=1e-3)
    )


def test_auto_step_stability_rule_and_edge_cases():
    # Euler on a mode damped at zeta = 1e-5 is stable only below 2 zeta/|λ|:
    # half of that is far below the accuracy rule's 4.1e-4/|λ|
    zeta, w = 1e-5, 10.0
    lam = w * np.array([-zeta + 1j * math.sqrt(1 - zeta**2), -zeta - 1j * math.sqrt(1 - zeta**2)])
    h, rule = steps.auto_step("euler", lam)
    assert h == pytest.approx(0.5 * qc.max_stable_step("euler", lam), rel=1e-12)
    assert h == pytest.approx(zeta / w, rel=1e-6) and rule.startswith("stability")
    # an undamped mode under Heun: no step is stable, the accuracy rule alone decides
    assert steps.auto_step("heun", [1j, -1j])[1].startswith("accuracy")
    # only integrators: nothing bounds the step
    assert steps.auto_step("rk4", [0.0, 0.0])[0] == math.inf


def test_the_substep_rule():
    """An interval that holds h an integer number of times up to rounding: that many steps."""
    assert steps.substeps_for(0.1, 0.001) == 100  # 0.1 / 0.001 = 100.00000000000001
    assert steps.substeps_for(0.01, 0.003) == 4
    assert steps.substeps_for(0.001, 0.01) == 1
    assert steps.substeps_for(0.01, math.inf) == 1  # no bound: the interval is one step


def test_substeps_are_the_fewest_with_H_over_k_at_most_h():
    """k = ceil(H/h): H/k <= h, and one step fewer would be longer than h."""
    rng = np.random.default_rng(7)
    for H, h in zip(10 ** rng.uniform(-4, 1, 200), 10 ** rng.uniform(-5, 0, 200)):
        k = steps.substeps_for(float(H), float(h))
        assert H / k <= h * (1 + 1e-12)  # the slack that absorbs rounding of H/h
        assert k == 1 or H / (k - 1) > h
    # n steps of a decimal step, n * h rounded, is n steps again (not n + 1)
    assert all(steps.substeps_for(n * 0.001, 0.001) == n for n in range(1, 2001))


def test_auto_substeps_splits_an_interval_to_the_automatic_step():
    """RK4 on ±10j rad/s: accuracy allows h = 0.1 / 10 = 0.01 s (its stability
    limit 2.83/10 s is far above), so a 0.05 s interval takes 5 substeps; a
    caller's larger count stands; no eigenvalue bounds nothing."""
    lam = [10j, -10j]
    assert steps.auto_step("rk4", lam)[0] == pytest.approx(0.01, rel=1e-12)
    assert steps.auto_substeps("rk4", lam, 0.05) == (5, steps.auto_step("rk4", lam)[1])
    assert steps.auto_substeps("rk4", lam, 0.05, substeps=7)[0] == 7
    assert steps.auto_substeps("rk4", [0.0], 0.05, substeps=3)[0] == 3


def test_whole_steps_of_ten_seconds():
    """10 s is 10000 steps of 1 ms, 500 of 0.02 s and 3 of 10/3 s; 0.003 s and
    0.0198 s divide it into no whole number; at_least=2 refuses one step."""
    assert steps.whole_steps(10.0, 0.001) == 10000
    assert steps.whole_steps(10.0, 0.02) == 500
    assert steps.whole_steps(10.0, 10 / 3) == 3
    assert steps.whole_steps(10.0, 0.003) is None
    assert steps.whole_steps(10.0, 0.0198) is None
    assert steps.whole_steps(10.0, 10.0) == 1
    assert steps.whole_steps(10.0, 10.0, at_least=2) is None
    assert steps.whole_steps(10.0, 20.0) is None  # half a step
    # within 1e-9 relative counts (rounding of a decimal step), 1e-6 does not
    assert steps.whole_steps(10.0, 0.001 * (1 + 1e-12)) == 10000
    assert steps.whole_steps(10.0, 0.001 * (1 + 1e-6)) is None
    assert steps.whole_steps(10.0, 0.0) is None and steps.whole_steps(10.0, math.inf) is None


def test_whole_step_is_the_nearest_dividing_step():
    """10 / round(10 / 0.0198) = 10 / 505; a step that divides is kept; never
    fewer than two steps."""
    assert steps.whole_step(10.0, 0.0198) == 10.0 / 505
    assert steps.whole_steps(10.0, steps.whole_step(10.0, 0.0198)) == 505
    assert steps.whole_step(10.0, 0.001) == 0.001
    assert steps.whole_step(10.0, 7.0) == 5.0


def test_the_one_two_five_series():
    """The largest of 1, 2, 5 times a power of ten not above the limit."""
    assert steps.preferred_step(0.0173) == 0.01
    assert steps.preferred_step(0.005) == 0.005  # a series value is its own step
    assert steps.preferred_step(0.0049) == 0.002
    assert steps.preferred_step(0.0199) == 0.01
    assert steps.preferred_step(3e-7) == 2e-7
    series = sorted(m * 10.0**e for e in range(-9, 3) for m in (1, 2, 5))
    for limit in 10 ** np.linspace(-8, 1.5, 301):
        step = steps.preferred_step(float(limit))
        below = [s for s in series if s <= limit * (1 + 1e-15)]
        assert step == pytest.approx(below[-1], rel=1e-15)
        assert limit / 2.5 <= step <= limit
    for bad in (0.0, -1e-3, math.inf, math.nan, "0.01"):
        with pytest.raises(ParameterError) as err:
            steps.preferred_step(bad)
        assert err.value.name == "limit"


def test_the_old_homes_still_answer():
    """``substeps_for`` lived in `numerics.stepper` (now warns, naming the new
    place); `responses.timeresp` re-exports the automatic step."""
    from qc_control.numerics import stepper
    from qc_control.responses import timeresp

    with pytest.warns(DeprecationWarning, match=r"qc_control\.numerics\.steps\.substeps_for"):
        old = stepper.substeps_for
    assert old is steps.substeps_for
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert timeresp.auto_step is steps.auto_step
        assert timeresp.AUTO_STEP_LOCAL_ERROR == steps.AUTO_STEP_LOCAL_ERROR
    with pytest.raises(AttributeError):
        stepper.no_such_name  # noqa: B018
