"""The one exact reference (qc_control.numerics.reference) against closed forms."""

import numpy as np
import pytest
import scipy.linalg

import qc_control as qc
from qc_control.numerics.reference import exact_response, rest_state


def test_the_free_response_is_the_matrix_exponential():
    """x(t) = e^{At} x0 for every t, to 1e-12 m (both are exponentials of A t)."""
    sys = qc.quarter_car()
    T = np.linspace(0.0, 2.0, 201)
    X0 = np.array([0.0, 0.0, 0.05, 0.0])
    r = exact_response(sys, T, X0)
    expected = np.stack([scipy.linalg.expm(sys.A * t) @ X0 for t in T], axis=1)
    np.testing.assert_allclose(r.states, expected, atol=1e-12)


def test_at_rest_the_car_stays_still_under_a_constant_input():
    """Under a constant road height u, x0 = -A⁻¹ B u is an equilibrium: the
    response stays at it (to rounding), and the body sits at the road's height."""
    sys = qc.quarter_car(road=True)
    T = np.linspace(0.0, 1.0, 101)
    U = np.full((1, T.size), 0.03)
    r = exact_response(sys, T, U=U, at_rest=True)
    x0 = rest_state(sys.A, sys.B, U[:, 0])
    np.testing.assert_allclose(sys.A @ x0 + sys.B @ U[:, 0], 0.0, atol=1e-9)
    np.testing.assert_allclose(r.states, np.repeat(x0[:, None], T.size, axis=1), atol=1e-12)


def test_at_rest_and_an_initial_state_exclude_each_other():
    sys = qc.quarter_car(road=True)
    T = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ValueError, match="X0 or at_rest"):
        exact_response(sys, T, np.zeros(4), np.zeros((1, 11)), at_rest=True)
    with pytest.raises(ValueError, match="needs the inputs U"):
        exact_response(sys, T, at_rest=True)


def test_the_modal_outputs_are_python_controls_exact_response():
    """exact_output_samples (the modal recurrence) against control.forced_response
    under a road step on 20,001 samples: within 1e-12 m (both are exact for an
    input linear between samples; rounding of a 5 cm response)."""
    sys = qc.quarter_car(road=True)
    T = np.linspace(0.0, 10.0, 20001)
    U = np.where(T >= 0.5, 0.05, 0.0)[None, :]
    X0 = np.array([0.0, 0.1, 0.0, 0.0])
    from qc_control.numerics.reference import exact_output_samples

    expected = np.asarray(exact_response(sys, T, X0, U).outputs)
    np.testing.assert_allclose(exact_output_samples(sys, T, X0, U), expected, rtol=0, atol=1e-12)
