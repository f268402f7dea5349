"""Modes of the half and full car named by shape, against closed forms."""

import dataclasses
import math
from pathlib import Path

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control.models.halfcar import FullCarParams, HalfCarParams

#: A tire 1e5 times stiffer than the springs: "rigid" up to the series spring
#: k·ku/(k+ku) (used below) and the wheel's inertia, a relative effect of
#: mu·ω²/ku < 1e-7 on the body modes.
RIGID = 2e9


def rigid(p, **changes):
    """No damping, (nearly) rigid tires."""
    values = dict(cs_front=0.0, cs_rear=0.0, ku_front=RIGID, ku_rear=RIGID) | changes
    return dataclasses.replace(p, **values)


def series(k):
    return k * RIGID / (k + RIGID)


def bounce_pitch_closed_form(p, per_axle=1):
    """The 2x2 bounce-pitch eigenproblem of a body on two springs (Gillespie,
    Fundamentals of Vehicle Dynamics, 1992, eq. 5-31..5-34):
    α = (kf + kr)/m, β = (kr b - kf a)/m, γ = (kf a² + kr b²)/Iy,
    ω² = (α + γ)/2 ± sqrt((α - γ)²/4 + β² m/Iy)."""
    kf, kr = per_axle * series(p.ks_front), per_axle * series(p.ks_rear)
    alpha = (kf + kr) / p.ms
    beta = (kr * p.b - kf * p.a) / p.ms
    gamma = (kf * p.a**2 + kr * p.b**2) / p.Iy
    root = math.sqrt((alpha - gamma) ** 2 / 4 + beta**2 * p.ms / p.Iy)
    return sorted(
        math.sqrt(w2) / (2 * math.pi) for w2 in ((alpha + gamma) / 2 + s * root for s in (-1, 1))
    )


def test_half_car_names_and_control_damp():
    ma = qc.modal_analysis(HalfCarParams())
    assert [m.name for m in ma.modes] == ["bounce", "pitch", "front wheel hop", "rear wheel hop"]
    wn, zeta, _ = control.damp(qc.half_car(), doprint=False)
    # the same |λ| and -Re λ/|λ| as python-control, to rounding
    np.testing.assert_allclose(
        sorted(m.wn for m in ma.modes), sorted(set(np.round(wn, 9))), rtol=1e-9
    )
    assert set(np.round([m.zeta for m in ma.modes], 9)) <= set(np.round(zeta, 9))


def test_rigid_tires_no_damping_bounce_and_pitch_from_the_2x2_problem():
    p = rigid(HalfCarParams())
    ma = qc.modal_analysis(p)
    lo, hi = bounce_pitch_closed_form(p)
    found = sorted([ma["bounce"].fn, ma["pitch"].fn])
    # the wheels' inertia on a 2e9 N/m tire shifts the body modes by < 1e-7 relative
    np.testing.assert_allclose(found, [lo, hi], rtol=1e-6)
    assert abs(ma["bounce"].zeta) < 1e-12 and abs(ma["pitch"].zeta) < 1e-12  # rounding
    # bounce's node lies outside the wheelbase, pitch's inside (Gillespie, ch. 5)
    assert not (-p.b < ma["bounce"].node_x < p.a)
    assert -p.b < ma["pitch"].node_x < p.a


def test_equal_axles_at_equal_distances_decouple_bounce_and_pitch():
    p = rigid(
        HalfCarParams(a=1.4, b=1.4, ks_rear=HalfCarParams().ks_front, mu_rear=40.0),
    )
    ma = qc.modal_analysis(p)
    k = series(p.ks_front)
    # pure heave on two springs, pure pitch on two springs at ±a
    assert ma["bounce"].fn == pytest.approx(math.sqrt(2 * k / p.ms) / (2 * math.pi), rel=1e-6)
    assert ma["pitch"].fn == pytest.approx(
        math.sqrt(2 * k * p.a**2 / p.Iy) / (2 * math.pi), rel=1e-6
    )
    bounce, pitch = dict(ma["bounce"].shape), dict(ma["pitch"].shape)
    # decoupled: no pitch in bounce, no heave in pitch (rounding only)
    assert abs(bounce["theta"]) < 1e-9 and abs(pitch["z"]) < 1e-9
    assert abs(ma["bounce"].node_x) > 1e6 and ma["pitch"].node_x == pytest.approx(0.0, abs=1e-9)


def test_olley_condition_puts_each_mode_over_one_axle():
    """k_y² = Iy/ms = a·b: the mass matrix is diagonal in the axle
    coordinates, so each body mode moves one axle and its node is at the
    other (damping and tires included: they act at the axles too)."""
    base = HalfCarParams()
    p = dataclasses.replace(base, Iy=base.ms * base.a * base.b)
    ma = qc.modal_analysis(p)
    nodes = sorted([ma["bounce"].node_x, ma["pitch"].node_x])
    np.testing.assert_allclose(nodes, [-p.b, p.a], rtol=1e-9)
    # and each frequency is a quarter car's with the axle's share of the body
    L = p.a + p.b
    quarter = qc.modal_analysis(
        qc.QuarterCarParams(
            ms=p.ms * p.b / L, mu=p.mu_front, ks=p.ks_front, ku=p.ku_front, cs=p.cs_front
        )
    )
    front = min(ma.modes[:2], key=lambda m: abs(m.node_x + p.b))  # node at the rear axle
    assert front.wn == pytest.approx(quarter.body.wn, rel=1e-9)


def test_full_car_names_and_roll_closed_form():
    p = rigid(FullCarParams(arb_front=18e3, arb_rear=5e3))
    ma = qc.modal_analysis(p)
    assert sorted(m.name for m in ma.modes) == sorted(
        [
            "bounce",
            "pitch",
            "roll",
            "front wheel hop",
            "rear wheel hop",
            "front axle tramp",
            "rear axle tramp",
        ]
    )

    # roll: per axle, springs at ±t/2 plus the bar (k t²/2 + K_arb), in series with
    # the tires' roll stiffness ku t²/2; the wheels' inertia is left out (< 1e-7)
    def axle(ks, track, bar):
        suspension, tires = ks * track**2 / 2 + bar, RIGID * track**2 / 2
        return suspension * tires / (suspension + tires)

    k_roll = axle(p.ks_front, p.track_front, p.arb_front) + axle(
        p.ks_rear, p.track_rear, p.arb_rear
    )
    assert ma["roll"].fn == pytest.approx(math.sqrt(k_roll / p.Ix) / (2 * math.pi), rel=1e-6)
    # heave and pitch are the 2x2 problem with two springs per axle
    np.testing.assert_allclose(
        sorted([ma["bounce"].fn, ma["pitch"].fn]), bounce_pitch_closed_form(p, 2), rtol=1e-6
    )
    tramp = dict(ma["front axle tramp"].shape)
    hop = dict(ma["front wheel hop"].shape)
    assert tramp["xu_fl"] == pytest.approx(-tramp["xu_fr"], rel=1e-6)
    assert hop["xu_fl"] == pytest.approx(hop["xu_fr"], rel=1e-6)


def test_an_anti_roll_bar_stiffens_only_roll_and_tramp():
    soft = qc.modal_analysis(FullCarParams())
    barred = qc.modal_analysis(FullCarParams(arb_front=20e3))
    for name in ("bounce", "pitch", "front wheel hop", "rear wheel hop"):
        # a symmetric motion does not twist the bar: the same eigenvalue to rounding
        assert barred[name].wn == pytest.approx(soft[name].wn, rel=1e-9)
    assert barred["roll"].fn > soft["roll"].fn
    assert barred["front axle tramp"].fn > soft["front axle tramp"].fn


def test_vehicle_modes_accepts_models_and_labelled_systems():
    by_model = qc.modal_analysis(qc.half_car_model(road=True))
    by_system = qc.modal_analysis(qc.half_car(road=True))
    assert [m.name for m in by_model.modes] == [m.name for m in by_system.modes]
    frame = by_model.to_frame()
    assert "node x [m]" in frame.columns and "zeta nominal [-]" not in frame.columns
    # the quarter car keeps its own names and table
    assert [m.name for m in qc.modal_analysis(qc.quarter_car_model()).modes] == [
        "body bounce",
        "wheel hop",
    ]
    nm = qc.numerical_modes("rk4", 0.01, qc.half_car_model())
    assert list(nm.index)[:2] == ["bounce", "pitch"]
    with pytest.raises(ValueError, match="names no corners"):
        qc.modal_analysis(
            qc.half_car().__class__(np.asarray(qc.half_car().A), np.zeros((8, 1)), np.eye(8), 0)
        )
    with pytest.raises(ValueError, match="not in vehicle form"):
        qc.modal_analysis(control.ss(-np.eye(6), np.zeros((6, 1)), np.eye(6), 0))


def readme_table(title):
    """The rows of the guide's modal table after the line ``title``
    (``docs/guide/vehicles.md``, where the README's text moved)."""
    guide = Path(__file__).parent.parent / "docs" / "guide" / "vehicles.md"
    text = guide.read_text(encoding="utf-8")
    block = text.split(f"\n{title}\n", 1)[1].lstrip("\n").split("\n\n", 1)[0]
    rows = [line.strip("|").split("|") for line in block.splitlines()[2:]]
    return {r[0].strip(): [float(v) if v.strip() != "–" else math.nan for v in r[1:]] for r in rows}


@pytest.mark.parametrize(
    ("title", "params"),
    [("Half car:", HalfCarParams()), ("Full car (no anti-roll bars):", FullCarParams())],
)
def test_the_readme_modal_tables_are_the_example_vehicles(title, params):
    table = readme_table(title)
    ma = qc.modal_analysis(params)
    assert list(table) == [m.name for m in ma.modes]
    for m in ma.modes:
        expected = [m.fn, m.zeta, m.fd, m.fn_undamped, m.node_x]
        # printed to 3 decimals
        np.testing.assert_allclose(table[m.name], expected, atol=5.1e-4, equal_nan=True)
