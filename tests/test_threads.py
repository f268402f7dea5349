"""The library's hot paths run their BLAS calls on one thread, and leave the
user's thread count as it was.

threadpoolctl's own ``threadpool_info`` is the reference: it reads each
loaded BLAS library's thread count from the library itself. Each hot path
is observed from inside a call, by replacing a function it calls with a
recorder; nothing here is timed (benchmarks/run.py --busy measures speed).
"""

from __future__ import annotations

import threading

import numpy as np
import pytest
import scipy.linalg  # noqa: F401  (scipy's own OpenBLAS, limited too)
from threadpoolctl import threadpool_info, threadpool_limits

import qc_control as qc
from qc_control.models import mpc as mpc_module
from qc_control.numerics import lti, threads
from qc_control.studies import sweeps

#: The thread count the user chose, set around each test: 2, so that a
#: limit to 1 is visible on any machine (OpenBLAS accepts 2 on one core).
USER_THREADS = 2


def blas_threads() -> set[int]:
    """Thread counts of every loaded BLAS library, as the libraries report them."""
    return {lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"}


@pytest.fixture
def user_setting():
    with threadpool_limits(limits=USER_THREADS, user_api="blas"):
        if blas_threads() != {USER_THREADS}:
            pytest.skip(f"this BLAS will not run {USER_THREADS} threads: {blas_threads()}")
        yield
        # after every call under test, the user's choice is back
        assert blas_threads() == {USER_THREADS}


def recorder(monkeypatch, owner, name: str) -> list[set[int]]:
    """Replace ``owner.name`` by a wrapper that records the BLAS thread counts
    seen when it is called."""
    seen: list[set[int]] = []
    inner = getattr(owner, name)

    def record(*args, **kwargs):
        seen.append(blas_threads())
        return inner(*args, **kwargs)

    monkeypatch.setattr(owner, name, record)
    return seen


T = np.linspace(0.0, 2.0, 2001)
STEP = np.where(T >= 0.5, 0.05, 0.0)


def test_a_forced_response_runs_on_one_blas_thread(user_setting, monkeypatch):
    seen = recorder(monkeypatch, lti, "_input_offsets")
    qc.forced_response(qc.quarter_car(road=True), T, STEP, np.zeros(4), method="rk4")
    assert seen and all(s == {1} for s in seen), seen


def test_a_sweep_runs_on_one_blas_thread(user_setting, monkeypatch):
    seen = recorder(monkeypatch, sweeps, "step_matrices")
    sweeps.sweep({"ks": [2e4, 3e4]}, T, [0.0, 0.0, 0.05, 0.0], progress=False)
    assert seen and all(s == {1} for s in seen), seen


def test_an_mpc_plan_is_made_on_one_blas_thread(user_setting, monkeypatch):
    seen = recorder(monkeypatch, mpc_module._CondensedQP, "solve")
    car = qc.quarter_car_model(road=True, actuator=True)
    controller = qc.mpc_controller(car, 0.01, 20, limits={"fa": 500.0})
    controller.solve(np.array([0.0, 0.0, 0.05, 0.0]))
    assert seen == [{1}]


def test_the_user_setting_is_restored_after_an_error(user_setting):
    @threads.one_blas_thread
    def fails():
        assert blas_threads() == {1}
        raise ValueError("inside")

    with pytest.raises(ValueError, match="inside"):
        fails()
    assert blas_threads() == {USER_THREADS}


def test_concurrent_calls_run_on_one_thread_and_restore_the_default():
    """Calls overlapping on several Python threads (a Dask worker's, a GUI's):
    while the first is inside, all run on one thread; the last one out finds
    the machine's default back. (With no ``threadpool_limits`` held by the
    test: threadpoolctl lets only the thread holding one change the count.)"""
    default = blas_threads()
    if default == {1}:
        pytest.skip("BLAS already runs on one thread here")
    inside = threading.Barrier(4)
    views: list[set[int]] = []

    @threads.one_blas_thread
    def work():
        with threads.blas_single_thread():  # nested: still one thread
            inside.wait(timeout=30)  # all four inside
            views.append(blas_threads())
        inside.wait(timeout=30)  # all four back in the outer call
        views.append(blas_threads())
        inside.wait(timeout=30)  # all seen before the first one leaves

    workers = [threading.Thread(target=work) for _ in range(4)]
    for w in workers:
        w.start()
    for w in workers:
        w.join(timeout=60)
    assert views == [{1}] * 8
    assert blas_threads() == default


def test_a_user_limit_held_on_another_thread_is_left_alone(user_setting):
    """The user's ``threadpool_limits`` context on the main thread controls
    OpenBLAS; a call on a worker thread neither overrides nor undoes it."""
    seen = []
    worker = threading.Thread(target=threads.one_blas_thread(lambda: seen.append(blas_threads())))
    worker.start()
    worker.join(timeout=60)
    assert seen == [{USER_THREADS}]


def test_a_library_loaded_after_the_first_call_is_limited_too(user_setting, monkeypatch):
    """The controller is rebuilt when modules were imported since it was
    built, so a BLAS that arrived later (scipy's) is not missed."""
    with threads.blas_single_thread():
        pass
    monkeypatch.setattr(threads, "_modules_seen", -1)  # as if a module had been imported
    rebuilt = []
    real = threads.ThreadpoolController

    def counting():
        rebuilt.append(1)
        return real()

    monkeypatch.setattr(threads, "ThreadpoolController", counting)
    with threads.blas_single_thread():
        assert blas_threads() == {1}
    assert rebuilt == [1]
