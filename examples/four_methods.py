"""The seed's four methods against python-control's exact response.

Run:  python examples/four_methods.py [OUT_DIR]
Writes four_methods.png: the body displacement by each method at the
default step h = 0.01 s, over control.initial_response, and the error
of each on a log axis.
"""

import sys
from pathlib import Path

import control
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import qc_control as qc  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
sys_ = qc.quarter_car()
T = np.linspace(0.0, 10.0, 1001)  # h = 0.01 s
X0 = [0.0, 0.0, 0.05, 0.0]  # body released from 5 cm

exact = control.initial_response(sys_, T, X0)
fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
top.plot(T, exact.outputs[0] * 1e3, "k", lw=3, alpha=0.3, label="exact (control)")
for method in qc.METHODS:
    resp = qc.initial_response(sys_, T, X0, method=method)  # the one-line swap
    top.plot(T, resp.outputs[0] * 1e3, lw=1, label=method)
    error = np.abs(resp.outputs[0] - exact.outputs[0])
    bottom.semilogy(T[1:], error[1:], lw=1, label=method)
    print(f"{method:9s} max |xs error| = {error.max():.3e} m with {resp.nfev} RHS evaluations")
top.set(ylabel="body displacement xs [mm]", title="Quarter car, h = 0.01 s")
bottom.set(xlabel="time [s]", ylabel="|xs error| [m]")
top.legend()
bottom.legend(ncol=4, fontsize="small")
fig.tight_layout()
fig.savefig(out / "four_methods.png", dpi=120)
print(f"wrote {out / 'four_methods.png'}")
