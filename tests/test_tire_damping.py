"""The quarter car's tire damping cu (qc_control.models.quarter): the change of state
variable that avoids differentiating the road, checked against the closed form."""

from __future__ import annotations

import control
import numpy as np
import pytest

import qc_control as qc


def test_road_to_body_transfer_function_matches_the_closed_form_with_cu():
    p = qc.QuarterCarParams(ms=300.0, mu=40.0, ks=20000.0, ku=180000.0, cs=1500.0, cu=250.0)
    sys = qc.quarter_car(p, road=True)
    s = control.tf("s")
    # Newton on both masses, tire force ku (xu - zr) + cu (xu' - zr'), Laplace-transformed
    den = (p.ms * s**2 + p.cs * s + p.ks) * (p.mu * s**2 + (p.cs + p.cu) * s + p.ks + p.ku) - (
        p.cs * s + p.ks
    ) ** 2
    xs_closed = (p.cs * s + p.ks) * (p.cu * s + p.ku) / den
    xu_closed = (p.ms * s**2 + p.cs * s + p.ks) * (p.cu * s + p.ku) / den
    w = np.logspace(-1, 3, 60)  # [rad/s] across both modes
    for label, closed in (("xs", xs_closed), ("xu", xu_closed)):
        got = control.ss2tf(sys[label, "zr"])
        # 1e-9: both are rational functions evaluated in double precision
        np.testing.assert_allclose(got(1j * w), closed(1j * w), rtol=1e-9)
    # body_acc = s² xs (through the D term the change of variable adds)
    np.testing.assert_allclose(
        control.ss2tf(sys["body_acc", "zr"])(1j * w), (1j * w) ** 2 * xs_closed(1j * w), rtol=1e-9
    )


def test_cu_zero_is_the_seed_model():
    seed = qc.quarter_car(qc.QuarterCarParams(), road=True, actuator=True)
    zero = qc.quarter_car(qc.QuarterCarParams(cu=0.0), road=True, actuator=True)
    for M in "ABCD":
        np.testing.assert_array_equal(getattr(seed, M), getattr(zero, M))
    assert qc.QuarterCarParams().cu == 0.0


def test_bad_cu_and_the_nonlinear_car():
    with pytest.raises(ValueError, match=r"cu \(tire damping\) must be a finite number >= 0"):
        qc.QuarterCarParams(cu=-1.0)
    with pytest.raises(ValueError, match="nonlinear car has no tire damping"):
        qc.nonlinear_quarter_car(qc.QuarterCarParams(cu=100.0))
