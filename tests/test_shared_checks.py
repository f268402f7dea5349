"""One test of nonlinearity per meaning, and one check of X0 and U for the
responses and the sweep."""

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control.numerics.lti import is_nonlinear_system

T = np.linspace(0.0, 2.0, 2001)  # h = 1 ms
RELEASE = [0.0, 0.0, 0.05, 0.0]


def _decay(t, x, u, params):
    return -x


def _saturate(t, x, u, params):
    return -x + np.clip(u, -1.0, 1.0)


SATURATING = control.nlsys(_saturate, None, inputs=1, outputs=1, states=1)


@pytest.mark.parametrize(
    "system, nonlinear",
    [
        (control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]), False),
        (control.tf([1.0], [1.0, 1.0]), False),
        (qc.quarter_car(), False),
        (control.nlsys(_decay, None, states=1), True),
        (qc.nonlinear_quarter_car(), True),
        # python-control 0.10 makes StateSpace a subclass of NonlinearIOSystem:
        # the class, not the base, says which a system is; a series of a linear
        # and a nonlinear part is an InterconnectedSystem, nonlinear
        (control.ss(-1.0, 1.0, 1.0, 0.0) * SATURATING, True),
    ],
)
def test_a_system_is_nonlinear_when_python_control_steps_its_right_hand_side(system, nonlinear):
    assert is_nonlinear_system(system) is nonlinear


def test_a_model_is_nonlinear_when_its_system_is_or_it_has_batch_dynamics():
    assert not qc.quarter_car_model().is_nonlinear
    assert qc.nonlinear_quarter_car_model().is_nonlinear
    # a callable force law that does not vectorise: no batch dynamics, still nonlinear
    scalar_only = qc.nonlinear_quarter_car_model(spring=lambda d: 2e4 * d if d > 0 else 1e4 * d)
    assert scalar_only.batch_dynamics is None and scalar_only.is_nonlinear


@pytest.mark.parametrize("bad", [[0.0, 0.05], [0.0, 0.0, np.nan, 0.0], [1j, 0.0, 0.0, 0.0]])
def test_the_sweep_and_the_responses_refuse_a_bad_x0_in_the_same_words(bad):
    with pytest.raises(ValueError) as response:
        qc.initial_response(qc.quarter_car(), T, bad)
    with pytest.raises(ValueError) as swept:
        qc.sweep([qc.QuarterCarParams()], T, bad, progress=False)
    assert str(swept.value) == str(response.value)


@pytest.mark.parametrize("bad", [np.zeros(5), np.full(T.size, np.inf), np.zeros((2, T.size))])
def test_the_sweep_and_the_responses_refuse_a_bad_u_in_the_same_words(bad):
    with pytest.raises(ValueError) as response:
        qc.forced_response(qc.quarter_car(road=True), T, bad, np.zeros(4))
    with pytest.raises(ValueError) as swept:
        qc.sweep([qc.QuarterCarParams()], T, np.zeros(4), U=bad, progress=False)
    assert str(swept.value) == str(response.value)


@pytest.mark.parametrize("X0", [RELEASE, [[v] for v in RELEASE], 0.05])
def test_the_sweep_takes_x0_in_the_shapes_python_control_takes(X0):
    exact = control.initial_response(qc.quarter_car(), T, X0, return_x=True)
    swept = qc.sweep([qc.QuarterCarParams()], T, X0, states=True, progress=False)
    # RK4 at h = 1 ms (h|λ|max = 0.025) against the matrix exponential: measured
    # 2e-9 m; 1e-8 m (2e-7 of the 5 cm release) leaves room for other BLAS builds
    np.testing.assert_allclose(swept.states[0], exact.states, rtol=0, atol=1e-8)
