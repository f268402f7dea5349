"""Runs sized by a product (grids of designs, substeps, max_step) are counted and
refused before anything of that size is allocated (issue 28, item 7).

Each refusal is `ResourceLimitError` (a ValueError) from
`qc_control.numerics.limits.check_memory`, naming the count it was asked for.
The expected counts are closed forms (the product of the axes' lengths, the
intervals of T times the substeps), not the code's own output. The limit is
fixed through ``QC_CONTROL_MAX_MEMORY`` so that the boundary does not depend
on the machine; every refusal must come before any large allocation (the
grids used to run 39 s into a bare MemoryError): what the refused call
allocates is measured with tracemalloc, never its time.
"""

import itertools
import tracemalloc

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control.numerics import limits
from qc_control.numerics.integrate import integrate, stage_times
from qc_control.studies.sweeps import DESIGN_BYTES, design_grid

#: The issue's grid: 1000 values on each of three axes, a billion designs.
BILLION = {
    "ks": np.linspace(1e4, 5e4, 1000),
    "cs": np.linspace(100, 5000, 1000),
    "ms": np.linspace(200, 400, 1000),
}
T = np.linspace(0, 1, 101)  # 100 intervals
X0 = [0.0, 0.0, 0.05, 0.0]


@pytest.fixture
def limit_16g(monkeypatch):
    """A fixed limit far above the allowed runs here, far below the refused ones."""
    monkeypatch.setenv(limits.ENV_VAR, "16G")


#: What a refusal may allocate [bytes]: the refused runs need TiB, and building
#: their grids first (as before the checks) took GBs; the check's own arrays (a
#: grid's axes, T) are kilobytes. 64 MB leaves room for a first call's caches.
REFUSAL_BYTES = 64 * 2**20


def refused_quickly(call, *words):
    """``call()`` raises ResourceLimitError, its message holding ``words``, having
    allocated less than `REFUSAL_BYTES` (tracemalloc's peak, which NumPy's
    arrays report to): the count was refused before the run was built."""
    with pytest.raises(limits.ResourceLimitError):
        call()  # once untraced: imports and caches a first call makes
    tracemalloc.start()
    try:
        with pytest.raises(limits.ResourceLimitError) as err:
            call()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    text = str(err.value)
    for word in words:
        assert word in text, text
    assert "QC_CONTROL_MAX_MEMORY=16G" in text and "TiB" in text
    assert peak < REFUSAL_BYTES, f"allocated {peak / 2**20:.0f} MB before refusing"
    return text


@pytest.mark.usefixtures("limit_16g")
@pytest.mark.parametrize(
    "call, words",
    [
        (lambda: qc.sweep(BILLION, T, progress=False), ["a sweep of 1000000000 designs"]),
        (
            lambda: qc.sweep(BILLION, road=qc.ISO8608Road("C", 20.0)),
            ["a spectral sweep of 1000000000 designs"],
        ),
        (lambda: design_grid(BILLION), ["a design grid of 1000000000 designs"]),
    ],
    ids=["sweep", "spectral", "design_grid"],
)
def test_a_billion_design_grid_is_refused_by_its_count(call, words):
    """1000**3 designs: refused naming the count, the axes and what to do."""
    text = refused_quickly(call, *words, "(1000 ks × 1000 cs × 1000 ms)")
    assert "use fewer" in text


def test_a_grid_just_under_the_limit_is_built_and_one_just_over_is_refused(monkeypatch):
    """At a 1 MiB limit and `DESIGN_BYTES` (2560 B) a design, 409 designs fit:
    a 256-design grid is the cartesian product (itertools.product, the
    reference), a 1000-design grid is refused with its count."""
    monkeypatch.setenv(limits.ENV_VAR, "1M")
    axes = {"ks": [2e4, 3e4, 4e4, 5e4], "ms": [250.0, 300.0, 350.0, 400.0] * 4, "mu": [30, 40] * 2}
    designs = design_grid(axes)
    want = list(itertools.product(axes["ks"], axes["ms"], axes["mu"]))
    assert len(designs) == 256 and 256 * DESIGN_BYTES < 2**20
    assert [(d["ks"], d["ms"], d["mu"]) for d in designs] == want
    with pytest.raises(limits.ResourceLimitError, match=r"1000 designs \(10 ks × 100 ms\)"):
        design_grid({"ks": np.linspace(2e4, 5e4, 10), "ms": np.linspace(250, 400, 100)})


@pytest.mark.slow
def test_an_allowed_grid_sweeps_every_design(monkeypatch):
    """A sweep of a grid under an 8 MiB limit runs (its streamed chunk is 4 MiB,
    its 96 designs 240 kB) and equals python-control's exact free response
    on one of its designs; 2000 designs (5 MiB more) are refused."""
    monkeypatch.setenv(limits.ENV_VAR, "8M")
    grid = {"ks": np.linspace(2e4, 5e4, 4), "zeta": np.linspace(0.2, 0.5, 4), "ms": [250.0] * 6}
    T1 = np.linspace(0, 2, 401)
    res = qc.sweep(grid, T1, progress=False, metrics=["peak_susp_travel"])
    assert len(res.metrics) == 96 and not len(res.errors)
    p = qc.QuarterCarParams(ks=5e4, zeta=0.5, ms=250.0)
    exact = control.initial_response(qc.quarter_car(p), T1, X0)
    travel = exact.outputs[list(exact.output_labels).index("susp_travel")]
    row = res.metrics[(res.metrics.ks == 5e4) & np.isclose(res.metrics.zeta, 0.5)].iloc[0]
    # RK4 at h = 5 ms on modes up to ~60 rad/s: (h·ω)^5 / 120 ~ 2e-5 relative per step,
    # so the peak agrees to 1e-4 of its size
    np.testing.assert_allclose(row["peak_susp_travel [m]"], np.abs(travel).max(), rtol=1e-4)
    big = {"ks": np.linspace(2e4, 5e4, 20), "zeta": np.linspace(0.2, 0.5, 100)}
    with pytest.raises(limits.ResourceLimitError, match="a sweep of 2000 designs"):
        qc.sweep(big, T1, progress=False)


@pytest.mark.usefixtures("limit_16g")
@pytest.mark.parametrize(
    "call, words",
    [
        (
            lambda: qc.initial_response(qc.quarter_car(), T, X0, substeps=10**9, engine="generic"),
            ["100000000000 steps", "substeps = 1000000000 in each of 100 intervals"],
        ),
        (
            # a non-uniform grid: the generic engine, 3 intervals
            lambda: qc.forced_response(
                qc.quarter_car(road=True), [0, 0.3, 0.5, 1], np.zeros(4), substeps=10**9
            ),
            ["3000000000 steps", "substeps = 1000000000 in each of 3 intervals"],
        ),
        (
            lambda: qc.input_output_response(
                qc.nonlinear_quarter_car(road=False), T, X0=X0, substeps=10**9
            ),
            ["100000000000 steps", "substeps = 1000000000"],
        ),
        (
            # 10 ms intervals at 1e-12 s: 1e10 substeps each
            lambda: qc.input_output_response(
                qc.nonlinear_quarter_car(road=False), T, X0=X0, solve_ivp_kwargs={"max_step": 1e-12}
            ),
            ["1000000000000 steps", "max_step = 1e-12 s: substeps = 10000000000"],
        ),
        (
            lambda: qc.input_output_response(
                qc.quarter_car(), T, X0=X0, solve_ivp_kwargs={"max_step": 1e-12}
            ),
            ["1000000000000 steps", "max_step = 1e-12"],
        ),
        (
            lambda: qc.sweep(
                [qc.nonlinear_quarter_car_model().params],
                T,
                model=qc.nonlinear_quarter_car_model(road=False),
                substeps=10**9,
                progress=False,
            ),
            ["stage-times table of 100000000000 steps", "substeps = 1000000000"],
        ),
        (
            lambda: stage_times(T, "rk4", substeps=10**9),
            ["stage-times table of 100000000000 steps"],
        ),
        (
            lambda: integrate(lambda t, x: -x, T, [1.0], substeps=10**9),
            ["100000000000 steps", "substeps = 1000000000"],
        ),
    ],
    ids=[
        "initial",
        "forced",
        "io-substeps",
        "io-max_step",
        "io-linear",
        "nl-sweep",
        "stage-times",
        "integrate",
    ],  # fmt: skip
)
def test_substeps_and_max_step_are_refused_by_their_step_count(call, words):
    """``substeps = 1e9`` and ``max_step = 1e-12`` gave an empty MemoryError: now the
    refusal names the steps and where they come from."""
    text = refused_quickly(call, *words)
    assert "use fewer substeps or a larger max_step" in text


def test_allowed_substeps_still_run(monkeypatch):
    """At a 2 MiB limit, 200 substeps on 100 intervals (a block of 20,000 steps,
    about 1.6 MB of step times and states) run and match python-control's exact
    response; 300 (2.4 MB) are refused."""
    monkeypatch.setenv(limits.ENV_VAR, "2M")
    car = qc.quarter_car()
    r = qc.input_output_response(car, T, X0=X0, substeps=200)
    exact = control.initial_response(car, T, X0)
    assert r.success and r.substeps == 200
    # RK4 at h = 5e-5 s on modes up to ~60 rad/s: error ~ (h·ω)^4 ~ 1e-16 per unit state;
    # 1e-10 m leaves room for rounding over 20,000 steps
    np.testing.assert_allclose(r.states, exact.states, rtol=0, atol=1e-10)
    with pytest.raises(limits.ResourceLimitError, match="30000 steps"):
        qc.input_output_response(car, T, X0=X0, substeps=300)


@pytest.mark.usefixtures("limit_16g")
def test_every_step_kept_is_counted_over_the_whole_run():
    """With ``evaluation_times=None`` every step is kept: 1e4 substeps on 1e6
    intervals are 1e10 steps of times, states and outputs (the block alone,
    128 intervals, would pass), refused with the count."""
    T_long = np.linspace(0, 1e4, 10**6 + 1)
    refused_quickly(
        lambda: qc.input_output_response(
            qc.quarter_car(), T_long, X0=X0, substeps=10**4, evaluation_times=None
        ),
        "the times, states and outputs at every step of 10000000000 steps",
        "substeps = 10000 in each of 1000000 intervals",
    )
