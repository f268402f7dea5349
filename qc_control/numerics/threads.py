"""One BLAS thread for the library's small dense products.

The LTI engine, the sweeps, the spectral kernels and the MPC multiply
matrices of a few tens of rows (the car's 4-14 states, a block of 16 steps).
OpenBLAS splits such a product over every core it was started with; on a
machine whose other cores are busy (a laptop with a browser open) each
split waits for a core, and a 0.03 ms product takes milliseconds. One
thread is never slower for these sizes, so the library's hot paths run on
one, and the user's own setting is restored when the call returns.

`threadpoolctl <https://github.com/joblib/threadpoolctl>`_ does the work.
Its ``threadpool_limits`` scans the process's shared libraries at every
call (~1 ms, twice a whole response of the seed car), so one
``ThreadpoolController`` is kept and rebuilt only when modules have been
imported since it was built (scipy's OpenBLAS arrives with scipy.linalg):
entering and leaving the limit then costs ~0.02 ms.
"""

from __future__ import annotations

import functools
import sys
import threading
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any, TypeVar

from threadpoolctl import ThreadpoolController

__all__ = ["blas_single_thread", "one_blas_thread"]

F = TypeVar("F", bound=Callable[..., Any])

_lock = threading.Lock()
_controller: ThreadpoolController | None = None
_modules_seen = -1
#: The limit is the process's (OpenBLAS has one thread count), and
#: threadpoolctl lets one Python thread at a time set it. So one thread owns
#: the limit: the first to enter a hot path, until its outermost call
#: returns and restores the count it found. Calls on other threads meanwhile
#: run under its limit and change nothing; a user's own ``threadpool_limits``
#: held on another thread wins, and is never undone by ours.
_owner: int | None = None
_depth = 0
_limit: Any = None


def _current_controller() -> ThreadpoolController:
    global _controller, _modules_seen
    if _controller is None or len(sys.modules) != _modules_seen:
        _controller = ThreadpoolController()
        _modules_seen = len(sys.modules)
    return _controller


class _OneThread(AbstractContextManager):
    def __enter__(self):
        global _owner, _depth, _limit
        me = threading.get_ident()
        with _lock:
            if _owner is None:
                _owner, _limit = me, _current_controller().limit(limits=1, user_api="blas")
                _limit.__enter__()
            if _owner == me:
                _depth += 1
        return self

    def __exit__(self, *exc):
        global _owner, _depth, _limit
        with _lock:
            if _owner == threading.get_ident():
                _depth -= 1
                if _depth == 0:
                    limit, _limit, _owner = _limit, None, None
                    limit.__exit__(None, None, None)
        return False


def blas_single_thread() -> AbstractContextManager:
    """A context in which every loaded BLAS library runs on one thread.

    The number of threads each library had is restored on leaving, also
    after an exception. Nested contexts set the limit once.

    Examples
    --------
    >>> import numpy as np
    >>> with blas_single_thread():
    ...     y = np.ones((626, 17)) @ np.ones((17, 64))
    """
    return _OneThread()


def one_blas_thread(func: F) -> F:
    """Decorate a hot path so that its BLAS calls run on one thread.

    See `blas_single_thread`; the decorated function's signature and
    docstring are kept.
    """

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with _OneThread():
            return func(*args, **kwargs)

    return wrapper  # type: ignore[return-value]
