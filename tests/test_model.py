"""QuarterCarParams and quarter_car against the seed paper and closed forms."""

import dataclasses
import math

import control
import numpy as np
import pytest
from conftest import valid_params
from hypothesis import given, settings
from hypothesis import strategies as st

import qc_control as qc
from qc_control import QuarterCarParams, load_config, quarter_car

SEED = dict(ms=301.2, mu=100.0, ks=30000.0, ku=29530.0)


def seed_A(ms, mu, ks, ku, cs):
    """The seed's matrix A, section 4.2, typed in from the paper."""
    return np.array(
        [
            [-cs / ms, cs / ms, -ks / ms, ks / ms],
            [cs / mu, -cs / mu, ks / mu, -(ks + ku) / mu],
            [1, 0, 0, 0],
            [0, 1, 0, 0],
        ],
        dtype=float,
    )


def test_defaults_are_the_seed_table():
    p = QuarterCarParams()
    assert (p.ms, p.mu, p.ks, p.ku, p.zeta) == (301.2, 100.0, 30000.0, 29530.0, 0.25)
    # Table 1: cs = 2*sqrt(ks*ms)*zeta = 1502.997 N s/m (to the mm/s the issue quotes)
    assert p.cs == pytest.approx(2 * math.sqrt(30000 * 301.2) * 0.25, rel=1e-15)
    assert round(p.cs, 3) == 1502.997


def test_cs_given_is_kept_and_zeta_follows():
    p = QuarterCarParams(cs=1000.0)
    assert p.cs == 1000.0
    assert p.zeta == pytest.approx(1000.0 / (2 * math.sqrt(30000 * 301.2)), rel=1e-15)


def test_params_are_immutable():
    with pytest.raises(dataclasses.FrozenInstanceError):
        QuarterCarParams().ms = 1.0


@pytest.mark.parametrize("field", ["ms", "mu", "ks", "ku"])
@pytest.mark.parametrize("value", [0.0, -1.0, math.nan, math.inf])
def test_bad_mass_or_stiffness_names_field_and_value(field, value):
    with pytest.raises(ValueError) as err:
        QuarterCarParams(**{field: value})
    assert field in str(err.value) and repr(value) in str(err.value)


@pytest.mark.parametrize("field", ["zeta", "cs"])
@pytest.mark.parametrize("value", [-0.1, math.nan, -math.inf])
def test_bad_damping_names_field_and_value(field, value):
    with pytest.raises(ValueError) as err:
        QuarterCarParams(**{field: value})
    assert field in str(err.value) and repr(value) in str(err.value)


def test_non_number_is_rejected():
    # a string is not a number: the one checker's words, naming the field and the value
    match = r"ms \(sprung mass\) must be a finite number > 0 kg, got '300'"
    with pytest.raises(qc.ParameterError, match=match):
        QuarterCarParams(ms="300")


def test_zero_damping_is_allowed():
    assert QuarterCarParams(zeta=0.0).cs == 0.0


def test_inconsistent_zeta_and_cs():
    with pytest.raises(ValueError, match="cs=100.0 and zeta=0.3 disagree"):
        QuarterCarParams(zeta=0.3, cs=100.0)


def test_unknown_key_in_dict_is_named():
    words = r"kt \(unknown parameter\) must be a parameter of QuarterCarParams: one of \['cs'"
    with pytest.raises(qc.ParameterError, match=words) as info:
        QuarterCarParams.from_mapping({"ms": 300.0, "kt": 1.0})
    assert info.value.name == "kt"  # what a command line points at


def test_toml_config(tmp_path):
    path = tmp_path / "car.toml"
    path.write_text("ms = 350.0\nzeta = 0.3\n[scenario]\nh = 0.005\n")
    params, scenario = load_config(path)
    assert params == QuarterCarParams(ms=350.0, zeta=0.3)
    assert scenario == {"h": 0.005}


def test_toml_unknown_key_is_named(tmp_path):
    path = tmp_path / "car.toml"
    path.write_text("ms = 350.0\nspring = 3\n")
    with pytest.raises(ValueError, match=r"spring \(unknown parameter\) .* got 'spring'"):
        load_config(path)


def test_toml_bad_value_names_file_and_field(tmp_path):
    path = tmp_path / "car.toml"
    path.write_text("mu = -5.0\n")
    with pytest.raises(
        ValueError, match=r"car.toml.*mu .* must be a finite number > 0 kg, got -5.0"
    ):
        load_config(path)


def test_A_is_the_seed_matrix_exactly():
    p = QuarterCarParams()
    sys = quarter_car(p)
    np.testing.assert_array_equal(sys.A, seed_A(p.ms, p.mu, p.ks, p.ku, p.cs))
    assert sys.state_labels == ["vs", "vu", "xs", "xu"]
    assert sys.output_labels == ["xs", "xu", "susp_travel", "tire_defl", "body_acc"]
    assert sys.ninputs == 0 and sys.name
    assert control.isctime(sys, strict=True)


@pytest.mark.parametrize(
    "road, actuator, labels",
    [(False, False, []), (True, False, ["zr"]), (False, True, ["fa"]), (True, True, ["zr", "fa"])],
)
def test_inputs(road, actuator, labels):
    p = QuarterCarParams()
    sys = quarter_car(p, road=road, actuator=actuator)
    assert sys.input_labels == labels
    columns = {"zr": [0, p.ku / p.mu, 0, 0], "fa": [1 / p.ms, -1 / p.mu, 0, 0]}
    for j, name in enumerate(labels):
        np.testing.assert_allclose(np.asarray(sys.B)[:, j], columns[name], rtol=0, atol=0)


def test_outputs_by_hand():
    """susp_travel = xs - xu, tire_defl = xu - zr, at a chosen state and input."""
    sys = quarter_car(road=True, actuator=True)
    x = np.array([0.3, -0.2, 0.05, 0.01])
    u = np.array([0.02, 150.0])
    y = np.asarray(sys.C) @ x + np.asarray(sys.D) @ u
    assert y[0] == 0.05 and y[1] == 0.01
    assert y[2] == pytest.approx(0.04, abs=1e-15)
    assert y[3] == pytest.approx(0.01 - 0.02, abs=1e-15)


@settings(max_examples=60, deadline=None)
@given(valid_params, st.lists(st.floats(-1, 1), min_size=6, max_size=6))
def test_body_acc_is_first_row_of_dynamics(params, values):
    sys = quarter_car(params, road=True, actuator=True)
    x, u = np.array(values[:4]), np.array([values[4] * 0.1, values[5] * 1e3])
    dx = np.asarray(sys.A) @ x + np.asarray(sys.B) @ u
    y = np.asarray(sys.C) @ x + np.asarray(sys.D) @ u
    # Newton's law for the body, written independently of A:
    force = -params.cs * (x[0] - x[1]) - params.ks * (x[2] - x[3]) + u[1]
    assert y[4] == pytest.approx(dx[0], rel=1e-12, abs=1e-9)
    assert y[4] == pytest.approx(force / params.ms, rel=1e-9, abs=1e-9)


def test_static_gain_road_to_body_is_one():
    # At rest on a raised road both masses rise by the road height.
    gain = control.dcgain(quarter_car(road=True))
    np.testing.assert_allclose(gain[:4, 0], [1, 1, 0, 0], atol=1e-12)
    assert abs(gain[4, 0]) < 1e-12


@pytest.mark.slow  # control.bode_plot draws a figure: 1.3-3.9 s measured
def test_works_with_python_control_functions():
    sys = quarter_car(road=True)
    T = np.linspace(0, 2, 201)
    resp = control.initial_response(sys, T, [0, 0, 0.05, 0])
    assert resp.outputs.shape == (5, 201)
    assert control.forced_response(sys, T, np.full(201, 0.01)).outputs.shape == (5, 201)
    wn, zeta, _ = control.damp(sys, doprint=False)
    assert len(wn) == 4
    fr = control.frequency_response(sys, np.logspace(-1, 2, 20))
    assert fr.magnitude.shape == (5, 1, 20)
    assert control.bode_plot(fr) is not None


def _one_by_one(d):
    try:
        return QuarterCarParams.from_mapping(d)
    except ValueError as exc:
        return str(exc)


@pytest.mark.parametrize(
    "designs",
    [
        # ks and zeta: good, at the edges, and every way to be refused
        [{"ks": ks, "zeta": z} for ks in (3e4, 1e-3, 0.0, -1.0, np.inf, 1e305, np.nan)
         for z in (0.0, 0.3, -0.1, np.nan, 1e300)],
        # cs given alone, and with zeta (agreeing to 1e-9 relative or not)
        [{"ks": 3e4, "cs": c} for c in (0.0, 1500.0, -1.0, 1e200, 1e9)],
        [{"ms": 301.2, "ks": 3e4, "zeta": 0.25, "cs": c}
         for c in (1502.997, 0.25 * 2 * np.sqrt(3e4) * np.sqrt(301.2) * (1 + 1e-10), 1400.0)],
        # time scales beyond MAX_RATE_SPAN, masses refused, ints
        [{"ms": m, "mu": u, "ku": 29530} for m in (301, 1e-9, -5.0, 1e12) for u in (100, 1e-20)],
    ],
)  # fmt: skip
def test_from_mappings_accepts_exactly_what_the_constructor_accepts(designs):
    """The array checks of from_mappings against the one-by-one constructor
    (the reference): a design it passes must be one the constructor accepts,
    with the same six floats to the bit; every design the constructor refuses
    must be left to it (None), so its message names the value."""
    fast = QuarterCarParams.from_mappings(designs)
    for d, p in zip(designs, fast):
        ref = _one_by_one(d)
        if p is not None:  # (None, left to the constructor, is always safe)
            assert not isinstance(ref, str), (d, ref)
            assert vars(p) == vars(ref) and all(type(v) is float for v in vars(p).values())
    # the good designs of a grid are all taken by the array path
    good = [p for d, p in zip(designs, fast) if not isinstance(_one_by_one(d), str)]
    assert all(p is not None for p in good)


def test_from_mappings_leaves_other_designs_to_the_constructor():
    """Mixed keys, bools, None, strings and non-dicts are not checked in arrays."""
    for designs in (
        [{"ks": 3e4}, {"zeta": 0.3}],
        [{"ks": True}],
        [{"ks": 3e4, "zeta": None}],
        [{"ks": "3e4"}],
        [QuarterCarParams()],
        [{"kt": 1.0}],
        [{"ks": 10**400}],
    ):
        assert QuarterCarParams.from_mappings(designs) == [None] * len(designs)
