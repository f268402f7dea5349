"""
Wheel lift-off: RK4's order with and without contact events
===========================================================

The seed's quarter car with gravity and a unilateral tire
(`qc_control.nonlinear_quarter_car`) drives over a 1 − cos bump 20 cm high
and 8 m long at 20 m/s. The seed's tire is soft (static deflection 13.3 cm),
so it takes a bump this size to throw the wheel off the road: it flies for
about 0.086 s. The tire force has a kink where contact is lost and regained.

Stepping across the kink, RK4 loses its order; locating the kink inside the
step and stepping to it exactly (``events=True``) gives it back. The
reference is RK4 with events at h = 1/16 ms. Prints the errors, the observed
orders and the contact times; writes ``lift_off.png`` (tire force and wheel
height).

Run: ``python examples/lift_off.py [OUT_DIR]`` (default ``./lift_off_output``).
"""

import math

import numpy as np
from matplotlib.figure import Figure

import qc_control as qc
from qc_control.report.outputs import output_folder, save_and_show

out = output_folder("lift_off")  # OUT_DIR from the command line, if any

HEIGHT, LENGTH, SPEED, T0, T_END = 0.20, 8.0, 20.0, 0.1, 0.8


# The road under the tire; its ends (0.1 s, 0.5 s) are points of every grid below.
bump = qc.road.Bump(height=HEIGHT, length=LENGTH, speed=SPEED, t0=T0)
car = qc.nonlinear_quarter_car(road=bump)  # the seed's Table 1, gravity, unilateral tire


def run(h, events):
    T = np.linspace(0.0, T_END, int(round(T_END / h)) + 1)
    return qc.input_output_response(car, T, events=events)


reference = run(1 / 16000, True)
steps = (2e-3, 1e-3, 5e-4)
print(f"bump {HEIGHT * 100:g} cm x {LENGTH:g} m at {SPEED:g} m/s; RK4 against RK4 at h = 1/16 ms")
print("contact lost and regained at t = " + ", ".join(f"{t:.5f} s" for t in reference.t_events))
for events in (False, True):
    errors = []
    for h in steps:
        r = run(h, events or None)
        stride = int(round(h * 16000))
        errors.append(float(np.max(np.abs(r.states[2:] - reference.states[2:, ::stride]))))
    orders = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
    print(
        f"events={events!s:5}  errors "
        + "  ".join(f"{e:.2e}" for e in errors)
        + "  observed orders "
        + "  ".join(f"{p:.2f}" for p in orders)
    )

fig = Figure(figsize=(7, 5), layout="constrained")
ax1, ax2 = fig.subplots(2, 1, sharex=True)
ax1.plot(reference.time, reference.outputs[5], label="tire contact force")
ax1.set_ylabel("force [N]")
ax2.plot(reference.time, reference.states[3], label="wheel xu")
ax2.plot(reference.time, [bump(t) for t in reference.time], label="road zr")
ax2.set_ylabel("height from static [m]")
ax2.set_xlabel("time [s]")
for ax in (ax1, ax2):
    for t in reference.t_events:
        ax.axvline(t, color="grey", lw=0.8, ls="--")
    ax.legend()
save_and_show(fig, out / "lift_off.png", dpi=100)
print(f"wrote {out / 'lift_off.png'}")
