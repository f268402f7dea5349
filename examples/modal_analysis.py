"""
Modal analysis, and why the body's damping is not the nominal 0.25
==================================================================

Prints the modal table of the seed's car and sweeps the tire stiffness,
to show the body mode's damping approaching the nominal ratio
cs/(2√(ks·ms)) as the tire stiffens.

Run: ``python examples/modal_analysis.py [OUT_DIR]`` (default
``./modal_analysis_output``). Writes ``modal_tire_stiffness.png``.
"""

import numpy as np
from matplotlib.figure import Figure

import qc_control as qc
from qc_control.report.outputs import output_folder, save_and_show

out = output_folder("modal_analysis")  # OUT_DIR from the command line, if any
print(f"writing into {out.resolve()}")
print(qc.modal_analysis())  # the seed's Table 1

# %%
# Stiffen the tire from a third of the spring's stiffness to a thousand times it.
ratios = np.logspace(-0.5, 3, 60)  # ku / ks
seed = qc.QuarterCarParams()
body = [qc.modal_analysis(qc.QuarterCarParams(ku=r * seed.ks)).body for r in ratios]

fig = Figure(figsize=(7, 4.5), layout="constrained")
top, bottom = fig.subplots(2, 1, sharex=True)
top.semilogx(ratios, [m.zeta for m in body], label="modal ζ of body bounce")
top.axhline(seed.zeta, color="k", ls="--", label="nominal ζ = cs/(2√(ks·ms))")
top.axvline(seed.ku / seed.ks, color="r", ls=":", label="seed's tire")
top.set(ylabel="damping ratio [-]")
top.legend(fontsize="small", loc="lower right")
bottom.semilogx(ratios, [m.fn for m in body])
bottom.axhline(
    np.sqrt(seed.ks / seed.ms) / (2 * np.pi), color="k", ls="--", label="rigid tire: √(ks/ms)/2π"
)
bottom.set(xlabel="tire stiffness / suspension stiffness, ku/ks [-]", ylabel="body frequency [Hz]")
bottom.legend(fontsize="small", loc="lower right")
save_and_show(fig, out / "modal_tire_stiffness.png", dpi=110)
print(
    f"\nAt ku/ks = 1000 the body's ζ is {body[-1].zeta:.4f} (nominal {seed.zeta}); "
    f"wrote {out / 'modal_tire_stiffness.png'}"
)
