"""Compiled recurrences of the LTI engine (numba); like every numerics module,
they know no vehicle.

`qc_control.numerics.lti.OutputStream` carries each design's state from block to
block, ``c_{b+1} = Q c_b + w_{b+1}`` with ``Q = Φ^L`` the step map over a
block and ``w`` the input's effect over it. Written with NumPy over the
designs, that recurrence was a log-depth (Hillis–Steele) scan: about
``log2(blocks)`` rounds of batched 4 × 4 products, each a NumPy call whose
fixed cost is most of its time for a chunk of a hundred designs. As a
compiled loop it is the recurrence itself, ``n²`` multiply-adds per block
and design, and its sums are the recurrence's own (no reassociation).

numba is imported with this module, so `qc_control.numerics.lti` imports it only when
a stream is first built (sweeps, never a single response); the compiled code
is cached on disk (`compiled`).
"""

from __future__ import annotations

from collections.abc import Callable

import numba

__all__ = ["carry_scan", "compiled"]


def compiled(**options) -> Callable:
    """A decorator: the function compiled by numba (nopython, without the GIL),
    its machine code cached on disk where numba finds a place to write it
    (``NUMBA_CACHE_DIR``, beside the module, or the user's cache directory).

    Where it finds none (a read-only installation run by a user without a
    writable home), ``numba.njit(cache=True)`` raises when the module is
    imported; the function is then compiled anew in each process instead, at
    the cost of the compilation (a few seconds) on first use.
    """

    def decorate(fn: Callable) -> Callable:
        try:
            return numba.njit(cache=True, nogil=True, **options)(fn)
        except RuntimeError:  # "cannot cache function ...: no locator available"
            return numba.njit(nogil=True, **options)(fn)

    return decorate


@compiled()
def carry_scan(Q, V):  # pragma: no cover - compiled (tested through lti.OutputStream)
    """In place, per design ``d``: ``V[d, :, b+1] += Q[d] @ V[d, :, b]`` for ``b = 0 .. S-2``.

    Parameters
    ----------
    Q : ndarray (m, n, n)
        Each design's step map over one block.
    V : ndarray (m, n, S)
        On entry, column 0 is the first carry and column ``b + 1`` the
        input's effect over block ``b`` (0 for a free response); on return,
        the carries ``c_0 .. c_{S-1}``.
    """
    m, n, S = V.shape
    for d in range(m):
        for b in range(S - 1):
            for r in range(n):
                acc = 0.0
                for c in range(n):
                    acc += Q[d, r, c] * V[d, c, b]
                V[d, r, b + 1] += acc
