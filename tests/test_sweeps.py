"""sweep(): equal to single runs, independent of executor and chunking, robust to bad designs."""

from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control.numerics.lti import OutputStream, TailBound, step_matrices
from qc_control.numerics.methods import get_method
from qc_control.ride import road
from qc_control.ride.comfort import ride_metrics
from qc_control.studies.sweeps import DEFAULT_METRICS, METRICS, design_grid, sweep

T = np.linspace(0, 5, 2001)  # h = 2.5 ms
X0 = [0.0, 0.0, 0.05, 0.0]
GRID = {"ks": [2e4, 3e4, 4.5e4], "zeta": [0.1, 0.3, 0.6], "mu": [40.0, 100.0]}


def independent_metrics(y, T, p=qc.QuarterCarParams()):
    """The default metrics written plainly, on (5, N) outputs of one run."""
    xs = y[0]
    dev = np.abs(xs - xs[-1])
    outside = np.flatnonzero(dev > 0.02 * dev.max())
    settle = T[min(outside[-1] + 1, T.size - 1)] if outside.size else T[0]
    return {
        "peak_susp_travel [m]": np.max(np.abs(y[2])),
        "rms_body_acc [m/s²]": np.sqrt(np.trapezoid(y[4] ** 2, T) / (T[-1] - T[0])),
        "settling_time [s]": settle,
        "peak_tire_defl [m]": np.max(np.abs(y[3])),
        "rms_tire_load / static [-]": p.ku
        * np.sqrt(np.trapezoid(y[3] ** 2, T) / (T[-1] - T[0]))
        / ((p.ms + p.mu) * 9.80665),
    }


@pytest.fixture(scope="module")
def grid_result():
    return sweep(GRID, T, X0, states=True, progress=False)


def test_grid_is_the_cartesian_product(grid_result):
    assert len(grid_result.metrics) == 18
    assert list(grid_result.metrics[["ks", "zeta", "mu"]].iloc[1]) == [2e4, 0.1, 100.0]
    # zeta sets cs along the grid: cs = 2 zeta sqrt(ks ms)
    row = grid_result.metrics.iloc[5]
    assert row["cs"] == pytest.approx(2 * row["zeta"] * np.sqrt(row["ks"] * row["ms"]))


def test_equal_to_single_runs(grid_result):
    for i, d in enumerate(design_grid(GRID)):
        sys = qc.quarter_car(qc.QuarterCarParams(**d))
        single = qc.initial_response(sys, T, X0, method="rk4", engine="generic")
        # the same method computed two ways: rounding only (1e-12 of the 5 cm scale)
        np.testing.assert_allclose(grid_result.states[i], single.states, rtol=0, atol=1e-12)
        expected = independent_metrics(single.outputs, T, qc.QuarterCarParams(**d))
        for name, value in expected.items():
            assert grid_result.metrics.loc[i, name] == pytest.approx(value, rel=1e-9, abs=1e-12)


def test_rk4_sweep_against_control_exact():
    """RK4 at h = 1 ms: peak travel within 1e-8 m of the exact response's."""
    T1 = np.linspace(0, 5, 5001)
    r = sweep(
        [qc.QuarterCarParams(), qc.QuarterCarParams(ks=4e4, zeta=0.4)], T1, X0, progress=False
    )
    for i, p in enumerate([qc.QuarterCarParams(), qc.QuarterCarParams(ks=4e4, zeta=0.4)]):
        exact = control.initial_response(qc.quarter_car(p), T1, X0).outputs
        assert abs(r.metrics.loc[i, "peak_susp_travel [m]"] - np.max(np.abs(exact[2]))) < 1e-8


def test_road_sweep_equals_forced_response():
    U = np.where(T >= 0.5, 0.05, 0.0)
    designs = [qc.QuarterCarParams(), qc.QuarterCarParams(zeta=0.5, ku=2e5)]
    r = sweep(designs, T, np.zeros(4), U=U, method="heun", states=True, progress=False)
    for i, p in enumerate(designs):
        single = qc.forced_response(
            qc.quarter_car(p, road=True), T, U, method="heun", engine="generic"
        )
        np.testing.assert_allclose(r.states[i], single.states, rtol=0, atol=1e-12)
        expected = independent_metrics(single.outputs, T)
        assert r.metrics.loc[i, "peak_tire_defl [m]"] == pytest.approx(
            expected["peak_tire_defl [m]"], rel=1e-9
        )


def test_chunking_and_executors_do_not_change_results(grid_result):
    ref = grid_result.metrics
    cols = list(DEFAULT_METRICS)
    for kwargs in (
        dict(chunk_size=1),
        dict(chunk_size=7),
        dict(chunk_size=1000),
        dict(executor=ThreadPoolExecutor(2), chunk_size=4),
    ):
        other = sweep(GRID, T, X0, progress=False, **kwargs).metrics
        # each design's arithmetic is the same whatever its chunk: agree to 1e-13
        np.testing.assert_allclose(other[cols].to_numpy(), ref[cols].to_numpy(), rtol=1e-13)
    with ProcessPoolExecutor(2) as pool:
        other = sweep(GRID, T, X0, executor=pool, chunk_size=5, progress=False).metrics
    np.testing.assert_allclose(other[cols].to_numpy(), ref[cols].to_numpy(), rtol=1e-13)


@pytest.mark.slow  # starts a Dask cluster with a worker process: about 4 s
def test_dask_local_cluster(grid_result):
    """A sweep on a Dask cluster's executor: chunks pickled to a worker in another
    process, results gathered by distributed. One worker is enough: the sweep reads
    each chunk's future in submission order whatever its worker, and two processes
    finishing out of order are the ProcessPoolExecutor case above (a second worker
    process cost 3.2 CPU-s, measured: 12.0 s with two, 8.8 s with one)."""
    distributed = pytest.importorskip("dask.distributed")
    with (
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        other = sweep(
            GRID, T, X0, executor=client.get_executor(), chunk_size=4, progress=False
        ).metrics
    cols = list(DEFAULT_METRICS)
    np.testing.assert_allclose(
        other[cols].to_numpy(), grid_result.metrics[cols].to_numpy(), rtol=1e-13
    )


def test_bad_designs_are_reported_and_nothing_else_is_lost(grid_result):
    # designs in order: (300, ok) (300, nan) (-5, ok) (-5, nan) (400, ok) (400, nan)
    grid = {"ms": [300.0, -5.0, 400.0], "ku": [29530.0, float("nan")]}
    with pytest.warns(RuntimeWarning, match="4 of 6 designs were rejected"):
        r = sweep(grid, T, X0, progress=False)
    assert list(r.errors["index"]) == [1, 2, 3, 5]
    assert (
        "ku (tire stiffness) must be a finite number > 0 N/m, got nan" in r.errors.loc[0, "error"]
    )
    assert "ms (sprung mass) must be a finite number > 0 kg, got -5.0" in r.errors.loc[1, "error"]
    assert r.errors.loc[1, "value"]["ms"] == -5.0
    good = r.metrics[r.metrics["error"] == ""]
    assert list(good.index) == [0, 4] and good[list(DEFAULT_METRICS)].notna().all().all()
    assert r.metrics.loc[1, list(DEFAULT_METRICS)].isna().all()
    alone = sweep([qc.QuarterCarParams(ms=400.0)], T, X0, progress=False).metrics
    assert r.metrics.loc[4, "peak_susp_travel [m]"] == pytest.approx(
        alone.loc[0, "peak_susp_travel [m]"], rel=1e-13
    )


def test_unstable_designs_are_flagged():
    r = sweep(
        [qc.QuarterCarParams(), qc.QuarterCarParams(ku=3e6)],
        np.linspace(0, 1, 101),
        X0,
        method="euler",
        progress=False,
    )
    # h = 10 ms: fine for the seed (limit 19.8 ms), not for a 3e6 N/m tire
    assert list(r.metrics["stable"]) == [True, False]


def test_progress_bar_when_asked(capsys):
    sweep([qc.QuarterCarParams()] * 3, T, X0, progress=True, chunk_size=1)
    assert "sweep" in capsys.readouterr().err


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        (dict(designs={"kt": [1.0]}), ValueError, "unknown parameter 'kt' in the grid"),
        (dict(designs=[]), ValueError, "designs is empty"),
        (dict(T=[0, 0.1, 0.3]), ValueError, "uniformly spaced"),
        (dict(X0=[0, 0.05]), ValueError, "X0 must be 4 finite numbers"),
        (dict(U=np.zeros(5)), ValueError, "U must be finite, of shape \\(2001,\\)"),
        (dict(chunk_size=0), qc.ParameterError, "chunk_size must be a whole number >= 1, got 0"),
        (dict(metrics=["comfort"]), ValueError, "unknown metric 'comfort'"),
        (dict(executor="pool"), TypeError, "executor must be a concurrent.futures.Executor"),
        (dict(method="rk5"), ValueError, "unknown method"),
    ],
)
def test_bad_input(kwargs, error, words):
    args = dict(designs=[qc.QuarterCarParams()], T=T, X0=X0)
    args.update(kwargs)
    with pytest.raises(error, match=words):
        sweep(args.pop("designs"), args.pop("T"), args.pop("X0"), progress=False, **args)


def test_custom_metric_and_states_off():
    r = sweep(
        [qc.QuarterCarParams()],
        T,
        X0,
        metrics={"final xs [m]": lambda c: c.output("xs")[:, -1]},
        progress=False,
    )
    assert r.states is None and list(r.metrics.columns)[-2] == "final xs [m]"
    exact = control.initial_response(qc.quarter_car(), T, X0).outputs[0, -1]
    assert r.metrics.loc[0, "final xs [m]"] == pytest.approx(exact, abs=1e-8)


def test_ride_metrics_in_a_road_sweep_equal_ride_metrics():
    """Every ride metric of the sweep against qc.ride_metrics of the single run."""
    Tr = np.linspace(0, 4, 2001)
    U = road.iso8608(Tr, "D", 15.0, seed=2)
    designs = [qc.QuarterCarParams(), qc.QuarterCarParams(ku=1.5e5, zeta=0.15)]
    r = sweep(designs, Tr, np.zeros(4), U=U, metrics=list(METRICS), progress=False).metrics
    names = {
        "rms_body_acc [m/s²]": "rms_body_acc [m/s²]",
        "rms_body_acc_wk [m/s²]": "rms_body_acc_wk [m/s²]",
        "vdv [m/s^1.75]": "vdv [m/s^1.75]",
        "rms_tire_load / static [-]": "rms_tire_load / static [-]",
        "lift_off_duration [s]": "lift_off_duration [s]",
    }
    for i, p in enumerate(designs):
        single = qc.forced_response(qc.quarter_car(p, road=True), Tr, U, method="rk4")
        expected = ride_metrics(single, p)
        for ours, theirs in names.items():
            # same formulas on trajectories equal to rounding: 1e-9 relative
            assert r.loc[i, ours] == pytest.approx(expected[theirs], rel=1e-9, abs=1e-12), ours


@pytest.mark.parametrize(
    "X0, U",
    [
        (X0, None),  # the seed's release: free response
        ([0.1, 0.0, 0.02, 0.01], "iso"),  # a rough road from a moving start
        ([0.0, 0.0, 0.0, 0.0], "drop"),  # a 20 cm drop: the wheels lift off
    ],
)
def test_streamed_metrics_equal_materialised(X0, U):
    """Every registered metric, streamed block by block (states=False), equals
    the same metric on the whole trajectories (states=True keeps them and
    evaluates RideSignals on them; the Wk weighting there is the FFT
    convolution, in the stream the filter's state rides in the scan). Both
    are sums of the same ~4000 terms in another order: 1e-12 relative, and
    the settling time, lift-off duration and flags exactly."""
    Tr = np.linspace(0, 4, 4001)
    if U == "iso":
        U = road.iso8608(Tr, "E", 15.0, seed=1)
    elif U == "drop":
        U = np.where(Tr >= 0.5, -0.2, 0.0)
    grid = {"ks": [2e4, 4.5e4], "zeta": [0.05, 0.3, 0.9], "ku": [1e5, 2.5e5]}
    names = list(METRICS)
    whole = sweep(grid, Tr, X0, U=U, metrics=names, states=True, progress=False).metrics
    streamed = sweep(grid, Tr, X0, U=U, metrics=names, chunk_size=5, progress=False).metrics
    for column in whole.columns[7:-1]:
        expected = whole[column].to_numpy(float)
        np.testing.assert_allclose(streamed[column].to_numpy(float), expected, rtol=1e-12)
    for column in ("settling_time [s]", "lift_off_duration [s]", "lift_off"):
        assert (streamed[column] == whole[column]).all(), column
    if U is not None and U[-1] < 0:
        assert streamed["lift_off"].any()


def test_free_sweep_rms_from_the_block_gram_equals_materialised():
    """The default metrics of a free sweep read the body acceleration only
    through its mean square, which then comes from the block Gram form
    (OutputStream.sum_squares) without streaming the samples: equal to the
    materialised RMS to 1e-12 relative (a regrouped sum of positive terms)."""
    grid = {"ks": [2e4, 4.5e4], "zeta": [0.05, 0.3, 0.9], "mu": [40.0, 100.0]}
    whole = sweep(grid, T, X0, states=True, progress=False).metrics
    streamed = sweep(grid, T, X0, progress=False).metrics
    for column in DEFAULT_METRICS:
        np.testing.assert_allclose(streamed[column], whole[column], rtol=1e-12)


def test_a_chunk_larger_than_the_vector_unit_is_split_and_reassembled():
    """A chunk of 100 designs is computed 64 at a time (VECTOR_DESIGNS); its
    metrics and kept states equal those of chunks of 7, design for design
    (the same arithmetic per design: 1e-13)."""
    from qc_control.studies.sweeps import VECTOR_DESIGNS

    Ts = np.linspace(0, 1, 101)
    grid = {"ks": np.linspace(2e4, 4e4, 10), "zeta": np.linspace(0.1, 0.6, 10)}
    assert VECTOR_DESIGNS < 100
    big = sweep(grid, Ts, X0, chunk_size=100, states=True, progress=False)
    small = sweep(grid, Ts, X0, chunk_size=7, states=True, progress=False)
    np.testing.assert_allclose(big.states, small.states, rtol=1e-13, atol=1e-18)
    cols = list(DEFAULT_METRICS)
    np.testing.assert_allclose(big.metrics[cols], small.metrics[cols], rtol=1e-13)
    streamed = sweep(grid, Ts, X0, chunk_size=100, progress=False).metrics
    np.testing.assert_allclose(streamed[cols], small.metrics[cols], rtol=1e-12)


@pytest.mark.parametrize(
    "X0, names",
    [
        ((0.0, 0.0, 0.05, 0.0), None),
        ((0.0, 0.0, 0.3, -0.05), None),
        # the Wk filter's state rides in the scan: the bound covers it too (no VDV:
        # a sum of fourth powers needs every sample, so that sweep is not cut; nor
        # MTVV and MSDV, whose running window and Wf filter read whole signals)
        ((0.0, 0.0, 0.3, -0.05), [n for n in METRICS if n not in ("vdv", "mtvv", "msdv")]),
    ],
)
def test_free_sweep_cut_short_equals_materialised(X0, names, monkeypatch):
    """A free sweep stops streaming once `TailBound` proves no later sample can
    move a peak, a lift-off count or the largest excursion, and finds the
    settling time's last sample outside the band by a backward search. On a
    grid from barely damped (still ringing at 10 s) to overdamped, and a
    release from 30 cm that lifts the wheel: the default metrics equal those
    of the whole trajectories (states=True) to 1e-12 relative (regrouped sums
    of squares), and the settling time and lift-off duration exactly (the
    same samples, compared with the same thresholds)."""
    grid = {"ks": [1.5e4, 4.5e4], "zeta": [0.02, 0.1, 0.3, 0.6, 1.5], "mu": [30.0, 60.0]}
    T10 = np.linspace(0, 10, 10001)
    whole = sweep(grid, T10, X0, metrics=names, states=True, progress=False).metrics
    searched = []  # chunks cut short: their settling time comes from the backward search
    carries = OutputStream.block_carries
    monkeypatch.setattr(
        OutputStream, "block_carries", lambda self: searched.append(1) or carries(self)
    )
    streamed = sweep(grid, T10, X0, metrics=names, chunk_size=4, progress=False).metrics
    assert searched
    for column in whole.columns[7:-1]:
        expected = whole[column].to_numpy(float)
        np.testing.assert_allclose(streamed[column].to_numpy(float), expected, rtol=1e-12)
    for column in ("settling_time [s]", "lift_off_duration [s]"):
        assert (streamed[column] == whole[column]).all(), column
    # the cases this covers: designs settled early and late, and lift-off
    settle = whole["settling_time [s]"]
    assert settle.min() < 2.0 and settle.max() > 8.0
    if X0[2] > 0.1:
        assert (whole["lift_off_duration [s]"] > 0).any()


def test_tail_bound_bounds_every_later_output():
    """`TailBound`'s modal bound against the outputs themselves: for stable step
    maps (the car's RK4 map, and random ones with |λ| < 1), every later
    |y_k| is at most the bound from x_K, and the bound is finite; a map with
    |λ| >= 1 gets inf (no claim)."""
    rng = np.random.default_rng(3)
    phis = []
    for params in (qc.QuarterCarParams(), qc.QuarterCarParams(ks=4.5e4, zeta=0.05)):
        A = np.asarray(qc.quarter_car(params).A)
        phis.append(step_matrices(get_method("rk4"), A, np.zeros((4, 1)), 1e-3)[0])
    for _ in range(4):
        Q = rng.standard_normal((4, 4))
        phis.append(0.97 * Q / np.max(np.abs(np.linalg.eigvals(Q))))
    phis.append(np.diag([1.0, 0.5, 0.2, 0.1]))  # a mode that does not decay
    phi = np.array(phis)
    C = rng.standard_normal((len(phis), 3, 4))
    bound = TailBound(phi, C)
    x = rng.standard_normal((len(phis), 4))
    K = 0
    for k in range(3000):
        if k % 500 == 0:
            beta, K = bound(x), k
        y = np.abs((C @ x[..., None])[..., 0])
        assert np.all(y[:-1] <= beta[:-1]), (k, K)
        x = (phi @ x[..., None])[..., 0]
    assert np.all(np.isfinite(beta[:-1])) and np.all(np.isinf(beta[-1]))


def test_rejected_designs_carry_the_constructors_messages():
    """sweep checks a grid of dicts in arrays (QuarterCarParams.from_mappings);
    its rejected designs and their messages must be those of the one-by-one
    constructor (the reference), index by index."""
    grid = {"ks": [3e4, -1.0, np.nan], "zeta": [0.2, -0.5]}
    designs = qc.design_grid(grid)
    expected = []
    for i, d in enumerate(designs):
        try:
            qc.QuarterCarParams.from_mapping(d)
        except ValueError as exc:
            expected.append((i, str(exc)))
    T = np.linspace(0, 1, 101)
    with pytest.warns(RuntimeWarning, match="5 of 6 designs were rejected"):
        res = qc.sweep(grid, T, progress=False)
    assert list(zip(res.errors["index"], res.errors["error"])) == expected
    assert res.metrics["error"].ne("").tolist() == [i != 0 for i in range(6)]


def test_tail_bound_from_the_eigenvectors_of_A():
    """Given A's eigenvectors (the sweep's one decomposition), `TailBound` reads
    Φ = R(hA)'s eigenvalues off V⁻¹ Φ V. The reference: the bound from Φ's own
    decomposition, `np.linalg.eig(Φ)`. β = Σ_i |(CV)_ri| |(V⁻¹x)_i| does not
    depend on how the eigenvectors are scaled or ordered, so the two agree to
    rounding amplified by κ(V) (~1e3 for these cars): 1e-9 relative. It still
    bounds every later output (checked on the recurrence for 3000 steps)."""
    rng = np.random.default_rng(5)
    designs = [
        qc.QuarterCarParams(ks=ks, zeta=z) for ks in (1.5e4, 4.5e4) for z in (0.02, 0.3, 1.5)
    ]
    A = np.array([np.asarray(qc.quarter_car(p).A) for p in designs])
    phi = np.array([step_matrices(get_method("rk4"), a, np.zeros((4, 1)), 1e-3)[0] for a in A])
    C = rng.standard_normal((len(designs), 3, 4))
    shared = TailBound(phi, C, vectors=np.linalg.eig(A)[1])
    own = TailBound(phi, C)
    x = rng.standard_normal((len(designs), 4))
    np.testing.assert_allclose(shared(x), own(x), rtol=1e-9)
    beta = shared(x)
    assert np.all(np.isfinite(beta))
    for _ in range(3000):
        assert np.all(np.abs((C @ x[..., None])[..., 0]) <= beta)
        x = (phi @ x[..., None])[..., 0]


def test_free_sweep_of_many_designs_reuses_the_ordering_decomposition(monkeypatch):
    """Past 64 designs a free sweep orders the designs by decay with one
    np.linalg.eig(A) and hands each chunk its eigenvalues (``stable``) and
    eigenvectors (`TailBound`). Its metrics against the whole trajectories
    (states=True, no bound, no decomposition shared): 1e-12 relative
    (regrouped sums of squares), settling time and flags exactly."""
    grid = {
        "ks": [1.5e4, 3e4, 4.5e4],
        "zeta": [0.02, 0.1, 0.3, 0.6, 1.5],
        "mu": [30.0, 45.0, 60.0, 80.0, 100.0],
    }
    T10 = np.linspace(0, 10, 10001)
    whole = sweep(grid, T10, X0, states=True, progress=False).metrics
    given = []  # the chunks' TailBounds got the shared eigenvectors
    init = TailBound.__init__
    monkeypatch.setattr(
        TailBound,
        "__init__",
        lambda self, phi, C, vectors=None: (
            given.append(vectors is not None) or init(self, phi, C, vectors)
        ),
    )
    streamed = sweep(grid, T10, X0, progress=False).metrics
    assert len(streamed) > 64 and given and all(given)
    _assert_default_metrics_equal(streamed, whole)


def _assert_default_metrics_equal(streamed, whole):
    """The default metrics streamed against the materialised ones: 1e-12
    relative (regrouped sums of squares), settling times and flags exactly."""
    for column in DEFAULT_METRICS:
        if column == "settling_time [s]":
            assert (streamed[column] == whole[column]).all()
        else:
            np.testing.assert_allclose(streamed[column], whole[column], rtol=1e-12)
    assert (streamed["stable"] == whole["stable"]).all()


def test_a_free_chunk_is_split_by_the_free_vector_unit():
    """A free sweep of registered metrics computes FREE_VECTOR_DESIGNS (128)
    designs together: a task of 300 designs sent to an executor is split into
    128, 128 and 44, and run here the sweep goes by chunks of 128. The
    reference: the materialised metrics of the whole trajectories
    (states=True, 64 at a time): 1e-12 relative (regrouped sums of squares),
    settling times and flags exactly."""
    from concurrent.futures import ThreadPoolExecutor

    from qc_control.studies.sweeps import FREE_VECTOR_DESIGNS

    grid = {"ks": np.linspace(1.5e4, 4.5e4, 15), "zeta": np.linspace(0.05, 1.2, 20)}
    T2 = np.linspace(0, 3, 3001)
    assert 2 * FREE_VECTOR_DESIGNS < 300
    whole = sweep(grid, T2, X0, states=True, progress=False).metrics
    with ThreadPoolExecutor(1) as pool:
        sent = sweep(grid, T2, X0, executor=pool, chunk_size=300, progress=False).metrics
    here = sweep(grid, T2, X0, progress=False).metrics
    for streamed in (sent, here):
        _assert_default_metrics_equal(streamed, whole)


#: Two front dampers of the half and the full car on a class C road at 20 m/s.
HALF_GRID = {"cs_front": [1000.0, 1800.0]}
HALF_ROAD = road.ISO8608Road("C", speed=20.0)
ISO_METRICS = ["a_w_z", "a_w_rx", "a_w_ry", "a_v"]
#: Each car: its model, its parameters' class, and the rotations it has.
CARS = {
    "half": (qc.half_car_model, qc.HalfCarParams, ("ry",)),
    "full": (qc.full_car_model, qc.FullCarParams, ("rx", "ry")),
}
#: ISO 2631-1's seated comfort factors of the rotations (§8.2): k [m/rad].
K_ROTATION = {"rx": 0.63, "ry": 0.4}


def _a_v(values: dict) -> float:
    """(a_w_z² + Σ (k a_w_r)²)^½, ISO 2631-1:1997 §6.5 written out."""
    rotations = sum((K_ROTATION[a] * values[a]) ** 2 for a in K_ROTATION if a in values)
    return float(np.sqrt(values["z"] ** 2 + rotations))


@pytest.mark.filterwarnings("ignore::qc_control.ride.spectral.IndependentTracksWarning")
@pytest.mark.parametrize("name", CARS)
def test_the_spectral_sweep_gives_iso2631_metrics_as_the_single_design_lyapunov(name):
    """sweep(road=ISO8608Road) without T takes the spectral path: its batched a_w_z,
    a_w_rx, a_w_ry, a_v of each design equal `spectral_axis_rms` of that design alone
    and a_v its formula (ISO 2631-1 §6.5, k of §8.2), to 1e-12 (the same Lyapunov
    equations, batched or not: rounding only); a rotation the car has not is 0."""
    from qc_control.ride.iso2631_spectral import spectral_axis_rms

    build, params, rotations = CARS[name]
    got = sweep(
        HALF_GRID, model=build(road=True), road=HALF_ROAD, metrics=ISO_METRICS, progress=False
    )
    for k, cs in enumerate(HALF_GRID["cs_front"]):
        alone = spectral_axis_rms(
            build(params(cs_front=cs), road=True), HALF_ROAD.intensity, speed=HALF_ROAD.speed
        )
        row = got.metrics.iloc[k]
        assert row["a_w_z [m/s²]"] == pytest.approx(alone["z"], rel=1e-12)
        for axis in ("rx", "ry"):
            value = row[f"a_w_{axis} [rad/s²]"]
            if axis in rotations:
                assert value == pytest.approx(alone[axis], rel=1e-12)
            else:
                assert value == 0.0
        assert row["a_v [m/s²]"] == pytest.approx(_a_v(alone), rel=1e-12)


def test_the_quarter_cars_spectral_a_w_z_is_its_wk_lyapunov_value():
    """On a quarter car a_w_z is the Wk-weighted RMS that the spectral sweep has
    long computed through its own realisation of Wk (`white_velocity_wk_variance`):
    two state spaces of one filter agree to 1e-9 (measured: equal to the last bit)."""
    got = sweep(
        GRID, model=qc.quarter_car_model(road=True), road=HALF_ROAD,
        metrics=["a_w_z", "rms_body_acc_wk", "a_v"], progress=False,
    ).metrics  # fmt: skip
    np.testing.assert_allclose(got["a_w_z [m/s²]"], got["rms_body_acc_wk [m/s²]"], rtol=1e-9)
    np.testing.assert_allclose(got["a_v [m/s²]"], got["a_w_z [m/s²]"], rtol=1e-12)


@pytest.mark.parametrize("name", CARS)
def test_a_sweep_reads_a_cars_pitch_and_roll_for_the_rotation_metrics(name):
    """The simulated sweep passes a half or full car's pitch and roll accelerations
    to a_w_rx, a_w_ry and a_v (refused before): each design against
    `qc.ride_assessment` of python-control's exact response to the same road samples."""
    build, params, rotations = CARS[name]
    car = build(road=True)
    T = np.arange(0.0, 3.0 + 0.0025, 0.005)
    got = sweep(
        HALF_GRID, T, np.zeros(car.system.nstates), model=car, road=HALF_ROAD,
        metrics=ISO_METRICS, progress=False,
    ).metrics  # fmt: skip
    p = car.params
    U, _ = (
        HALF_ROAD.wheel_inputs(T, "axles", wheelbase=p.a + p.b)
        if name == "half"
        else HALF_ROAD.wheel_inputs(T, "corners", wheelbase=p.a + p.b, track=p.track_front)
    )
    for k, cs in enumerate(HALF_GRID["cs_front"]):
        design = build(params(cs_front=cs), road=True)
        exact = qc.ride_assessment(control.forced_response(design.system, T, U), model=design)
        row = got.iloc[k]
        # RK4 at 5 ms against the exact response: the wheel hop (about 10 Hz, ωh 0.3)
        # errs by at most 1.6e-4 in a_w_z, 6e-5 in a rotation (measured); 1e-3 holds it
        assert row["a_w_z [m/s²]"] == pytest.approx(exact["z"].a_w, rel=1e-3)
        for axis in ("rx", "ry"):
            value = row[f"a_w_{axis} [rad/s²]"]
            expected = exact[axis].a_w if axis in rotations else 0.0
            assert value == pytest.approx(expected, rel=1e-3)
        assert row["a_v [m/s²]"] == pytest.approx(exact.a_v, rel=1e-3)


@pytest.mark.filterwarnings("ignore::qc_control.ride.spectral.IndependentTracksWarning")
@pytest.mark.parametrize("name", CARS)
def test_the_spectral_sweep_delays_each_design_by_its_own_wheelbase(name):
    """Designs of different wheelbases in one batch: each design's rear wheels meet
    the road (a + b)/speed after the front ones, its own a + b: the batched values
    equal the single design's to 1e-12 (rounding only), and differ from the
    independent tracks' (which a shared delay, or none, would give)."""
    from qc_control.ride.iso2631_spectral import spectral_axis_rms

    build, params, _ = CARS[name]
    grid = {"a": [0.9, 1.1, 1.5]}
    got = sweep(grid, model=build(road=True), road=HALF_ROAD, metrics=ISO_METRICS, progress=False)
    for k, a in enumerate(grid["a"]):
        car = build(params(a=a), road=True)
        alone = spectral_axis_rms(car, HALF_ROAD.intensity, speed=HALF_ROAD.speed)
        independent = spectral_axis_rms(car, HALF_ROAD.intensity)
        value = got.metrics.iloc[k]["a_w_ry [rad/s²]"]
        assert value == pytest.approx(alone["ry"], rel=1e-12)
        assert abs(value / independent["ry"] - 1) > 0.05
