"""
Active and semi-active suspensions on python-control
====================================================

Closes the loop around the seed's quarter car with skyhook (ideal and
semi-active), LQR (``control.lqr``) and, when slycot is installed, H∞ on
MATLAB's active-suspension weights; finds the comfort-optimal passive
damper in closed form; and compares them on a bump and an ISO 8608 class C
road at 20 m/s (`qc_control.studies.control_study.compare_controllers`), with the
transmissibility of each linear design.

Run: ``python examples/active_suspension.py [OUT_DIR]`` (default
``./active_suspension_output``). Writes ``control_table.csv``,
``transmissibility_body_acc.png``, ``transmissibility_tire_defl.png`` and
``pareto.png``. The full comparison is ``qc-control control-report``.
"""

import pandas as pd

import qc_control as qc
from qc_control.models.controllers import HINF_AVAILABLE
from qc_control.report.control import transmissibility_chart
from qc_control.report.outputs import output_folder, save_and_show
from qc_control.studies.control_study import compare_controllers

out = output_folder("active_suspension")  # OUT_DIR from the command line, if any
print(f"writing into {out.resolve()}")
params = qc.QuarterCarParams()

# the comfort-optimal passive damper: cs = ks·sqrt((ms + mu)/kt)
opt = qc.optimal_damping(params, "comfort")
print(f"comfort-optimal damping: cs = {opt.cs:.1f} N·s/m (zeta = {opt.zeta:.3f}, {opt.method})")

# the controllers, each a python-control system joined to the car by control.interconnect
car = qc.quarter_car_model(params, road=True, actuator=True)
lqr = qc.closed_loop(car, qc.lqr_controller(car))
print("LQR closed-loop poles [1/s]:", ", ".join(f"{p:.2f}" for p in lqr.system.poles()))
if HINF_AVAILABLE:
    design = qc.hinf_controller(car, beta=0.5)
    print(f"H∞: gamma = {design.gamma:.4f}, closed-loop H∞ norm = {design.norm:.4f}")

designs = ["passive (seed)", "passive optimum", "skyhook", "skyhook semi-active", "LQR"]
designs += ["H∞"] if HINF_AVAILABLE else []
cmp = compare_controllers(params, designs=designs, road_duration=5.0, bump_duration=8.0)
cmp.table.to_csv(out / "control_table.csv")
with pd.option_context("display.width", 200, "display.max_columns", 20):
    print(
        cmp.table[
            [
                "bump: peak_body_acc [m/s²]",
                "road: rms_body_acc [m/s²]",
                "road: rms_tire_load / static [-]",
            ]
        ].round(4)
    )
for signal in ("body_acc", "tire_defl"):
    fig = transmissibility_chart(cmp, signal)
    save_and_show(fig, out / f"transmissibility_{signal}.png", dpi=100)

# the passive comfort / road-holding front, with the linear controllers marked
front = qc.pareto_front(
    params,
    {"cs": [500.0 * k for k in range(1, 17)], "ks": [2e4, 3e4, 4e4]},
    travel_limit=0.05,
    controllers={"skyhook": qc.closed_loop(car, qc.skyhook(3000.0)), "LQR": lqr},
)
save_and_show(front.figure, out / "pareto.png", dpi=100)
print(f"{len(front.designs)} non-dominated passive designs of {len(front.all_designs)}")
