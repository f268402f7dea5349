"""A car closed by a controller on a clock: the sampled-data closed loop.

`qc_control.closed_loop` comes here when the controller is discrete
(``dt > 0``): an ECU's law, a discretised LQR, `qc_control.mpc_controller`.
The loop is a `qc_control.numerics.clocked.ClockedLoop`: the continuous car
between the ticks, the controller's move held by a zero-order hold, and
``delay`` whole ticks of computation delay. The responses step it with its
steps landing on every tick (`qc_control.numerics.clocked.step_clocked`).
"""

from __future__ import annotations

import control
import numpy as np

from ..numerics.clocked import ClockedLoop, DiscreteLaw
from .vehicle import VehicleModel

__all__ = ["sampled_loop", "check_delay", "period_label"]


def check_delay(delay) -> int:
    """``delay`` as a whole number of ticks >= 0, or a ValueError naming it."""
    if isinstance(delay, bool) or not isinstance(delay, (int, np.integer)) or delay < 0:
        raise ValueError(f"delay must be a whole number of controller samples >= 0, got {delay!r}")
    return int(delay)


def _law(controller):
    """The controller as a `ClockedLaw`: itself if it is one (MPC), else its equations."""
    if callable(getattr(controller, "tick", None)):
        return controller
    return DiscreteLaw(controller)


def period_label(dt: float) -> str:
    """A controller period as a system name may hold it: python-control refuses
    a '.' in a name, so 2.5 ms is '2500 µs', and a period of no whole number of
    microseconds is named by its rate ('3000 Hz', or '~1234 Hz' rounded)."""
    for scale, unit in ((1e3, "ms"), (1e6, "µs")):
        if abs(dt * scale - round(dt * scale)) <= 1e-9 * dt * scale:
            return f"{round(dt * scale)} {unit}"
    rate = 1.0 / dt
    return f"{round(rate)} Hz" if abs(rate - round(rate)) <= 1e-9 * rate else f"~{round(rate)} Hz"


def sampled_loop(car: VehicleModel, controller, plant, delay: int, name, rebuild) -> VehicleModel:
    """The car (``plant``: with the measured states as outputs) and a discrete controller.

    See `qc_control.closed_loop`; ``plant`` is its ``_measured_plant``,
    ``rebuild(params)`` the same loop around the rebuilt car.
    """
    delay = check_delay(delay)
    dt = float(controller.dt) if controller.dt is not True else None
    if dt is None or not np.isfinite(dt) or dt <= 0:
        raise ValueError(
            f"controller {controller.name!r} must have a sample period dt > 0 [s], "
            f"got dt={controller.dt!r}"
        )
    sys = car.system
    inputs = [label for label in sys.input_labels if label != "fa"]
    order = [plant.input_labels.index(label) for label in [*inputs, "fa"]]
    rows = [plant.output_labels.index(label) for label in controller.input_labels]
    A, B = np.asarray(plant.A, float), np.asarray(plant.B, float)[:, order]
    C, D = np.asarray(plant.C, float), np.asarray(plant.D, float)[:, order]
    ny = sys.noutputs
    ordered = control.ss(A, B, C[:ny], D[:ny])
    ctrl_states = [f"{controller.name}_{s}" for s in controller.state_labels]
    labels = {
        "inputs": inputs,
        "outputs": list(sys.output_labels),
        "states": [*sys.state_labels, *ctrl_states],
        "moves": ["fa"],
    }
    loop = ClockedLoop(
        ordered,
        1,
        (C[rows], D[rows]),
        _law(controller),
        dt,
        delay,
        labels,
        name or f"{car.name} + {controller.name} @ {period_label(dt)}",
    )
    units = dict(car.units)
    units["fa"] = "N"
    units.update({label: "-" for label in ctrl_states})
    units.update({label: "N" for label in loop.state_labels[len(labels["states"]) :]})
    return VehicleModel(
        loop,
        car.params,
        units,
        car.roles,
        rebuild,
    )
