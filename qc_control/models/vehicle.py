"""The model description every layer reads: a vehicle as signals with roles.

A vehicle model is a ``control`` system plus what the suspension tools need
to know about it, stated once:

- the unit of every signal label;
- which output is the body (or seat) acceleration and the body displacement;
- per wheel (a `Corner`): which outputs are the suspension travel and the
  tire deflection, which input is the road under it, the tire stiffness and
  the static wheel load;
- the parameters it was built from, and how to build it again from other
  parameters, one at a time or as a batch of matrices for sweeps.

Compare, ride metrics, sweeps and the report look signals up by these
labels, never by index, so a new vehicle plugs in by returning a
`VehicleModel`; nothing downstream changes. `qc_control.models.quarter.quarter_car_model`
is the first such model.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import control
import numpy as np

from ..numerics.lti import is_nonlinear_system

__all__ = [
    "Corner",
    "SignalRoles",
    "VehicleModel",
    "BatchedModel",
    "stack_models",
    "params_as",
    "STANDARD_GRAVITY",
]

#: Standard gravity [m/s²] (ISO 80000-3), for static wheel loads.
STANDARD_GRAVITY = 9.80665


@dataclass(frozen=True)
class Corner:
    """One wheel: where the suspension and the tire meet the road.

    Attributes
    ----------
    name : str
        ``''`` for a quarter car; ``'front'``, ``'rear'``, ``'front left'``...
    susp_travel, tire_defl : str
        Output labels of the suspension travel and of the tire deflection
        (``wheel - road``, compression negative) at this wheel [m].
    road : str or None
        Input label of the road height under this wheel [m], if the model
        has that input.
    tire_stiffness : float
        Tire stiffness [N/m]; the dynamic tire load is
        ``-tire_stiffness · tire_defl``.
    static_load : float
        Static wheel load [N] that the tire carries at rest.
    """

    name: str
    susp_travel: str
    tire_defl: str
    road: str | None
    tire_stiffness: float
    static_load: float

    def suffix(self) -> str:
        """``''`` or ``' front'``: appended to per-wheel metric names."""
        return f" {self.name}" if self.name else ""


@dataclass(frozen=True)
class SignalRoles:
    """Which output labels play which part: what metrics need of a model.

    Small and picklable (a ``control`` system is not), so that it travels
    with a sweep's chunks to worker processes.

    Attributes
    ----------
    body_acc : str
        Output label of the body (or seat) vertical acceleration [m/s²].
    body_disp : str
        Output label of the body's vertical displacement [m].
    corners : tuple[Corner, ...]
        One per wheel, in a fixed order.
    """

    body_acc: str
    body_disp: str
    corners: tuple[Corner, ...]


@dataclass(frozen=True, eq=False)
class BatchedModel:
    """``m`` designs of one model, as stacked matrices for the sweep engine.

    ``A (m, n, n)``, ``B (m, n, k)``, ``C (m, p, n)``, ``D (m, p, k)``; per
    corner, ``tire_stiffness`` and ``static_load`` of shape ``(m,)``; for a car
    with axles, each design's ``wheelbase`` ``a + b`` [m] ``(m,)`` (the rear
    wheels' delay on a road; None for one wheel). Labels are those of the
    single model, which every design shares.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    tire_stiffness: tuple[np.ndarray, ...]
    static_load: tuple[np.ndarray, ...]
    wheelbase: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class VehicleModel:
    """A vehicle as a ``control`` system with the roles of its signals.

    Attributes
    ----------
    system : control.StateSpace
        The linear model (states, inputs and outputs labelled).
    params : object
        The parameters the model was built from (e.g. `QuarterCarParams`).
    units : Mapping[str, str]
        SI unit of every state, input and output label.
    roles : SignalRoles
        Which outputs are the body acceleration and displacement, and the
        wheels (`corners`); also reachable as ``model.body_acc``,
        ``model.body_disp`` and ``model.corners``.
    rebuild : callable ``params -> VehicleModel``
        Builds the same kind of model (same inputs, same options) from other
        parameters; sweeps and optimisers use it.
    rebuild_batch : callable ``Sequence[params] -> BatchedModel``, optional
        A vectorised `rebuild` for sweeps. Without it, `batch` stacks the
        matrices of one `rebuild` per design.
    batch_dynamics : callable ``Sequence[params] -> dynamics``, optional
        For a nonlinear ``system``: its right-hand side over arrays of
        designs, which `qc_control.sweep` steps for all designs at once
        (`qc_control.studies.nlsweep`). The dynamics object has ``size``,
        ``state_labels``, ``input_labels``, ``output_labels``,
        ``switching_labels``, ``tire_stiffness`` and ``static_load`` (per
        corner, ``(m,)``), ``rhs(t, x, u)`` on states ``(n, m)``,
        ``outputs(t, x, u)`` (label -> ``x.shape[1:]``, also on blocks
        ``(n, m, L)``), ``switching(t, x, u) -> (q, m)`` and ``take(index)``;
        `qc_control.NonlinearQuarterCarBatch` is the example. Without it,
        a sweep of a nonlinear model runs one response per design.
    """

    system: control.StateSpace
    params: Any
    units: Mapping[str, str]
    roles: SignalRoles
    rebuild: Callable[[Any], VehicleModel]
    rebuild_batch: Callable[[Sequence[Any]], BatchedModel] | None = field(default=None)
    batch_dynamics: Callable[[Sequence[Any]], Any] | None = field(default=None)

    def __post_init__(self):
        outputs, inputs = list(self.system.output_labels), list(self.system.input_labels)
        wanted = [self.body_acc, self.body_disp]
        wanted += [label for c in self.corners for label in (c.susp_travel, c.tire_defl)]
        for label in wanted:
            if label not in outputs:
                raise ValueError(
                    f"model {self.system.name!r}: {label!r} is not an output; outputs are {outputs}"
                )
        for c in self.corners:
            if c.road is not None and c.road not in inputs:
                raise ValueError(
                    f"model {self.system.name!r}: road input {c.road!r} of corner "
                    f"{c.name!r} is not an input; inputs are {inputs}"
                )
        labels = list(self.system.state_labels) + inputs + outputs
        missing = [label for label in labels if label not in self.units]
        if missing:
            raise ValueError(f"model {self.system.name!r}: no unit for {missing}")

    @property
    def name(self) -> str:
        return self.system.name

    @property
    def is_nonlinear(self) -> bool:
        """Whether the model is stepped by its right-hand side, not scanned as ``R(hA)``.

        True when its ``system`` is a nonlinear I/O system
        (`qc_control.numerics.lti.is_nonlinear_system`) or it gives
        ``batch_dynamics``, which only a nonlinear model has: `qc_control.sweep`
        then takes its nonlinear path (`qc_control.studies.nlsweep`).
        """
        return self.batch_dynamics is not None or is_nonlinear_system(self.system)

    @property
    def body_acc(self) -> str:
        return self.roles.body_acc

    @property
    def body_disp(self) -> str:
        return self.roles.body_disp

    @property
    def corners(self) -> tuple[Corner, ...]:
        return self.roles.corners

    def output(self, label: str) -> int:
        """Index of an output label, or a ValueError naming the outputs."""
        labels = list(self.system.output_labels)
        if label not in labels:
            raise ValueError(f"model {self.name!r} has no output {label!r}; outputs are {labels}")
        return labels.index(label)

    def unit(self, label: str) -> str:
        """The SI unit of a signal label (``'-'`` when unknown)."""
        return self.units.get(label, "-")

    def road_inputs(self) -> list[str]:
        """The road input labels, one per corner that has one, in corner order."""
        return [c.road for c in self.corners if c.road is not None]

    def batch(self, designs: Sequence[Any]) -> BatchedModel:
        """Stacked matrices and corner data of many designs of this model."""
        if self.rebuild_batch is not None:
            return self.rebuild_batch(designs)
        return stack_models([self.rebuild(p) for p in designs])


def stack_models(models: Sequence[VehicleModel]) -> BatchedModel:
    """A `BatchedModel` from single models of one kind (the generic `batch`)."""
    mats = [[np.asarray(getattr(m.system, k), dtype=float) for m in models] for k in "ABCD"]
    A, B, C, D = (np.stack(ms) for ms in mats)
    corners = len(models[0].corners)
    stiffness = tuple(
        np.array([m.corners[i].tire_stiffness for m in models]) for i in range(corners)
    )
    load = tuple(np.array([m.corners[i].static_load for m in models]) for i in range(corners))
    axles = all(hasattr(m.params, "a") and hasattr(m.params, "b") for m in models)
    wheelbase = np.array([m.params.a + m.params.b for m in models]) if axles else None
    return BatchedModel(A, B, C, D, stiffness, load, wheelbase)


def params_as(cls, params):
    """``params`` as an instance of the parameter class ``cls``.

    None gives ``cls()`` (the model's defaults), an instance is kept, and a
    mapping is read by field name with ``cls.from_mapping`` (which names an
    unknown key); anything else raises ``TypeError``.
    """
    if params is None:
        return cls()
    if isinstance(params, cls):
        return params
    if isinstance(params, Mapping):
        return cls.from_mapping(params)
    raise TypeError(f"params must be a {cls.__name__}, a dict or None, got {type(params).__name__}")
