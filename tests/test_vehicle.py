"""The model description: roles by label, units, rebuild and batch, checked
against the quarter car assembled independently from its equations."""

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control.models.quarter import UNITS, quarter_car_abcd
from qc_control.models.vehicle import (
    STANDARD_GRAVITY,
    Corner,
    SignalRoles,
    VehicleModel,
    stack_models,
)


def test_quarter_car_model_roles_and_units():
    p = qc.QuarterCarParams(ms=350.0, mu=45.0, ks=25e3, ku=2e5, zeta=0.3)
    m = qc.quarter_car_model(p, road=True, actuator=True)
    assert m.system.input_labels == ["zr", "fa"]
    assert (m.body_acc, m.body_disp) == ("body_acc", "xs")
    (corner,) = m.corners
    assert (corner.susp_travel, corner.tire_defl, corner.road) == ("susp_travel", "tire_defl", "zr")
    assert corner.tire_stiffness == 2e5
    # static wheel load (ms + mu) g with standard gravity 9.80665 m/s² (ISO 80000-3)
    assert corner.static_load == pytest.approx((350.0 + 45.0) * 9.80665, rel=1e-15)
    assert STANDARD_GRAVITY == 9.80665
    assert m.unit("body_acc") == "m/s²" and m.unit("fa") == "N" and m.unit("vs") == "m/s"
    assert m.road_inputs() == ["zr"] and m.output("tire_defl") == 3
    assert m.params is p


def test_body_acc_row_is_the_equation_of_motion():
    """body_acc = (-cs(vs-vu) - ks(xs-xu) + fa)/ms, written out here from the
    seed's equations (section 4.1), for a random state and input."""
    p = qc.QuarterCarParams(ms=320.0, mu=40.0, ks=2.2e4, ku=1.9e5, cs=1700.0)
    sys = qc.quarter_car_model(p, road=True, actuator=True).system
    rng = np.random.default_rng(3)
    x, u = rng.normal(size=4), rng.normal(size=2)
    vs, vu, xs, xu = x
    zr, fa = u
    y = np.asarray(sys.C) @ x + np.asarray(sys.D) @ u
    acc = (-p.cs * (vs - vu) - p.ks * (xs - xu) + fa) / p.ms
    expected = [xs, xu, xs - xu, xu - zr, acc]
    np.testing.assert_allclose(y, expected, rtol=1e-13, atol=1e-15)


def test_batch_equals_one_rebuild_per_design():
    model = qc.quarter_car_model(road=True)
    designs = [qc.QuarterCarParams(ks=k, zeta=z) for k in (2e4, 4e4) for z in (0.1, 0.7)]
    batch = model.batch(designs)
    for i, d in enumerate(designs):
        single = model.rebuild(d)
        for name in "ABCD":
            np.testing.assert_array_equal(getattr(batch, name)[i], getattr(single.system, name))
        assert batch.tire_stiffness[0][i] == single.corners[0].tire_stiffness
        assert batch.static_load[0][i] == single.corners[0].static_load
    # the vectorised assembly agrees with the generic one (stack of rebuilds)
    generic = stack_models([model.rebuild(d) for d in designs])
    np.testing.assert_array_equal(generic.A, batch.A)
    A, B, C, D = quarter_car_abcd(301.2, 100.0, 3e4, 29530.0, 1500.0, road=True)
    assert A.shape == (4, 4) and B.shape == (4, 1) and C.shape == (5, 4) and D.shape == (5, 1)


def test_a_model_with_a_missing_role_is_refused():
    sys = qc.quarter_car(road=True)
    roles = SignalRoles("body_acc", "xs", (Corner("", "travel", "tire_defl", "zr", 1.0, 1.0),))
    with pytest.raises(ValueError, match="'travel' is not an output"):
        VehicleModel(sys, None, UNITS, roles, lambda p: None)
    roles = SignalRoles("body_acc", "xs", (Corner("", "susp_travel", "tire_defl", "z", 1.0, 1.0),))
    with pytest.raises(ValueError, match="road input 'z'"):
        VehicleModel(sys, None, UNITS, roles, lambda p: None)
    with pytest.raises(ValueError, match="no unit for"):
        VehicleModel(sys, None, {}, SignalRoles("body_acc", "xs", ()), lambda p: None)
    with pytest.raises(ValueError, match="has no output 'seat_acc'"):
        qc.quarter_car_model().output("seat_acc")


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        (dict(ms=None), r"ms \(sprung mass\) must be a finite number > 0 kg, got None"),
        (dict(ku=None), r"ku \(tire stiffness\) must be a finite number > 0 N/m, got None"),
        (dict(ms=1e-300, ks=1e300), r"ks/ms overflows"),
        (dict(ms=1e200, ks=1e200), r"time scales span more than 1e\+07: cs/mu = 5e\+197"),
        (dict(mu=1e-300, ku=1e300), r"overflows"),
    ],
)
def test_params_that_cannot_make_a_finite_model_are_refused(kwargs, words):
    with pytest.raises(ValueError, match=words):
        qc.QuarterCarParams(**kwargs)


def test_huge_but_consistent_params_give_a_finite_model():
    """ms = ks = 1e200 with mu, ku and cs to scale: 2·√(ks·ms) would overflow,
    2·√ks·√ms does not; the body mode is √(ks/ms) = 1 rad/s on a stiff tire,
    as control.damp finds (1e-6: the tire is 1e4 times the spring)."""
    p = qc.QuarterCarParams(ms=1e200, ks=1e200, mu=1e199, ku=1e204, zeta=0.0)
    assert np.isfinite(p.cs)
    wn, _, _ = control.damp(qc.quarter_car(p), doprint=False)
    assert min(wn) == pytest.approx(1.0, rel=1e-4)


def test_params_system_property_is_the_plain_quarter_car():
    p = qc.QuarterCarParams(zeta=0.4)
    np.testing.assert_array_equal(p.system.A, qc.quarter_car(p).A)
    assert p.system.ninputs == 0
