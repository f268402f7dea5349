"""
Bounce and pitch of a half car on a bump, and wheelbase filtering
=================================================================

The half car (`qc_control.half_car`, the passenger car of Ikenaga et al.,
2000) drives over a 5 cm, 1 m long bump at two speeds: the front wheel meets
it first, the rear wheel a wheelbase later (`qc_control.ride.road.axle_inputs`).
The slower the car, the longer the time between the two hits, and the more
the car pitches rather than bounces.

Then the frequency response from the road to the body's heave and pitch
accelerations at 15 m/s (`qc_control.transmissibility` with ``speed``): one
road under both axles, the rear ``τ = (a + b)/V`` later, so the axles'
contributions cancel where ``e^{-j2πfτ} = ±1``: near ``f = (k + ½)·V/(a + b)``
for heave and ``f = k·V/(a + b)`` for pitch (wheelbase filtering).

Run: ``python examples/half_car_pitch.py [OUT_DIR]`` (default
``./half_car_pitch_output``). Writes ``half_car_bump.png`` and
``half_car_wheelbase_filtering.png``.
"""

import numpy as np
from matplotlib.figure import Figure

import qc_control as qc
from qc_control.report.outputs import output_folder, save_and_show

out = output_folder("half_car_pitch")  # OUT_DIR from the command line, if any
print(f"writing into {out.resolve()}")
car = qc.HalfCarParams(seat_x=0.3)  # the driver's seat 0.3 m ahead of the CG
L = car.a + car.b
print(qc.modal_analysis(car))

# %%
# The bump at 5 and 20 m/s: heave and pitch of the body (RK4, h = 1 ms).
T = np.linspace(0.0, 3.0, 3001)
sys_ = qc.half_car(car, road=True)
fig = Figure(figsize=(8, 5), layout="constrained")
heave_ax, pitch_ax = fig.subplots(2, 1, sharex=True)
for speed in (5.0, 20.0):
    front = qc.road.bump(T, height=0.05, length=1.0, speed=speed, t0=0.2)
    U = qc.road.axle_inputs(T, front, L, speed)
    resp = qc.forced_response(sys_, T, U, method="rk4")
    z = resp.outputs[sys_.output_labels.index("z")]
    theta = resp.outputs[sys_.output_labels.index("theta")]
    seat = resp.outputs[sys_.output_labels.index("seat_acc")]
    heave_ax.plot(T, 1e3 * z, label=f"{speed:g} m/s")
    pitch_ax.plot(T, np.degrees(theta), label=f"{speed:g} m/s")
    print(
        f"at {speed:4.1f} m/s (rear hit {L / speed:.3f} s later): peak heave "
        f"{1e3 * np.max(np.abs(z)):.2f} mm, peak pitch {np.degrees(np.max(np.abs(theta))):.3f} "
        f"deg, peak seat acceleration {np.max(np.abs(seat)):.2f} m/s²"
    )
heave_ax.set(ylabel="heave z [mm]", title="A 5 cm bump under the front, then the rear wheel")
pitch_ax.set(xlabel="time [s]", ylabel="pitch θ [deg] (nose up +)")
for ax in (heave_ax, pitch_ax):
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
save_and_show(fig, out / "half_car_bump.png", dpi=110)

# %%
# Wheelbase filtering at 15 m/s: the notches of heave and pitch.
speed = 15.0
f = np.linspace(0.2, 15.0, 3000)
tr = qc.transmissibility(car, f, speed=speed)
fig = Figure(figsize=(8, 4.5), layout="constrained")
ax = fig.subplots()
ax.semilogy(f, np.abs(tr.response["heave_acc"]), label="heave acceleration / zr [(m/s²)/m]")
ax.semilogy(f, np.abs(tr.response["pitch_acc"]), label="pitch acceleration / zr [(rad/s²)/m]")
for k, fk in enumerate(tr.wheelbase_notches("pitch")):
    ax.axvline(fk, color="tab:orange", ls=":", lw=1, label="k·V/(a+b)" if k == 0 else None)
for k, fk in enumerate(tr.wheelbase_notches("heave")):
    ax.axvline(fk, color="tab:blue", ls=":", lw=1, label="(k+½)·V/(a+b)" if k == 0 else None)
ax.set(xlabel="frequency [Hz]", title=f"One road under both axles at {speed:g} m/s")
ax.grid(alpha=0.3, which="both")
ax.legend(fontsize="small", loc="lower left")
save_and_show(fig, out / "half_car_wheelbase_filtering.png", dpi=110)
print(f"\nwheelbase {L:.3f} m at {speed:g} m/s, V/(a+b) = {speed / L:.3f} Hz")
for signal, label in (("heave", "heave_acc"), ("pitch", "pitch_acc")):
    gain = np.abs(tr.response[label])
    for fk in tr.wheelbase_notches(signal)[:2]:
        near = (f > fk - 0.4) & (f < fk + 0.4)
        i = np.argmin(np.where(near, gain, np.inf))
        print(
            f"  |{label}/zr| dips to {gain[i]:.3g} at {f[i]:.3f} Hz "
            f"(wheelbase filtering: {fk:.3f} Hz)"
        )
