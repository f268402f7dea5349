"""The stage loop compiled (numba), for compiled right-hand sides over batches of designs.

`qc_control.numerics.stepper` steps a Python right-hand side; a batch of a
thousand designs written with NumPy costs a dozen NumPy calls per stage,
whose fixed cost (about a microsecond each) is most of the time. A model
that writes its right-hand side as a compiled loop over the designs
(``rhs(x, u, p, o, out)``, `qc_control.models.nlkernel` for the nonlinear
car) is stepped by `stage_loop` instead: the same step,

.. math::

    k_i = f\\big(x + \\textstyle\\sum_{j<i} h a_{ij} k_j,\\; u(t + c_i h)\\big),
    \\qquad x \\leftarrow x + \\textstyle\\sum_i h b_i k_i ,

with the inputs at the stage times given (the caller interpolates them,
`qc_control.numerics.sampled`), compiled together with the right-hand side.

A model binds the loop to its right-hand side in a function of its own::

    @compiled()
    def advance(x, out, first, count, step, substeps, a, b, stage_u, p, o):
        stage_loop(_rhs, x, out, first, count, step, substeps, a, b, stage_u, p, o)

`stage_loop` is inlined into that function (``inline="always"``), so the
right-hand side is a known function there, not a function-typed argument:
numba then caches the model's function on disk (`qc_control.numerics.recurrence.compiled`),
which it cannot do for a closure over a compiled function or a call
through a function argument.

numba is imported with this module; a model imports it only when a batch
is first stepped.
"""

from __future__ import annotations

import numpy as np

from .recurrence import compiled

__all__ = ["stage_loop"]


@compiled(inline="always")
def stage_loop(rhs, x, out, first, count, step, substeps, a, b, stage_u, p, o):  # pragma: no cover
    """Step the designs ``x`` ``(n, m)`` (in place) over ``count`` samples.

    Whole arrays and offsets, not slices, so that numba compiles one
    specialisation (a slice's layout would depend on where it falls).

    Parameters
    ----------
    rhs : compiled function ``rhs(x, u, p, o, out)``
        Writes ``dx/dt`` of every design at the states ``x`` ``(n, m)`` with
        the inputs ``u`` ``(k,)`` into ``out`` ``(n, m)``; ``p`` and ``o`` are
        the model's own data (per-design parameters, options).
    x : ndarray (n, m)
        The states at the first sample's start; on return, at the last one's end.
    out : ndarray (n, B, m)
        Written: ``out[:, first + l]`` is the state after sample ``l`` (``l < count``).
    first, count : int
    step : int
        The index in ``stage_u`` of the first step.
    substeps : int
        Steps of the tableau per sample.
    a : ndarray (s, s)
        ``h a_ij`` (strictly lower triangular).
    b : ndarray (s,)
        ``h b_i``.
    stage_u : ndarray (steps, s, k)
        The inputs at every step's stage times.
    p, o : ndarray
        Passed to ``rhs``.
    """
    n, m = x.shape
    s = b.size
    K = np.empty((s, n, m))
    xi = np.empty((n, m))
    # flat views: the stage sums as loops of unit stride over all n·m numbers
    x_flat, xi_flat, K_flat = x.reshape(n * m), xi.reshape(n * m), K.reshape(s, n * m)
    for sample in range(first, first + count):
        for _ in range(substeps):
            for i in range(s):
                for j in range(n * m):
                    xi_flat[j] = x_flat[j]
                for q in range(i):
                    c = a[i, q]
                    if c != 0.0:
                        k_q = K_flat[q]
                        for j in range(n * m):
                            xi_flat[j] = xi_flat[j] + c * k_q[j]
                rhs(xi, stage_u[step, i], p, o, K[i])
            for j in range(n * m):
                acc = 0.0
                for i in range(s):
                    acc = acc + b[i] * K_flat[i, j]
                x_flat[j] = x_flat[j] + acc
            step += 1
        for r in range(n):  # (explicit loops: numba compiles a slice assignment slowly)
            for j in range(m):
                out[r, sample, j] = x[r, j]
