"""General numerics that know no vehicle.

Butcher tableaus and their order conditions (`methods`, `order_conditions`),
the fixed-step stepper and the time grid (`integrate`), stability regions and
step limits (`stability`), the exact LTI engine (`lti`), interconnected
systems compiled for stepping (`interconnect`), compiled recurrences
(`recurrence`), the memory guard (`limits`) and how values appear in error
messages (`messages`). Nothing here imports a vehicle model.
"""
