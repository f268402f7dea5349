"""The exact reference every study measures a method against.

For a linear system ``x' = A x + B u`` with the input linear between samples,
python-control's ``initial_response`` and ``forced_response`` are exact to
rounding (the matrix exponential of the augmented matrix, Franklin, Powell &
Workman, *Digital Control of Dynamic Systems*, 3rd ed., §6.3). Every error a
study, a report or an exercise quotes is a distance to this response, so it
is computed here, one way, for all of them.

On long grids (a check of a cost under a road input is solved on a grid of
up to 200,000 samples) `exact_output_samples` gives the same outputs by the
modal recurrence of `qc_control.numerics.exact`, in milliseconds instead of
python-control's second (tests/test_reference.py holds the two to 1e-12).

A run "at rest" starts where the car sits still under its first input
sample: ``x' = 0 = A x_0 + B u_0``, so ``x_0 = -A⁻¹ B u_0`` (`rest_state`),
as a rig record starts.
"""

from __future__ import annotations

import control
import numpy as np

from .exact import exact_outputs

__all__ = ["exact_response", "exact_output_samples", "rest_state"]


def rest_state(A, B, u0) -> np.ndarray:
    """``x_0 = -A⁻¹ B u_0``: the state at rest under the constant input ``u0``.

    Parameters
    ----------
    A : array_like, shape (n, n)
        Nonsingular (a car with springs to the ground).
    B : array_like, shape (n, m)
    u0 : array_like, shape (m,)

    Examples
    --------
    >>> rest_state([[-1.0]], [[2.0]], [0.5])
    array([1.])
    """
    A, B = np.asarray(A, dtype=float), np.asarray(B, dtype=float)
    return -np.linalg.solve(A, B @ np.asarray(u0, dtype=float).reshape(-1))


def exact_response(sys, T, X0=None, U=None, *, at_rest: bool = False) -> control.TimeResponseData:
    """python-control's exact response of ``sys`` on the grid ``T``.

    Parameters
    ----------
    sys : control.StateSpace
    T : array_like
        A uniform time grid [s] (python-control's exact solver needs one).
    X0 : array_like, optional
        The initial state (zeros by default); not given with ``at_rest``.
    U : array_like, optional
        The inputs at ``T``, shape ``(ninputs, len(T))``, linear between
        samples; None: the free response (``control.initial_response``).
    at_rest : bool
        Start at rest under the first input sample (`rest_state`).

    Returns
    -------
    control.TimeResponseData
        With the states.
    """
    if at_rest:
        if X0 is not None:
            raise ValueError("give X0 or at_rest=True, not both")
        if U is None:
            raise ValueError("at_rest=True needs the inputs U: it is the rest under U[:, 0]")
        U = np.asarray(U, dtype=float).reshape(sys.ninputs, -1)
        X0 = rest_state(sys.A, sys.B, U[:, 0])
    X0 = np.zeros(sys.nstates) if X0 is None else X0
    if U is None:
        return control.initial_response(sys, T, X0)
    return control.forced_response(sys, T, U, X0)


def exact_output_samples(sys, T, X0, U) -> np.ndarray:
    """The outputs of `exact_response` under an input, by the modal recurrence.

    Parameters
    ----------
    sys : control.StateSpace
    T : array_like
        A uniform grid [s].
    X0 : array_like
    U : array_like, shape (ninputs, len(T))
        Linear between samples.

    Returns
    -------
    ndarray, shape (noutputs, len(T))
    """
    T = np.asarray(T, dtype=float)
    U = np.asarray(U, dtype=float).reshape(sys.ninputs, -1)
    H = (T[-1] - T[0]) / (T.size - 1)
    return exact_outputs(sys.A, sys.B, sys.C, sys.D, H, U, np.asarray(X0, dtype=float))
