"""One road object through every API that takes a road (issue 38, item 2).

Reference: the older form of each call (the road's samples as ``U`` with
their description, a plain function of time, an intensity or a
``(class, speed)`` pair, flat keywords), which every API still takes. The
road object must give the same result to the bit (``np.array_equal``,
``DataFrame.equals``: no tolerance), since it is the same numbers reaching
the same code; the older forms must warn naming the new one. Where the older
form is samples (``U``), it stays a form of its own (any input, not only a
road) and does not warn.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import qc_control as qc
from qc_control import road
from qc_control.studies.damping import spectral_ride

T = np.linspace(0.0, 2.0, 201)
X0 = np.zeros(4)
STEP = road.Step(height=0.05, t0=0.5)
BUMP = road.Bump(height=0.05, length=1.0, speed=10.0, t0=0.3)


def test_compare_methods_on_a_road_is_the_comparison_on_its_samples():
    p = qc.QuarterCarParams()
    on_road = qc.compare_methods(p, T, X0, road=STEP, methods=["heun", "rk4"], timing=False)
    U, words = STEP.wheel_inputs(T)
    sampled = qc.compare_methods(
        qc.quarter_car_model(p, road=True),
        T,
        X0,
        U=U,
        input_description=words,
        methods=["heun", "rk4"],
        timing=False,
    )
    assert on_road.input_description == sampled.input_description == words
    assert on_road.table["max |xs err| [m]"].equals(sampled.table["max |xs err| [m]"])
    for name, response in on_road.responses.items():
        assert np.array_equal(response.states, sampled.responses[name].states)


def test_compare_methods_half_car_road_reaches_the_rear_a_wheelbase_later():
    p = qc.HalfCarParams()
    on_road = qc.compare_methods(p, T, np.zeros(8), road=BUMP, methods=["rk4"], timing=False)
    U, words = BUMP.wheel_inputs(T, "axles", wheelbase=p.a + p.b)
    sampled = qc.compare_methods(
        qc.half_car_model(p, road=True),
        T,
        np.zeros(8),
        U=U,
        input_description=words,
        methods=["rk4"],
        timing=False,
    )
    assert np.array_equal(on_road.responses["rk4"].states, sampled.responses["rk4"].states)


def test_a_road_with_its_samples_as_well_is_refused_by_name():
    with pytest.raises(qc.ParameterError, match="road") as err:
        qc.compare_methods(None, T, X0, road=STEP, U=STEP.samples(T))
    assert err.value.name == "road"


# ----------------------------------------------------------------- sweep(road=)

DESIGNS = {"ks": [20e3, 30e3], "cs": [1000.0, 2500.0]}


@pytest.mark.parametrize(
    "the_road",
    [STEP, BUMP, road.Sine(amplitude=0.01, frequency=1.5), road.ISO8608Road("D", speed=15.0)],
    ids=["step", "bump", "sine", "iso8608"],
)
def test_sweep_on_a_road_is_the_sweep_on_its_samples(the_road):
    on_road = qc.sweep(DESIGNS, T, X0, road=the_road, states=True)
    sampled = qc.sweep(DESIGNS, T, X0, U=the_road.samples(T), states=True)
    assert on_road.metrics.equals(sampled.metrics)
    assert np.array_equal(on_road.states, sampled.states)
    assert on_road.road == the_road and sampled.road is None
    # the streamed metrics (no states kept) too
    assert qc.sweep(DESIGNS, T, X0, road=the_road).metrics.equals(
        qc.sweep(DESIGNS, T, X0, U=the_road.samples(T)).metrics
    )


@pytest.mark.parametrize("kind", ["half", "full"])
def test_sweep_of_a_car_on_axles_reaches_the_rear_a_wheelbase_later(kind):
    p = qc.HalfCarParams() if kind == "half" else qc.FullCarParams()
    model = p.model(road=True)
    iso = road.ISO8608Road("C", speed=10.0, seed=4)
    designs = {"cs_front": [1000.0, 2000.0]}
    X = np.zeros(model.system.nstates)
    on_road = qc.sweep(designs, T, X, road=iso, model=model)
    if kind == "half":
        U, _ = iso.wheel_inputs(T, "axles", wheelbase=p.a + p.b)
    else:  # two tracks of one isotropic road, the rear a wheelbase later
        U, _ = iso.wheel_inputs(T, "corners", wheelbase=p.a + p.b, track=p.track_front)
    sampled = qc.sweep(designs, T, X, U=U, model=model)
    assert on_road.metrics.equals(sampled.metrics)


def test_sweep_of_the_nonlinear_car_on_a_road_is_the_sweep_on_its_samples():
    model = qc.nonlinear_quarter_car_model(road=True)
    designs = {"cs": [1000.0, 2000.0]}
    on_road = qc.sweep(designs, T, X0, road=BUMP, model=model)
    assert on_road.metrics.equals(qc.sweep(designs, T, X0, U=BUMP.samples(T), model=model).metrics)


def test_a_sweep_on_no_road_is_the_free_sweep():
    assert qc.sweep(DESIGNS, T, road=road.NoRoad()).metrics.equals(qc.sweep(DESIGNS, T).metrics)


def test_a_sweep_refuses_a_road_beside_its_samples_or_a_car_without_road_input_by_name():
    with pytest.raises(qc.ParameterError, match="road") as err:
        qc.sweep(DESIGNS, T, X0, U=STEP.samples(T), road=STEP)
    assert err.value.name == "road"
    with pytest.raises(qc.ParameterError, match="a model with road inputs") as err:
        qc.sweep(DESIGNS, T, X0, road=STEP, model=qc.quarter_car_model())
    assert err.value.name == "model"


# ------------------------------------------- the spectral studies: road=ISO8608Road

C20 = road.ISO8608Road("C", speed=20.0)
OLD_C20 = re.escape("road=qc.road.ISO8608Road('C', speed=20.0)")


def test_spectral_ride_on_an_iso_road_is_the_older_pair_and_its_intensity():
    model = qc.quarter_car_model(road=True)
    new = spectral_ride(model, C20, wk=True)
    with pytest.warns(DeprecationWarning, match=OLD_C20):
        old = spectral_ride(model, ("C", 20.0), wk=True)
    assert new.equals(old)
    # the documented intensity q [m²/s] is the same number and stays without a warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        q = spectral_ride(model, road.iso8608_intensity("C", 20.0), wk=True)
    assert new.equals(q)


def test_optimal_damping_on_an_iso_road_is_the_older_pair():
    for objective, limit in (("comfort", None), ("comfort_wk", None), ("road_holding", 0.02)):
        new = qc.optimal_damping(None, objective, road=C20, travel_limit=limit, sigmas=3)
        with pytest.warns(DeprecationWarning, match=OLD_C20):
            old = qc.optimal_damping(
                None, objective, road=("C", 20.0), travel_limit=limit, sigmas=3
            )
        assert (new.cs, new.value, new.method) == (old.cs, old.value, old.method), objective
        assert new.metrics.equals(old.metrics)


def test_pareto_front_on_an_iso_road_is_the_older_pair_and_warns_once():
    vary = {"cs": [800.0, 1500.0, 3000.0, 6000.0], "ks": [2e4, 4e4]}
    new = qc.pareto_front(None, vary, road=road.ISO8608Road("E", speed=10.0), travel_limit=0.1)
    with pytest.warns(DeprecationWarning) as caught:
        old = qc.pareto_front(None, vary, road=("E", 10.0), travel_limit=0.1)
    spelled = "road=qc.road.ISO8608Road('E', speed=10.0)"
    assert [str(w.message).count(spelled) for w in caught] == [1]  # one warning, read once
    assert new.all_designs.equals(old.all_designs)
    assert new.markers.equals(old.markers)


def test_the_spectral_road_is_refused_by_name_when_it_is_not_one():
    with pytest.raises(qc.ParameterError, match="an ISO8608Road") as err:
        qc.optimal_damping(road=STEP)  # a step has no stationary spectrum
    assert err.value.name == "road"
    with pytest.raises(qc.ParameterError) as err:
        qc.optimal_damping(road=-1.0)
    assert err.value.name == "road"
    with pytest.raises(qc.ParameterError) as err:
        qc.optimal_damping(road=("Q", 20.0))  # the pair's class, refused before any warning
    assert err.value.name == "road_class"


@pytest.mark.parametrize("exact", [False, True])
def test_ride_metrics_spectral_on_an_iso_road_is_the_older_arguments(exact):
    iso = road.ISO8608Road("D", speed=25.0, band=(0.02, 2.0))
    new = qc.ride_metrics_spectral(None, iso, exact=exact)
    spelled = re.escape("road=qc.road.ISO8608Road('D', speed=25.0, band=(0.02, 2.0))")
    with pytest.warns(DeprecationWarning, match=spelled):
        positional = qc.ride_metrics_spectral(None, "D", 25.0, (0.02, 2.0), exact=exact)
    with pytest.warns(DeprecationWarning, match=spelled):
        named = qc.ride_metrics_spectral(
            None, road_class="D", speed=25.0, band=(0.02, 2.0), exact=exact
        )
    assert new.equals(positional) and new.equals(named)
    assert new.attrs == positional.attrs
    with pytest.raises(qc.ParameterError) as err:
        qc.ride_metrics_spectral(None, iso, 25.0)  # the speed twice
    assert err.value.name == "speed"
    with pytest.raises(qc.ParameterError, match="ISO8608Road") as err:
        qc.ride_metrics_spectral(None, BUMP)
    assert err.value.name == "road"


def test_ride_metrics_spectral_default_is_the_default_road_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        default = qc.ride_metrics_spectral()
    assert default.equals(qc.ride_metrics_spectral(None, C20))


# ------------------------------------------------ compare_controllers(road=, bump=)

FEW = ["passive (seed)", "passive optimum", "skyhook"]
SHORT = {"road_duration": 1.0, "bump_duration": 1.0, "freqs_hz": [0.5, 2.0, 8.0]}


def test_compare_controllers_on_road_objects_is_the_older_keywords():
    iso = road.ISO8608Road("D", speed=15.0, seed=3)
    bump = road.Bump(height=0.03, length=1.0, speed=10.0, t0=0.5)
    new = qc.compare_controllers(designs=FEW, road=iso, bump=bump, **SHORT)
    with pytest.warns(DeprecationWarning) as caught:
        old = qc.compare_controllers(
            designs=FEW, road_class="D", speed=15.0, road_seed=3, bump_height=0.03, **SHORT
        )
    text = " ".join(str(w.message) for w in caught)
    assert "road=qc.road.ISO8608Road('D', speed=15.0, seed=3)" in text
    assert "bump=qc.road.Bump(height=0.03, length=1.0, speed=10.0)" in text
    assert new.table.equals(old.table)
    assert new.exact.equals(old.exact)
    assert new.pareto.markers.equals(old.pareto.markers)
    assert (new.bump, new.road) == (old.bump, old.road)
    # what the older keywords meant: the road's samples, bit for bit
    T_road = np.arange(0.0, 1.0 + 0.0025, 0.005)
    assert np.array_equal(iso.samples(T_road), road.iso8608(T_road, "D", speed=15.0, seed=3))


def test_compare_controllers_defaults_are_road_objects_and_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        default = qc.compare_controllers(designs=FEW[:1], **SHORT)
    assert default.road == {"road_class": "C", "speed": 20.0, "duration": 1.0, "seed": 0}
    assert default.bump["height"] == 0.05 and default.bump["speed"] == 10.0
    assert default.table.equals(
        qc.compare_controllers(
            designs=FEW[:1],
            road=road.ISO8608Road("C", speed=20.0),
            bump=road.Bump(height=0.05, length=1.0, speed=10.0, t0=0.5),
            **SHORT,
        ).table
    )


def test_compare_controllers_refuses_mixed_or_wrong_roads_by_name():
    with pytest.raises(qc.ParameterError) as err:
        qc.compare_controllers(designs=FEW[:1], road=road.ISO8608Road("D"), speed=20.0)
    assert err.value.name == "speed"
    with pytest.raises(qc.ParameterError) as err:
        qc.compare_controllers(designs=FEW[:1], road=STEP)
    assert err.value.name == "road"
    with pytest.raises(qc.ParameterError) as err:
        qc.compare_controllers(designs=FEW[:1], bump=STEP)
    assert err.value.name == "bump"
