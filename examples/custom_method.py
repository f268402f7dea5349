"""
Your own Butcher tableau in the comparison
==========================================

Adds Ralston's second-order method and Kutta's 3/8 rule to the seed's four
methods and writes the full comparison report for all six: Markdown, a
self-contained HTML page, a PDF, the CSV tables and the figures.

Run: ``python examples/custom_method.py [OUT_DIR]`` (default
``./custom_method_output``). Writes the report into
``OUT_DIR/custom_report/``.
"""

import numpy as np

import qc_control as qc
from qc_control.report import write_report
from qc_control.report.outputs import output_folder

out = output_folder("custom_method")  # OUT_DIR from the command line, if any
print(f"writing into {out.resolve()}")

# Ralston's second-order method: the 2-stage method of least error bound.
ralston = qc.ButcherTableau(
    "ralston", a=[[0, 0], [2 / 3, 0]], b=[1 / 4, 3 / 4], c=[0, 2 / 3], order=2
)
# Kutta's 3/8 rule, the other classic fourth-order method.
three_eighths = qc.ButcherTableau(
    "3/8-rule",
    a=[[0, 0, 0, 0], [1 / 3, 0, 0, 0], [-1 / 3, 1, 0, 0], [1, -1, 1, 0]],
    b=[1 / 8, 3 / 8, 3 / 8, 1 / 8],
    c=[0, 1 / 3, 2 / 3, 1],
    order=4,
)

cmp = qc.compare_methods(
    qc.QuarterCarParams(),
    np.linspace(0, 5, 501),
    methods=("euler", "midpoint", "heun", ralston, "rk4", three_eighths),
    repeats=3,
)
print(cmp.summary().to_string(float_format=lambda v: f"{v:.4g}"))
path = write_report(cmp, out / "custom_report", command="python examples/custom_method.py")
print(f"\nwrote {path / 'report.html'}, {path / 'report.pdf'} and the rest in {path}")
