"""The vehicle models by name: one entry per model is all a new vehicle needs.

A `ModelEntry` states, once, what the tools above the models need to know
about a kind of vehicle:

- its parameter dataclass (``from_mapping``, ``to_dict``, validation naming
  the field), whose fields become the TOML keys and the command-line options
  (``--ks-front``), with the units and meanings its ``table()`` gives;
- how its `VehicleModel` is built from parameters (``build(params, road=...,
  **options)``), and the options of its own (``tire``, ``bump_stop`` of the
  nonlinear car) with their checks;
- its default run (`DefaultRun`: start, road, end time and step);
- how its road inputs follow one road (`RoadLayout`: one wheel, two axles
  a wheelbase apart, or four corners on two tracks);
- what its figures draw besides the body (``wheel_disp``: the wheel's
  displacement output);
- which of its parameters a grey-box identification may fit
  (``fit_parameters``; none: the model is not identified).

`qc_control.compare_methods`, `qc_control.Scenario`, the command line and the
report ask the registry; none of them names a model. `register_model` adds
one (also as ``qc.register_model``), `unregister_model` takes it away again
(tests), `get_model` finds one by name, `model_for_params` by the type of
its parameters, and `vehicle_model` builds the model of any registered
vehicle's parameters (the ride metrics and the transmissibility take a
half car's parameters as they take a quarter car's).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from ..numerics.checks import ParameterError
from .halfcar import FullCarParams, HalfCarParams, full_car_model, half_car_model
from .nonlinear import BumpStop, nonlinear_quarter_car_model
from .quarter import (
    SEED_X0,
    QuarterCarParams,
    as_params,
    check_mount_stiffness,
    quarter_car_model,
)
from .vehicle import VehicleModel

__all__ = [
    "ModelEntry",
    "ModelOption",
    "DefaultRun",
    "RoadLayout",
    "MODELS",
    "register_model",
    "unregister_model",
    "get_model",
    "model_for_params",
    "model_for_system",
    "vehicle_model",
    "parameter_keys",
    "parameter_help",
]

#: How a model's road inputs follow one road: ``'single'`` (one input, the
#: road itself), ``'axles'`` (front and rear, the rear a wheelbase ``a + b``
#: later), ``'corners'`` (front left, front right, rear left, rear right on
#: two tracks ``track_front`` apart, the rear a wheelbase later).
RoadLayout = str
_LAYOUTS = ("single", "axles", "corners")


@dataclass(frozen=True)
class ModelOption:
    """A run option of one model (beyond its parameters), e.g. the nonlinear car's tire.

    Attributes
    ----------
    name : str
        The `qc_control.Scenario` field and TOML key (``[scenario]``); the
        command-line option is ``--name`` with ``-`` for ``_``.
    default : object
        The value when none is given.
    check : callable ``value -> value``
        Returns the value to keep, or raises ``ValueError`` whose message
        starts with the name (``"tire must be ..."``).
    help : str
        One line for ``--help``.
    target : {'build', 'compare'}
        Where the value goes: a keyword of the entry's ``build``, or of
        `qc_control.compare_methods`.
    convert : callable ``value -> argument``, optional
        The checked value as that keyword's argument (default: as it is).
    parse : callable ``str -> value``, optional
        The command line's reader of the option's text (default: the text);
        a ``ValueError`` says what was expected. A boolean option (its
        default a bool) is a flag instead: ``--no-name`` when the default is
        True, ``--name`` when False.
    metavar : str, optional
        The value's name in ``--help``.
    """

    name: str
    default: Any
    check: Callable[[Any], Any]
    help: str
    target: str = "build"
    convert: Callable[[Any], Any] | None = None
    parse: Callable[[str], Any] | None = None
    metavar: str | None = None

    def argument(self, value) -> Any:
        """The keyword argument of ``build`` or ``compare_methods`` for a checked value."""
        return value if self.convert is None else self.convert(value)


@dataclass(frozen=True)
class DefaultRun:
    """A model's default run, used where a `qc_control.Scenario` gives no value.

    Attributes
    ----------
    t_end, h : float
        End time and step [s].
    road : mapping or None
        The default road, ``{'kind': 'bump', 'height': ...}``, in the layout of
        a TOML file's ``[scenario.road]`` table (the
        `qc_control.road.Road` it describes is
        `qc_control.studies.scenario_toml.road_from_mapping`'s), or None for
        no road (the free response). A table, not a ``Road``: the roads live in
        ``ride``, a layer above the models. A road of the same kind given in
        part takes the rest of its parameters from this one.
    x0 : sequence of float or None
        The free response's start, in state order; None: the body
        (``roles.body_disp``) released from ``release`` [m], every other
        state zero. Under a road the car always starts at rest.
    release : float
        See ``x0``.
    """

    t_end: float = 10.0
    h: float = 0.01
    road: Mapping[str, Any] | None = None
    x0: tuple[float, ...] | None = None
    release: float = 0.05


@dataclass(frozen=True)
class ModelEntry:
    """One kind of vehicle, as the tools above the models see it.

    Attributes
    ----------
    name : str
        Its name: ``model = "name"`` in TOML, ``--model name``.
    params : type
        The parameter dataclass: ``cls()`` is the default vehicle,
        ``cls.from_mapping(dict)`` checks values (``ValueError`` naming the
        field), ``p.to_dict()`` gives them back and ``p.table()`` gives
        ``(name, description, value, unit)`` rows (the command line's help).
    build : callable ``(params, *, road, **options) -> VehicleModel``
        ``road`` is True for the road inputs, False for none; an entry with
        ``road_function`` also takes a function of time ``t -> zr`` [m].
    description : str
        One line for ``--help``.
    options : tuple of ModelOption
        Its run options beyond the parameters.
    defaults : DefaultRun
    road_layout : {'single', 'axles', 'corners'}
        See `RoadLayout`. ``'axles'`` and ``'corners'`` read the wheelbase
        ``a + b`` from the parameters, ``'corners'`` also ``track_front``.
    road_function : bool
        Whether ``build`` takes the road as a function of time (stepped at
        every stage, not interpolated between samples).
    wheel_disp : str or None
        The output the report draws as the wheel's displacement beside the
        body's (None: the body alone).
    fit_parameters : tuple of str
        The parameters (fields of ``params``) a grey-box identification of
        measured records may fit; empty (the default) for a model that is
        not identified.
    """

    name: str
    params: Any  # a parameter dataclass (its class)
    build: Callable[..., VehicleModel]
    description: str
    options: tuple[ModelOption, ...] = ()
    defaults: DefaultRun = field(default_factory=DefaultRun)
    road_layout: RoadLayout = "single"
    road_function: bool = False
    wheel_disp: str | None = None
    fit_parameters: tuple[str, ...] = ()

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"a model's name must be an identifier, got {self.name!r}")
        if not isinstance(self.params, type) or not hasattr(self.params, "from_mapping"):
            raise TypeError(
                f"params must be a parameter dataclass with from_mapping, got {self.params!r}"
            )
        if not callable(self.build):
            raise TypeError(f"build must be callable, got {self.build!r}")
        if self.road_layout not in _LAYOUTS:
            raise ValueError(
                f"road_layout must be one of {', '.join(_LAYOUTS)}, got {self.road_layout!r}"
            )
        unknown = [n for n in self.fit_parameters if n not in {f.name for f in fields(self.params)}]
        if unknown:
            raise ParameterError(
                "fit_parameters", self.fit_parameters, f"fields of {self.params.__name__}"
            )

    def model(self, params=None, *, road: Any = False, **options) -> VehicleModel:
        """The `VehicleModel` of ``params`` (the default vehicle for None)."""
        p = self.params() if params is None else params
        return self.build(p, road=road, **options)

    def option(self, name: str) -> ModelOption | None:
        """The option called ``name``, or None."""
        return next((o for o in self.options if o.name == name), None)

    def keys(self) -> tuple[str, ...]:
        """The parameter names: TOML keys and ``--name`` options."""
        return tuple(f.name for f in fields(self.params))

    def free_start(self, params, **options) -> tuple[float, ...]:
        """The default start of a free response, in state order (see `DefaultRun`);
        ``options`` build the model (a model option may add states, e.g. a mount)."""
        model = self.model(params, **options)
        x0 = self.defaults.x0
        if x0 is not None and len(x0) == model.system.nstates:
            return tuple(float(v) for v in x0)
        body = model.body_disp
        return tuple(self.defaults.release if s == body else 0.0 for s in model.system.state_labels)


#: The registered models by name, in the order they were registered.
MODELS: dict[str, ModelEntry] = {}


def register_model(entry: ModelEntry, *, replace: bool = False) -> ModelEntry:
    """Add a kind of vehicle; from then on ``Scenario(model=entry.name)``,
    ``qc-control report --model NAME`` and ``model = "NAME"`` in TOML run it.

    Parameters
    ----------
    entry : ModelEntry
    replace : bool, default False
        Replace an entry of the same name (else that is a ValueError).

    Returns
    -------
    ModelEntry
        ``entry``.
    """
    if not isinstance(entry, ModelEntry):
        raise TypeError(f"entry must be a ModelEntry, got {type(entry).__name__}")
    if entry.name in MODELS and not replace:
        raise ValueError(f"a model named {entry.name!r} is registered already (replace=True)")
    MODELS[entry.name] = entry
    return entry


def unregister_model(name: str) -> ModelEntry:
    """Remove a registered model (a test's, say) and return its entry."""
    if name not in MODELS:
        raise ValueError(f"no model named {name!r}; registered: {', '.join(MODELS)}")
    return MODELS.pop(name)


def get_model(name: str) -> ModelEntry:
    """The entry called ``name``; a ValueError lists the registered ones."""
    if not isinstance(name, str) or name not in MODELS:
        raise ValueError(f"model must be one of {', '.join(map(repr, MODELS))}, got {name!r}")
    return MODELS[name]


def model_for_params(params) -> ModelEntry | None:
    """The first entry whose parameters are of ``params``' type (exactly), or None."""
    return next((e for e in MODELS.values() if type(params) is e.params), None)


def model_for_system(sys) -> ModelEntry | None:
    """The entry whose model has ``sys``' signals: the same outputs, or (a closed
    loop, a model with more outputs) the model's outputs and states first.

    An exact match wins over a prefix match, so the nonlinear car (which has the
    quarter car's outputs and ``tire_force``) is found as itself.
    """
    outputs, states = list(sys.output_labels), list(sys.state_labels)
    road = any(label.startswith("zr") for label in sys.input_labels)
    prefix = None
    for entry in MODELS.values():
        try:
            like = entry.model(road=road).system
        except (TypeError, ValueError):  # a builder that takes no such road: not this one
            continue
        mine, theirs = list(like.output_labels), list(like.state_labels)
        if states[: len(theirs)] != theirs:
            continue
        if outputs == mine:
            return entry
        if prefix is None and outputs[: len(mine)] == mine:
            prefix = entry
    return prefix


def vehicle_model(params=None, *, road: Any = False, **options) -> VehicleModel:
    """The `VehicleModel` of a vehicle's parameters, built by its registered entry.

    The entry is found by the parameters' type (`model_for_params`: the
    first registered for it, the linear quarter car for `QuarterCarParams`);
    anything else is read as the quarter car's (`as_params`: None is the
    seed's car, a dict its fields), and a `VehicleModel` is returned as it
    is. ``road`` and ``options`` go to the entry's ``build`` (`ModelEntry.model`).

    Raises
    ------
    qc_control.ParameterError
        For parameters no registered model takes.
    """
    if isinstance(params, VehicleModel):
        return params
    entry = model_for_params(params)
    if entry is None:  # None, a dict: the quarter car's (as_params refuses the rest)
        params = as_params(params)
        entry = model_for_params(params)
    if entry is None:
        raise ParameterError("params", params, "the parameters of a registered model")
    return entry.model(params, road=road, **options)


def parameter_keys() -> dict[str, list[str]]:
    """Every parameter name of every registered model, each once in order,
    with the models that take it."""
    users: dict[str, list[str]] = {}
    for name, entry in MODELS.items():
        for key in entry.keys():
            users.setdefault(key, []).append(name)
    return users


def parameter_help(entry: ModelEntry, key: str) -> str:
    """``'sprung mass [kg]'``: a parameter's meaning and unit from the default
    vehicle's ``table()``; the bare name when the class has no table."""
    table = getattr(entry.params(), "table", None)
    rows = {row[0]: row for row in table()} if callable(table) else {}
    if key not in rows:
        return key
    _, description, _, unit = rows[key]
    return f"{description} [{unit}]" if unit and unit != "-" else str(description)


# ------------------------------------------------------------ the built-in models


_TIRES = ("unilateral", "linear")


def _tire(value) -> str:
    if value not in _TIRES:
        raise ValueError(f"tire must be 'unilateral' or 'linear', got {value!r}")
    return str(value)


def _events(value) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"events must be true or false, got {value!r}")
    return bool(value)


def _bump_stop(value) -> tuple[float, float] | None:
    if value is None:
        return None
    values = [v.strip() for v in value.split(",")] if isinstance(value, str) else value
    try:
        pair = [float(v) for v in values]
        ok = all(not isinstance(v, bool) for v in values) and len(pair) == 2
    except (TypeError, ValueError):
        ok = False
    if not ok or not all(map(math.isfinite, pair)) or not (pair[0] >= 0 and pair[1] > 0):
        raise ValueError(
            "bump_stop must be CLEARANCE,STIFFNESS: a clearance >= 0 m and a stiffness "
            f"> 0 N/m, finite, got {value!r}"
        )
    return (pair[0], pair[1])


def _numbers(text: str) -> list[float]:
    """``'a,b'`` as floats (the count is the option's check)."""
    try:
        return [float(v) for v in text.split(",")]
    except ValueError:
        raise ValueError(f"expected comma-separated numbers, got {text!r}") from None


def _stop(value) -> BumpStop | None:
    return None if value is None else BumpStop(*value)


#: The nonlinear car's default road: the lift-off bump (the wheel is airborne
#: 0.4356-0.5213 s), over 0-0.8 s at h = 2 ms.
_LIFT_OFF = DefaultRun(
    t_end=0.8,
    h=0.002,
    road={"kind": "bump", "height": 0.2, "length": 8.0, "speed": 20.0, "t0": 0.1},
)

for _entry in (
    ModelEntry(
        "quarter",
        QuarterCarParams,
        quarter_car_model,
        "the seed's quarter car",
        options=(
            ModelOption(
                "mount_stiffness",
                None,
                check_mount_stiffness,
                "a rubber top mount in series with the damper [N/m] (one more state, "
                "the damper's end; default none)",
                parse=float,
                metavar="N/M",
            ),
        ),
        defaults=DefaultRun(x0=SEED_X0),
        wheel_disp="xu",
        fit_parameters=("ms", "mu", "ks", "ku", "cs", "cu"),
    ),
    ModelEntry(
        "half",
        HalfCarParams,
        half_car_model,
        "the bounce-pitch half car",
        road_layout="axles",
        wheel_disp="xu_front",
    ),
    ModelEntry(
        "full",
        FullCarParams,
        full_car_model,
        "the heave-pitch-roll full car",
        road_layout="corners",
        wheel_disp="xu_fl",
    ),
    ModelEntry(
        "nonlinear",
        QuarterCarParams,
        nonlinear_quarter_car_model,
        "the quarter car with gravity and a unilateral tire (wheel lift-off), optionally a "
        "bump stop; by default over a 20 cm, 8 m bump at 20 m/s",
        options=(
            ModelOption("tire", "unilateral", _tire, "the tire", metavar="unilateral|linear"),
            ModelOption(
                "bump_stop",
                None,
                _bump_stop,
                "a bump stop: travel in compression before it touches [m], stiffness [N/m]",
                convert=_stop,
                parse=_numbers,
                metavar="CLEARANCE,STIFFNESS",
            ),
            ModelOption(
                "events",
                True,
                _events,
                "step to each contact event (the convergence study runs both ways regardless)",
                target="compare",
                convert=lambda on: None if on else False,
            ),
        ),
        defaults=_LIFT_OFF,
        road_function=True,
        wheel_disp="xu",
    ),
):
    register_model(_entry)
