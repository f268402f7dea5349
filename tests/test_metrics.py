"""One metric registry: ride_metrics and sweep share names and numbers."""

import numpy as np
import pandas as pd
import pytest

import qc_control as qc
from qc_control.models.vehicle import Corner, SignalRoles
from qc_control.ride import road
from qc_control.ride.metrics import METRICS, RIDE_METRICS, RideSignals, evaluate, metric_columns

T = np.linspace(0, 4, 2001)  # h = 2 ms


def test_every_metric_has_one_spelling_with_its_unit():
    names = [m.name for m in METRICS.values()]
    assert len(set(names)) == len(names)
    for m in METRICS.values():
        assert m.name == m.name.strip() and " [" not in m.name
        assert m.column().startswith(m.name)
    assert METRICS["rms_body_acc"].column() == "rms_body_acc [m/s²]"
    assert METRICS["lift_off"].column() == "lift_off"


def test_ride_metrics_and_sweep_agree_column_for_column():
    """The same RK4 trajectory two ways (LTI engine in the sweep, the generic
    stepper here): equal to rounding, so every metric equal to 1e-9 relative."""
    designs = [qc.QuarterCarParams(), qc.QuarterCarParams(ks=45e3, zeta=0.5, mu=60.0)]
    zr = road.bump(T, height=0.08, length=0.5, speed=20.0, t0=0.5)
    swept = qc.sweep(designs, T, np.zeros(4), U=zr, metrics=list(METRICS), progress=False)
    for i, p in enumerate(designs):
        resp = qc.forced_response(
            qc.quarter_car(p, road=True), T, zr, method="rk4", engine="generic"
        )
        single = qc.ride_metrics(resp, p, metrics=list(METRICS))
        for column, value in single.items():
            assert column in swept.metrics.columns
            assert float(swept.metrics.loc[i, column]) == pytest.approx(
                float(value), rel=1e-9, abs=1e-12
            )
    # the default ride columns are a subset of what a sweep can give
    assert set(qc.ride_metrics(resp, p).index) <= set(swept.metrics.columns)


def test_metrics_by_name_or_column_and_unknown_names():
    roles = qc.quarter_car_model(road=True).roles
    by_name = metric_columns(["rms_body_acc"], roles)
    by_column = metric_columns(["rms_body_acc [m/s²]"], roles)
    assert by_name == by_column
    with pytest.raises(ValueError, match="unknown metric 'comfort'; known: rms_body_acc"):
        metric_columns(["comfort"], roles)


def test_a_wheel_metric_is_evaluated_at_every_corner():
    """Two corners (a half car's axles): one column per corner, named after it,
    each computed from its own signals (peak |travel| by hand)."""
    roles = SignalRoles(
        "acc",
        "z",
        (
            Corner("front", "travel_f", "tire_f", None, 2e5, 3000.0),
            Corner("rear", "travel_r", "tire_r", None, 1e5, 2000.0),
        ),
    )
    rng = np.random.default_rng(0)
    outputs = {
        k: rng.normal(size=(3, 101))
        for k in ("acc", "z", "travel_f", "tire_f", "travel_r", "tire_r")
    }
    values = evaluate(
        RideSignals(np.linspace(0, 1, 101), outputs, roles), ["peak_susp_travel", "rms_body_acc"]
    )
    assert list(values) == [
        "peak_susp_travel front [m]",
        "peak_susp_travel rear [m]",
        "rms_body_acc [m/s²]",
    ]
    np.testing.assert_array_equal(
        values["peak_susp_travel rear [m]"], np.abs(outputs["travel_r"]).max(axis=1)
    )


def test_ride_metrics_series_types():
    resp = qc.forced_response(qc.quarter_car(road=True), T, road.step(T))
    m = qc.ride_metrics(resp)
    assert list(m.index) == [METRICS[n].column() for n in RIDE_METRICS]
    assert isinstance(m["lift_off"], bool) and isinstance(m["rms_body_acc [m/s²]"], float)
    assert isinstance(m, pd.Series)
