"""modal_analysis against control.damp and closed forms."""

import math

import control
import numpy as np
import pytest
from conftest import valid_params
from hypothesis import given, settings

from qc_control import QuarterCarParams, modal_analysis, quarter_car
from qc_control.numerics.stability import MARGINAL_RTOL


def undamped_closed_form(p):
    """Roots of det(K - w^2 M) = 0: ms mu w^4 - (ms (ks+ku) + mu ks) w^2 + ks ku = 0."""
    a, b, c = p.ms * p.mu, -(p.ms * (p.ks + p.ku) + p.mu * p.ks), p.ks * p.ku
    disc = math.sqrt(b * b - 4 * a * c)
    return sorted(
        math.sqrt(r) / (2 * math.pi) for r in ((-b - disc) / (2 * a), (-b + disc) / (2 * a))
    )


def test_seed_modes_match_control_damp():
    sys = quarter_car()
    ma = modal_analysis(sys)
    wn, zeta, poles = control.damp(sys, doprint=False)
    order = np.argsort(wn)
    # control.damp and ours both take |lambda| and -Re/|lambda|: agree to rounding.
    assert ma.body.wn == pytest.approx(wn[order[0]], rel=1e-12)
    assert ma.body.zeta == pytest.approx(zeta[order[0]], rel=1e-12)
    assert ma.wheel.wn == pytest.approx(wn[order[2]], rel=1e-12)
    assert ma.wheel.zeta == pytest.approx(zeta[order[2]], rel=1e-12)
    assert ma.body.fd == pytest.approx(abs(poles[order[0]].imag) / (2 * math.pi), rel=1e-12)


def test_seed_numbers_quoted_in_the_issue():
    ma = modal_analysis()
    assert round(ma.body.fn, 2) == 1.09 and round(ma.body.zeta, 3) == 0.068
    assert ma.body.zeta_nominal == pytest.approx(0.25, rel=1e-12)
    assert "0.068" in ma.note and "0.250" in ma.note and "rigid tire" in ma.note
    assert "\n" not in ma.note


def test_undamped_frequencies_closed_form():
    p = QuarterCarParams()
    ma = modal_analysis(p)
    lo, hi = undamped_closed_form(p)
    assert ma.body.fn_undamped == pytest.approx(lo, rel=1e-12)
    assert ma.wheel.fn_undamped == pytest.approx(hi, rel=1e-12)


def test_rigid_tire_limit():
    # ku -> inf: the body sits on a rigid wheel, wn -> sqrt(ks/ms), zeta -> nominal.
    # The error is O(ks/ku) = 3e-8 at ku = 1e12 N/m: 1e-6 relative is generous.
    p = QuarterCarParams(ku=1e12)
    ma = modal_analysis(p)
    assert ma.body.wn == pytest.approx(math.sqrt(p.ks / p.ms), rel=1e-6)
    assert ma.body.zeta == pytest.approx(p.zeta, rel=1e-6)
    assert ma.body.shape_ratio < 1e-6
    assert "within 10%" in ma.note


def test_undamped_system_has_zero_modal_damping():
    ma = modal_analysis(QuarterCarParams(zeta=0.0))
    lo, hi = undamped_closed_form(QuarterCarParams())
    assert ma.body.zeta == pytest.approx(0, abs=1e-12)
    assert ma.body.fn == pytest.approx(lo, rel=1e-10)
    assert ma.wheel.fn == pytest.approx(hi, rel=1e-10)


@pytest.mark.parametrize("zeta", [5.0, 50.0])
def test_a_locked_damper_makes_the_whole_car_bounce_on_its_tire(zeta):
    """With a very stiff damper the body and wheel move together (|xu/xs| -> 1)
    and bounce on the tire at sqrt(ku/(ms+mu)): that mode is body bounce, not
    wheel hop, even though the overdamped relative mode has the smaller
    |xu/xs|. Closed form of the locked car: 1.3655 Hz for the seed's masses;
    the damper's compliance leaves 0.4 % at zeta = 5 and 4e-5 at zeta = 50."""
    p = QuarterCarParams(zeta=zeta)
    ma = modal_analysis(p)
    locked = math.sqrt(p.ku / (p.ms + p.mu)) / (2 * math.pi)
    assert ma.body.fd == pytest.approx(locked, rel=5e-3 if zeta == 5.0 else 1e-4)
    assert ma.body.shape_ratio == pytest.approx(1.0, abs=0.01)
    assert ma.wheel.fd == 0.0 and ma.wheel.zeta > 1


def test_overdamped_modes_still_named():
    ma = modal_analysis(QuarterCarParams(zeta=3.0))
    assert {m.name for m in ma.modes} == {"body bounce", "wheel hop"}
    assert any(m.zeta >= 1 for m in ma.modes)


@settings(max_examples=80, deadline=None)
@given(valid_params)
def test_properties_over_random_vehicles(params):
    sys = quarter_car(params)
    assert np.all(np.linalg.eigvals(np.asarray(sys.A)).real < 0)
    ma = modal_analysis(params)
    names = [m.name for m in ma.modes]
    assert sorted(names) == ["body bounce", "wheel hop"]
    # In body bounce the wheel moves more in phase with the body than in wheel hop.
    in_phase = {m.name: m.shape_ratio * math.cos(math.radians(m.shape_phase)) for m in ma.modes}
    assert in_phase["body bounce"] > in_phase["wheel hop"]
    lo, hi = undamped_closed_form(params)
    assert sorted([ma.body.fn_undamped, ma.wheel.fn_undamped]) == pytest.approx([lo, hi], rel=1e-9)


def test_frame_and_str():
    ma = modal_analysis()
    frame = ma.to_frame()
    assert list(frame.index) == ["body bounce", "wheel hop"]
    assert frame.loc["body bounce", "fn [Hz]"] == pytest.approx(ma.body.fn)
    text = str(ma)
    assert "body bounce" in text and "wheel hop" in text and "zeta nominal" in text


def test_modal_rejects_other_systems():
    with pytest.raises(ValueError, match="quarter-car form"):
        modal_analysis(control.ss(np.eye(4) * -1, np.zeros((4, 1)), np.eye(4), 0))
    with pytest.raises(ValueError, match="continuous-time"):
        modal_analysis(control.c2d(quarter_car(road=True), 0.01))
    with pytest.raises(TypeError, match="got str"):
        modal_analysis("seed")


def test_overdamped_mode_whose_slow_root_is_below_rounding():
    """Found by the property suite: ms = 562 t on a 100 N/m spring at ζ = 10.

    The body mode's slow root, about -ks/cs = -1e-4/s, lies below
    MARGINAL_RTOL times the wheel's -8.4e4/s and is settled to 0; its damping
    ratio is then the limit of -(λ₁+λ₂)/(2√(λ₁λ₂)) as λ₁ -> 0⁻, +inf, and not
    a division by zero.
    """
    p = QuarterCarParams(ms=10.0**5.75, mu=0.1 * 10.0**1.25, ks=100.0, ku=1000.0, zeta=10.0)
    lam = np.linalg.eigvals(np.asarray(p.system.A))
    slow = lam[np.argmin(np.abs(lam))]
    assert abs(slow) <= MARGINAL_RTOL * np.max(np.abs(lam))  # the premise
    modes = modal_analysis(p).modes
    assert all(m.zeta >= 0 for m in modes)
    body = [m for m in modes if m.wn == 0.0]
    assert len(body) == 1 and body[0].zeta == np.inf
