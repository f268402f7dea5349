"""python-control's time-response call forms at a fixed step.

`timeresp` holds `initial_response`, `forced_response`, `step_response`,
`impulse_response` and `input_output_response` with control's signatures,
returning `FixedStepResponse` (a `control.TimeResponseData`), over the
numerics layer's stepper and LTI engine.
"""
