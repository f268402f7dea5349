"""General numerics that know no vehicle.

Butcher tableaus and their order conditions (`methods`, `order_conditions`),
the stage loop of every explicit step (`stepper`; compiled, `compiled_stepper`),
sampled inputs (`sampled`), fixed-step solutions and the time grid
(`integrate`), stability regions and
step limits (`stability`), the exact LTI engine (`lti`), interconnected
systems compiled for stepping (`interconnect`), compiled recurrences
(`recurrence`), the memory guard (`limits`) and how values appear in error
messages (`messages`). Nothing here imports a vehicle model.
"""
