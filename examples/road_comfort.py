"""
Comfort and road holding on ISO 8608 roads
==========================================

Prints the ISO 2631-1 Wk-weighted RMS body acceleration (comfort) and the
RMS dynamic tire load over the static wheel load (road holding) on road
classes A-D at 10, 20 and 30 m/s, from the road PSD
(``ride_metrics_spectral``), and checks one cell against a 100 s
simulation.

Run: ``python examples/road_comfort.py [OUT_DIR]`` (default
``./road_comfort_output``). Writes ``road_comfort.png`` and
``road_comfort.csv``.
"""

import control
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

import qc_control as qc
from qc_control.report.outputs import output_folder, save_and_show
from qc_control.ride import road

out = output_folder("road_comfort")  # OUT_DIR from the command line, if any
print(f"writing into {out.resolve()}")
params = qc.QuarterCarParams()
classes, speeds = "ABCD", (10.0, 20.0, 30.0)
rows = []
for c in classes:
    for v in speeds:
        m = qc.ride_metrics_spectral(params, qc.road.ISO8608Road(c, speed=v))
        rows.append(
            {
                "class": c,
                "speed [m/s]": v,
                "comfort: rms body_acc Wk [m/s²]": m["rms_body_acc_wk [m/s²]"],
                "road holding: rms tire load / static": m["rms_tire_load / static [-]"],
                "rms susp_travel [mm]": 1e3 * m["rms_susp_travel [m]"],
            }
        )
table = pd.DataFrame(rows).set_index(["class", "speed [m/s]"])
print(table.to_string(float_format=lambda x: f"{x:.3f}"))
table.to_csv(out / "road_comfort.csv")

# %%
# One cell by simulation: class C at 20 m/s, 100 s, the first 10 s dropped
T = np.arange(0, 100.0 + 1e-9, 0.002)
resp = qc.forced_response(
    qc.quarter_car(params, road=True), T, road.iso8608(T, "C", 20.0), method="rk4"
)
keep = T >= 10
window = control.TimeResponseData(
    T[keep], resp.outputs[:, keep], issiso=False, output_labels=resp.output_labels
)
sim = qc.ride_metrics(window, params)
print(
    f"\nclass C at 20 m/s simulated: Wk RMS {sim['rms_body_acc_wk [m/s²]']:.3f} m/s², "
    f"tire load {sim['rms_tire_load / static [-]']:.3f} (spectral: "
    f"{table.loc[('C', 20.0)].iloc[0]:.3f}, {table.loc[('C', 20.0)].iloc[1]:.3f})"
)

# %%
# Comfort and road holding against speed, one line per road class.
fig = Figure(figsize=(10, 3.8), layout="constrained")
left, right = fig.subplots(1, 2)
for c in classes:
    sub = table.loc[c]
    left.semilogy(sub.index, sub.iloc[:, 0], "o-", label=f"class {c}")
    right.semilogy(sub.index, sub.iloc[:, 1], "o-", label=f"class {c}")
left.set(
    xlabel="speed [m/s]",
    ylabel="Wk-weighted RMS body acceleration [m/s²]",
    title="Comfort (ISO 2631-1)",
)
right.set(
    xlabel="speed [m/s]", ylabel="RMS dynamic tire load / static load [-]", title="Road holding"
)
for ax in (left, right):
    ax.grid(alpha=0.3, which="both")
# outside the axes: inside, class D's line ran under the legend
fig.legend(*left.get_legend_handles_labels(), fontsize="small", loc="outside right upper")
save_and_show(fig, out / "road_comfort.png", dpi=110)
print(f"wrote {out / 'road_comfort.png'}")
