"""
The shipped rig records: a SIMULATED quarter-car rig test, not a measurement
============================================================================

Makes the two CSV files under ``qc_control/data/`` that the identification
example and the docs use (``rig_identification.csv``, 15 s, and
``rig_validation.csv``, 8 s, both at 200 Hz). They are simulated, not
measured: a known quarter car with a damped tire (ms = 320 kg, mu = 45 kg,
ks = 22 kN/m, cs = 1.8 kN·s/m, ku = 190 kN/m, cu = 150 N·s/m) on a rig
whose base plate moves randomly (0.5-20 Hz, 4 mm RMS) while an actuator
between the masses sweeps a force chirp (0.5-15 Hz, 300 N), simulated by
python-control's exact response. What a real rig's records have is added on
purpose: white sensor noise (1 % of each channel's RMS), a slow drift of the
body's displacement sensor (3 mm per minute), channels in mm, and a force
channel of the opposite sign to the model's ``fa``.

Run: ``python examples/make_rig_dataset.py [OUT_DIR]`` (default
``./make_rig_dataset_output``; ``qc_control/data`` remakes the shipped
files, which are the same to the byte: every random draw is seeded).
"""

import control
import numpy as np
import scipy.signal
from matplotlib.figure import Figure

import qc_control as qc
from qc_control.report.outputs import output_folder, save_and_show

#: The car the records come from (the answer the identification should find).
TRUE_CAR = dict(ms=320.0, mu=45.0, ks=22000.0, ku=190000.0, cs=1800.0, cu=150.0)
FS = 200.0  # [Hz]
NOISE = 0.01  # of each channel's RMS
DRIFT = 3e-3 / 60.0  # [m/s] of the body displacement sensor
HEADER = (
    "# SIMULATED quarter-car rig test (not measured), made by examples/make_rig_dataset.py\n"
    "# car: ms=320 kg, mu=45 kg, ks=22000 N/m, cs=1800 N*s/m, ku=190000 N/m, cu=150 N*s/m\n"
    "# channels: base plate [mm], actuator force [N, opposite sign to the model's fa],\n"
    "# suspension travel [mm], body and wheel acceleration [m/s^2], body displacement [mm,\n"
    "# drifting 3 mm/min]; 1 % white noise on every output\n"
)


def rig_inputs(duration: float, rng) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time, base-plate motion and actuator force, both starting from rest."""
    t = np.arange(int(round(duration * FS)) + 1) / FS
    sos = scipy.signal.butter(2, [0.5, 20.0], "bandpass", fs=FS, output="sos")
    ramp = np.minimum(t / 0.5, 1.0)
    zr = scipy.signal.sosfiltfilt(sos, rng.normal(size=t.size))
    zr *= 0.004 / np.std(zr) * ramp
    fa = 300.0 * scipy.signal.chirp(t, 0.5, t[-1], 15.0, phi=-90.0) * ramp
    return t, zr, fa


def rig_outputs(t, zr, fa) -> dict[str, np.ndarray]:
    """The car's exact outputs (python-control) and its wheel's acceleration."""
    p = qc.QuarterCarParams(**TRUE_CAR)
    sys_ = qc.quarter_car(p, road=True, actuator=True)
    full = control.ss(sys_.A, sys_.B, np.eye(4), np.zeros((4, 2)))
    U = np.vstack([zr, fa])
    y = control.forced_response(sys_, t, U).outputs
    vs, q, xs, xu = control.forced_response(full, t, U).outputs
    vu = q + p.cu / p.mu * zr  # the model's second state is xu' - (cu/mu) zr
    tire = p.ku * (xu - zr) + p.cu * (vu - np.gradient(zr, t))
    wheel_acc = (p.cs * (vs - vu) + p.ks * (xs - xu) - tire - fa) / p.mu
    labels = list(sys_.output_labels)
    return {k: y[labels.index(k)] for k in ("xs", "susp_travel", "body_acc")} | {
        "wheel_acc": wheel_acc
    }


def record(duration: float, seed: int) -> str:
    """One record as CSV text, in the rig's units and conventions."""
    rng = np.random.default_rng(seed)
    t, zr, fa = rig_inputs(duration, rng)
    y = rig_outputs(t, zr, fa)
    noisy = {k: v + NOISE * np.sqrt(np.mean(v**2)) * rng.normal(size=t.size) for k, v in y.items()}
    columns = {
        "time_s": t,
        "base_mm": 1e3 * zr,
        "force_N": -fa,  # the load cell's sign convention is the opposite of fa's
        "travel_mm": 1e3 * noisy["susp_travel"],
        "body_acc_ms2": noisy["body_acc"],
        "wheel_acc_ms2": noisy["wheel_acc"],
        "body_disp_mm": 1e3 * (noisy["xs"] + DRIFT * t),
    }
    lines = [",".join(columns)]
    for row in zip(*columns.values()):
        lines.append(",".join(f"{v:.5g}" for v in row))
    return HEADER + "\n".join(lines) + "\n"


if __name__ == "__main__":
    out = output_folder("make_rig_dataset")  # OUT_DIR from the command line, if any
    for name, duration, seed in (("rig_identification", 15.0, 2026), ("rig_validation", 8.0, 2027)):
        path = out / f"{name}.csv"
        path.write_text(record(duration, seed), encoding="utf-8", newline="\n")
        print(f"wrote {path} ({path.stat().st_size / 1024:.0f} kB)")

    # %%
    # The first seconds of the identification record, as the rig's channels say
    # them: the base plate, the force (opposite sign to the model's fa) and the
    # suspension travel, with their noise.
    rec = qc.Measurement.from_csv(
        out / "rig_identification.csv",
        time="time_s",
        columns={"zr": "base_mm", "fa": "force_N", "susp_travel": "travel_mm"},
        units={"zr": "mm", "susp_travel": "mm"},
    )
    fig = Figure(figsize=(7, 6), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    shown = rec.t <= 5.0
    for ax, (label, unit) in zip(axes, [("zr", "m"), ("fa", "N"), ("susp_travel", "m")]):
        ax.plot(rec.t[shown], rec[label][shown], lw=0.8)
        ax.set_ylabel(f"{label} [{unit}]")
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title("Simulated rig record (not a measurement)")
    save_and_show(fig, out / "rig_record.png", dpi=100)
