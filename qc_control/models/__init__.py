"""Vehicle models as python-control systems.

The model description (`vehicle`: `VehicleModel`, signal roles, units), the
quarter car of the seed (`quarter`), the half and full car (`halfcar`),
the nonlinear quarter car with contact and bump stops (`nonlinear`, its
compiled batched steps in `nlkernel`), controllers as systems and closed
loops (`controllers`), and modal analysis named by mode shape (`modal`).
"""
