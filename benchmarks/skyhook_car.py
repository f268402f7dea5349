"""The seed car under a clipped skyhook, joined by ``control.interconnect``.

The system whose RK4 run ``run.py`` times against control's default solve_ivp
(benchmarks/RESULTS.md), and on which tests/test_nonlinear_response.py checks
that the interconnection's fast path gives the right-hand side's run: one
definition, so the system timed is the system checked.
"""

from __future__ import annotations

import control
import numpy as np

import qc_control as qc


def car_with_velocities():
    """The seed car ``(ss, car)``: ``car`` is the StateSpace with the body and
    wheel velocities ``vs_m``, ``vu_m`` as extra outputs (what a controller reads)."""
    ss = qc.quarter_car(road=True, actuator=True)
    A, B, C, D = (np.asarray(m) for m in (ss.A, ss.B, ss.C, ss.D))
    car = control.ss(
        A,
        B,
        np.vstack([C, np.eye(4)[:2]]),
        np.vstack([D, np.zeros((2, 2))]),
        states=ss.state_labels,
        inputs=ss.input_labels,
        outputs=[*ss.output_labels, "vs_m", "vu_m"],
        name="car",
    )
    return ss, car


def car_with_skyhook(c_sky: float = 3000.0):
    """The seed car under Karnopp's clipped skyhook (Karnopp, Crosby & Harwood,
    ASME J. Eng. Ind. 96(2), 1974), a ``control.nlsys`` of ``c_sky`` [N·s/m]
    whose force is limited to ``fmax`` = 2 kN; input ``zr``, the car's outputs."""
    ss, car = car_with_velocities()

    def skyhook(t, x, u, p):  # the body's absolute damper, on when it dissipates
        vs, vu = u
        force = p["c_sky"] * vs if vs * (vs - vu) > 0 else 0.0
        return [-min(max(force, -p["fmax"]), p["fmax"])]

    ctrl = control.nlsys(
        None,
        skyhook,
        inputs=["vs_m", "vu_m"],
        outputs=["fa"],
        name="skyhook",
        params={"c_sky": c_sky, "fmax": 2000.0},
    )
    return control.interconnect([car, ctrl], inputs="zr", outputs=ss.output_labels, name="cl")
