"""
From measurement to model: identify a quarter car from rig records
==================================================================

Reads the shipped rig test (SIMULATED records of a known car, made by
``examples/make_rig_dataset.py``: a random base-plate motion, a force chirp,
1 % sensor noise, a drifting displacement sensor and a force channel of the
opposite sign), fits the quarter car with a damped tire to them, validates
the fit on a held-out record and writes the report.

The force channel's gain and sign are fitted (``gains=["fa"]``), so the
absolute scale is fixed by weighing the body (``fixed={"ms": 320}``). The
drifting body displacement is left out of the fit: a drift is not the car.

Run: ``python examples/identify_rig.py [OUT_DIR]`` (default
``./identify_rig_output``). Writes the report (``report.md``,
``report.html``, figures and CSV tables).
"""

from pathlib import Path

import qc_control as qc
from qc_control.report.identification import write_identification_report
from qc_control.report.outputs import output_folder
from qc_control.studies.measurement import RIG_COLUMNS

out = output_folder("identify_rig")  # OUT_DIR from the command line, if any
print(f"writing into {out.resolve()}")

# %%
# Read: the rig's columns mapped to the model's labels, millimetres to metres.
data = Path(qc.__file__).parent / "data"
units = {"zr": "mm", "susp_travel": "mm", "xs": "mm"}
record = qc.Measurement.from_csv(
    data / "rig_identification.csv", time="time_s", columns=RIG_COLUMNS, units=units
)
held_out = qc.Measurement.from_csv(
    data / "rig_validation.csv", time="time_s", columns=RIG_COLUMNS, units=units
)
print(record)

# %%
# Identify: the five physical parameters besides the weighed ms (the tire damping
# cu among them, bounded at 0) and the force channel's gain.
ident = qc.identify(
    record,
    fixed={"ms": 320.0},
    gains=["fa"],
    outputs=["susp_travel", "body_acc", "wheel_acc"],
)
print(ident)

# %%
# Validate on the held-out record, and write the report.
validation = ident.validate(held_out)
print("Validation fit [%]")
print(validation.to_string(float_format="{:.2f}".format))
write_identification_report(
    ident,
    record,
    out,
    validation=held_out,
    command=f"python examples/identify_rig.py {out}",
)
print(f"wrote {out / 'report.md'}")
