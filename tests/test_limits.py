"""Resource limits: runs that cannot fit are refused before they allocate."""

import numpy as np
import pytest

import qc_control as qc
from qc_control.numerics import limits
from qc_control.ride import road


def test_limit_from_the_environment(monkeypatch):
    monkeypatch.setenv(limits.ENV_VAR, "12G")
    assert limits.memory_limit()[0] == 12 * 2**30
    monkeypatch.setenv(limits.ENV_VAR, "1.5m")
    assert limits.memory_limit()[0] == int(1.5 * 2**20)
    monkeypatch.setenv(limits.ENV_VAR, "lots")
    with pytest.raises(limits.ResourceLimitError, match="'lots' is not a size"):
        limits.memory_limit()


def test_default_limit_is_half_the_machine(monkeypatch):
    monkeypatch.delenv(limits.ENV_VAR, raising=False)
    limit, source = limits.memory_limit()
    assert "half of this machine" in source and 0 < limit < 2**50


def test_refusal_names_the_run_the_estimate_and_the_limit(monkeypatch):
    monkeypatch.setenv(limits.ENV_VAR, "1M")
    T = np.linspace(0, 100, 100001)
    with pytest.raises(limits.ResourceLimitError) as err:
        qc.sweep([qc.QuarterCarParams()] * 4, T, states=True, progress=False)
    text = str(err.value)
    assert "a sweep of 4 designs over 100001 samples keeping their states" in text
    assert "more than the limit of 1 MiB (QC_CONTROL_MAX_MEMORY=1M)" in text
    assert "states=False" in text
    with pytest.raises(limits.ResourceLimitError, match="method comparison over 100000 steps"):
        qc.compare_methods(qc.QuarterCarParams(), T)


def test_iso8608_work_follows_the_span_not_the_smallest_gap(monkeypatch):
    """A 1e-9 s gap in a 10 s grid used to size the profile at 1e-9 s steps
    (169 GiB); now the profile follows the mean step."""
    asked = []
    real = road.check_memory
    monkeypatch.setattr(road, "check_memory", lambda n, *a: (asked.append(n), real(n, *a)))
    T = np.r_[0.0, 1e-9, np.arange(1, 2001) * 0.005]
    zr = road.iso8608(T, "C", speed=20.0, seed=2)
    assert zr.shape == T.shape and np.all(np.isfinite(zr))
    assert asked and max(asked) < 2e6  # about 0.2 MB of profile, not 169 GiB
    # on a uniform grid the road is unchanged: sampled exactly at the profile's points
    U = np.linspace(0, 10, 2001)
    x, z = road.iso8608_profile(200.0, 20.0 * 0.005, "C", seed=2)
    np.testing.assert_array_equal(road.iso8608(U, "C", 20.0, seed=2), np.interp(20.0 * U, x, z))


def test_negative_seed_is_named():
    with pytest.raises(ValueError, match="seed must be a whole number >= 0, got -1"):
        road.iso8608(np.linspace(0, 1, 201), "C", seed=-1)


def test_spectral_metrics_refuse_too_few_points():
    with pytest.raises(ValueError, match="points must be an integer >= 2.*got 1"):
        qc.ride_metrics_spectral(qc.QuarterCarParams(), road.ISO8608Road("C", speed=20.0), points=1)


def test_empty_design_grid_is_refused():
    with pytest.raises(ValueError, match="design grid is empty"):
        qc.sweep({}, np.linspace(0, 1, 101))
    with pytest.raises(ValueError, match="no values for 'ks'"):
        qc.sweep({"ks": []}, np.linspace(0, 1, 101))


def test_a_response_too_large_for_the_machine_is_refused_before_it_runs(monkeypatch):
    """Issue 14 item 13: 1e8 samples took 15.4 GB and ended in a raw MemoryError.
    The estimate is 8 B x N x (3n + 2p + m + 2): 27 GB for the quarter car on
    1e8 samples, 192 MB on the 1e6 used here against a 10 MiB limit, refused
    before any array of that size exists."""
    monkeypatch.setenv(limits.ENV_VAR, "10M")
    T = np.linspace(0, 1e4, 10**6 + 1)
    with pytest.raises(limits.ResourceLimitError) as err:
        qc.initial_response(qc.quarter_car(), T, [0, 0, 0.05, 0])
    text = str(err.value)
    assert "a fixed-step response of 'quarter_car' on 1000001 samples" in text
    assert "about 183 MiB" in text and "more than the limit of 10 MiB" in text
