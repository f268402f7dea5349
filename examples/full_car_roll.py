"""
Roll of a full car on a one-sided bump, with and without anti-roll bars
=======================================================================

The full car (`qc_control.full_car`, Ikenaga et al., 2000) drives at
10 m/s over a 5 cm bump under its left wheels only: the left track has the
bump, the right track is flat, the rear wheels meet it a wheelbase later
(`qc_control.ride.road.corner_inputs`). The car heaves, pitches and rolls. Anti-roll
bars (20 kN·m/rad in front, 8 kN·m/rad at the rear) stiffen roll, and only
roll: the roll mode (and the axle tramp modes) move up while bounce and pitch
stay where they were. What bars buy in cornering they cost on a one-sided
bump: they pass more of the left wheels' lift to the body, so the body rolls
further (the known ride penalty of anti-roll bars; Gillespie, *Fundamentals
of Vehicle Dynamics*, 1992, ch. 8).

Run: ``python examples/full_car_roll.py [OUT_DIR]`` (default
``./full_car_roll_output``). Writes ``full_car_roll.png``.
"""

import dataclasses

import numpy as np
from matplotlib.figure import Figure

import qc_control as qc
from qc_control.report.outputs import output_folder, save_and_show

out = output_folder("full_car_roll")  # OUT_DIR from the command line, if any
print(f"writing into {out.resolve()}")

plain = qc.FullCarParams()
barred = dataclasses.replace(plain, arb_front=20e3, arb_rear=8e3)
speed = 10.0
T = np.linspace(0.0, 3.0, 3001)  # h = 1 ms
left = qc.road.bump(T, height=0.05, length=1.0, speed=speed, t0=0.2)
U = qc.road.corner_inputs(T, left, np.zeros_like(T), plain.a + plain.b, speed)

fig = Figure(figsize=(8, 5), layout="constrained")
roll_ax, acc_ax = fig.subplots(2, 1, sharex=True)
for name, car in (("no anti-roll bars", plain), ("anti-roll bars", barred)):
    modes = qc.modal_analysis(car)
    sys_ = qc.full_car(car, road=True)
    resp = qc.forced_response(sys_, T, U, method="rk4")
    phi = resp.outputs[sys_.output_labels.index("phi")]
    roll_acc = resp.outputs[sys_.output_labels.index("roll_acc")]
    roll_ax.plot(T, np.degrees(phi), label=name)
    acc_ax.plot(T, roll_acc, label=name)
    print(
        f"{name}: roll mode {modes['roll'].fn:.3f} Hz (ζ = {modes['roll'].zeta:.3f}), "
        f"bounce {modes['bounce'].fn:.3f} Hz, pitch {modes['pitch'].fn:.3f} Hz; "
        f"peak roll {np.degrees(np.max(np.abs(phi))):.3f} deg, "
        f"peak roll acceleration {np.max(np.abs(roll_acc)):.2f} rad/s²"
    )
roll_ax.set(
    ylabel="roll φ [deg] (left side up +)",
    title=f"A 5 cm bump under the left wheels at {speed:g} m/s",
)
acc_ax.set(xlabel="time [s]", ylabel="roll acceleration [rad/s²]")
for ax in (roll_ax, acc_ax):
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
save_and_show(fig, out / "full_car_roll.png", dpi=110)
print(f"wrote {out / 'full_car_roll.png'}")
