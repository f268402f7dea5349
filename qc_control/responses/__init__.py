"""python-control's time-response call forms at a fixed step.

`timeresp` holds `initial_response`, `forced_response`, `step_response` and
`impulse_response` (python-control's ``timeresp``), `iosys` holds
`input_output_response` (python-control's ``nlsys``), and `common` what
they share: the result, `FixedStepResponse` (a `control.TimeResponseData`),
the checks of an initial state and of input samples, the options and the
record of a run. They step over the numerics layer's stepper and LTI
engine, and choose their step by its one policy (`qc_control.numerics.steps`).
Every name importable from `timeresp` before the split still is.
"""
