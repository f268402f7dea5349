"""ISO 2631-1's metrics by name in the controller comparison.

Reference: each linear design simulated here by python-control's exact
response (``control.forced_response``, the zero-order-hold discretisation of
the loop, on the same road and bump samples), assessed by
`qc.ride_assessment` (the per-axis assessment, itself held to Annex A and
the sine closed forms in its own tests). The comparison runs the loop
through the LTI engine, RK4 substepped to h|λ| <= 0.1, whose difference
from the exact response is below 1e-7 relative on these metrics (measured:
at most 7e-8 over a_w, a_v, VDV, MTVV and MSDV of both designs): 1e-6
relative bounds it tenfold.
"""

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control.ride import road
from qc_control.ride.iso2631_spectral import spectral_axis_rms
from qc_control.studies.control_study import (
    BUMP_METRICS,
    DEFAULT_BUMP,
    ISO2631_METRICS,
    ROAD_METRICS,
    compare_controllers,
)

P = qc.QuarterCarParams()
RUN = 3.0  # [s], each run: over the 1 s running-RMS window of the MTVV (§6.3.1)
DESIGNS = ["passive (seed)", "skyhook", "skyhook semi-active"]


def linear_designs():
    car = qc.quarter_car_model(P, road=True, actuator=True)
    return {
        "passive (seed)": qc.quarter_car_model(P, road=True),
        "skyhook": qc.closed_loop(car, qc.skyhook(3000.0)),  # the comparison's c_sky
    }


@pytest.fixture(scope="module")
def cmp():
    return compare_controllers(
        P,
        designs=DESIGNS,
        road_duration=RUN,
        bump_duration=RUN,
        freqs_hz=[1.0],
        road_metrics=ROAD_METRICS + ISO2631_METRICS,
        bump_metrics=BUMP_METRICS + ("vdv", "mtvv"),
    )


def assessed(model, T, U):
    """ISO 2631-1's values of the exact response, by the comparison's column names."""
    a = qc.ride_assessment(control.forced_response(model.system, T, U), model=model)
    return {
        "a_w_z [m/s²]": a["z"].a_w,
        "a_v [m/s²]": a.a_v,
        "vdv [m/s^1.75]": a["z"].vdv,
        "mtvv [m/s²]": a["z"].mtvv,
        "msdv [m/s^1.5]": a.msdv,
    }


@pytest.mark.parametrize("design", sorted(linear_designs()))
def test_the_road_run_gives_the_assessment_of_the_exact_response(cmp, design):
    T = np.arange(0.0, RUN + 0.0025, 0.005)  # the road run's 5 ms grid
    expected = assessed(linear_designs()[design], T, road.iso8608(T, "C", speed=20.0, seed=0))
    for column, value in expected.items():
        assert cmp.table.loc[design, f"road: {column}"] == pytest.approx(value, rel=1e-6), column


def test_the_bump_run_gives_vdv_and_mtvv_of_the_exact_response(cmp):
    T = np.arange(0.0, RUN + 0.001, 0.002)  # the bump run's 2 ms grid
    expected = assessed(linear_designs()["passive (seed)"], T, DEFAULT_BUMP.samples(T))
    for column in ("vdv [m/s^1.75]", "mtvv [m/s²]"):
        got = cmp.table.loc["passive (seed)", f"bump: {column}"]
        assert got == pytest.approx(expected[column], rel=1e-6), column


def test_every_design_has_the_columns_and_the_defaults_stay(cmp):
    columns = [f"road: {m}" for m in ("a_w_z [m/s²]", "vdv [m/s^1.75]", "msdv [m/s^1.5]")]
    assert np.isfinite(cmp.table[columns].to_numpy()).all()  # the semi-active row too
    # a quarter car neither pitches nor rolls: a_v is its vertical (§6.5, k_z = 1)
    assert (cmp.table["road: a_v [m/s²]"] == cmp.table["road: a_w_z [m/s²]"]).all()
    # the default columns are still there, and the Wk RMS is ISO's a_w_z
    assert "road: rms_body_acc_wk [m/s²]" in cmp.table.columns
    assert (cmp.table["road: rms_body_acc_wk [m/s²]"] == cmp.table["road: a_w_z [m/s²]"]).all()


def test_the_exact_table_gains_the_iso_metrics_asked_for(cmp):
    """The linear loops' stationary a_w_z against `spectral_axis_rms` of the loop built
    here (1e-9 relative: the same Lyapunov equation, rounding only); a_v is a_w_z on a
    car that neither pitches nor rolls (§6.5, k_z = 1)."""
    q = qc.road.ISO8608Road("C", speed=20.0).intensity
    for design, model in linear_designs().items():
        a_w = spectral_axis_rms(model, q)["z"]
        assert cmp.exact.loc[design, "a_w_z [m/s²]"] == pytest.approx(a_w, rel=1e-9)
        assert cmp.exact.loc[design, "a_v [m/s²]"] == pytest.approx(a_w, rel=1e-9)


def test_without_road_metrics_the_columns_are_the_defaults():
    one = compare_controllers(P, designs=["passive (seed)"], road_duration=1.0, bump_duration=1.0)
    names = [c.split(": ", 1)[1].split(" [")[0] for c in one.table.columns]
    assert names[: len(BUMP_METRICS) + len(ROAD_METRICS)] == [*BUMP_METRICS, *ROAD_METRICS]
    assert "a_w_z [m/s²]" not in one.exact.columns


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"road_metrics": ("a_w_z", "a_w_q")}, "road_metrics"),
        ({"bump_metrics": ("vdv", "crest")}, "bump_metrics"),
        ({"road_metrics": "a_w_z"}, "road_metrics"),
    ],
)
def test_a_bad_metric_is_refused_naming_the_argument(kwargs, name):
    with pytest.raises(qc.ParameterError) as err:
        compare_controllers(designs=["passive (seed)"], **kwargs)
    assert err.value.name == name and err.value.value == kwargs[name]
    assert repr(kwargs[name]) in str(err.value) and "mtvv" in str(err.value)
