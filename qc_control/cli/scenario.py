"""One comparison run as data: the vehicle, its start, the road, the grid and the methods.

A `Scenario` is what ``qc-control report`` runs and what a report records.
It is validated once, when it is made; it reads from and writes to TOML
(`Scenario.from_toml`, `Scenario.to_toml`), and `Scenario.command` gives the
exact command that redoes it. `Scenario.run` calls
`qc_control.compare_methods` and returns its `MethodComparison` with
``cmp.scenario`` set.

The TOML layout (every key optional)::

    ms = 301.2            # the vehicle's parameters at the top level:
    zeta = 0.25           # ms, mu, ks, ku and zeta or cs (QuarterCarParams)

    [scenario]
    model = "quarter"     # or "half", "full", "nonlinear", or any registered model
                          # (qc_control.register_model); the top-level keys are
                          # then that model's parameters
    t_end = 10.0          # end time [s]
    h = 0.01              # step [s]
    x0 = [0.0, 0.0, 0.05, 0.0]          # [vs, vu, xs, xu] in m/s, m/s, m, m
    methods = ["euler", "midpoint", "heun", "rk4"]
    max_steps = 100000    # refuse a run of more steps t_end/h than this
    tire = "unilateral"   # model = "nonlinear" only: or "linear"
    bump_stop = [0.05, 1e5]   # nonlinear only: clearance [m], stiffness [N/m] (default none)
    events = true         # nonlinear only: step to each contact event (default true)

    [scenario.road]       # none, step, bump, sine or iso8608
    kind = "bump"
    height = 0.1          # [m]
    length = 1.0          # [m]
    speed = 15.0          # [m/s]
    t0 = 0.5              # [s], when the car meets it

With ``model = "nonlinear"`` (`qc_control.nonlinear_quarter_car_model`:
gravity, a unilateral tire, an optional bump stop) the defaults are the
lift-off case: a 1 − cos bump 20 cm high and 8 m long at 20 m/s, met at
0.1 s, over 0-0.8 s at h = 2 ms (`NONLINEAR_ROAD`, `NONLINEAR_T_END`,
`NONLINEAR_H`); the road is then a function of time (a closed form at
every stage), except an ISO 8608 road, which is sampled.

The flat keys of earlier versions in ``[scenario]`` (``road = "iso8608"``,
``road_class``, ``speed``, ``seed``, and the nonlinear car's ``bump_height``
and ``bump_length``) are read for one more release, each with a
``DeprecationWarning`` naming its key in ``[scenario.road]``.
"""

from __future__ import annotations

import dataclasses
import inspect
import json
import math
import re
import shlex
import sys
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from types import FrameType
from typing import Any, cast

import control
import numpy as np

from ..models.quarter import QuarterCarParams
from ..models.registry import MODELS, ModelEntry, get_model, model_for_params, parameter_keys
from ..models.vehicle import VehicleModel
from ..numerics import methods as catalogue
from ..numerics.checks import ParameterError
from ..numerics.methods import METHODS, get_method
from ..numerics.stability import max_stable_step
from ..numerics.steps import preferred_step, whole_step
from ..ride.road import ROADS, Bump, ISO8608Road, NoRoad, Profile, Road, Sine, Step
from ..studies.compare import DEFAULT_METHODS, MethodComparison, compare_methods
from ..studies.on_road import road_inputs, road_problem
from ..studies.peers import check_solvers
from ..studies.scenarios import POTHOLE, STIFF_CAR, stiff_car_methods, stiff_car_ride_cost

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "Scenario",
    "read_config",
    "load_config",
    "ScenarioError",
    "Road",
    "NoRoad",
    "StepRoad",
    "BumpRoad",
    "SineRoad",
    "ISO8608Road",
    "ROADS",
    "CLI_ROADS",
    "RoadSpec",
    "MAX_STEPS",
    "MAX_CONFIG_BYTES",
    "config_text",
    "road_from_mapping",
    "MODELS",
    "ModelKind",
    "NONLINEAR_ROAD",
    "NONLINEAR_T_END",
    "NONLINEAR_H",
    "DEFAULT_MODEL",
    "command_line",
    "RUN_KEYS",
    "run_keys",
    "option_name",
    "option_flag",
    "vehicle_config",
    "whole_step",
]

#: The default limit on ``t_end / h``, the steps each method takes at h. The
#: comparison also runs every method at h/2, h/4, ... for its convergence
#: study, so the work is several times this. Measured on a 2-core machine:
#: 10,000 steps took 19 s and 0.3 GB for RK4 alone; 100,000 steps are a few
#: minutes and about 1.5 GB per method. Raise it per scenario (``max_steps``).
MAX_STEPS = 100_000

#: The largest config file read [bytes]. A config is a few dozen lines (a report's
#: scenario.toml is under 1 kB): a thousand times that still reads and parses in a
#: fraction of a second, and a larger file is something else (a device such as
#: /dev/zero, a log, a binary), refused before more than this is read.
MAX_CONFIG_BYTES = 1_000_000


class ScenarioError(ValueError):
    """A scenario's value is not valid. The message names the field and the value.

    Attributes
    ----------
    detail : str
        The message without its location.
    section : str or None
        The TOML table of the field (``'scenario'``, ``'scenario.road'``), or
        None for a vehicle parameter (top level).
    key : str or None
        The field's name within its table, when one field is at fault.
    source : str or None
        The file the value came from, when it came from one.
    """

    def __init__(
        self,
        detail: str,
        section: str | None = None,
        key: str | None = None,
        source: str | None = None,
    ):
        self.detail, self.section, self.key, self.source = detail, section, key, source
        text = f"[{section}] {detail}" if section else detail
        super().__init__(f"config file {source!r}: {text}" if source else text)


def _default(func: Callable, name: str):
    """The default of ``func``'s argument ``name``: defaults are read, never restated."""
    return inspect.signature(func).parameters[name].default


def _is_number(value) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))


def _number(section: str, key: str, value, unit: str, *, positive: bool) -> float:
    if not _is_number(value) or not math.isfinite(value) or (positive and value <= 0):
        what = f"a finite number > 0 {unit}" if positive else f"a finite number [{unit}]"
        raise ScenarioError(f"{key} must be {what}, got {value!r}", section, key)
    return float(value)


# ---------------------------------------------------------------- roads


_ROAD_SECTION = "scenario.road"

# The road kinds are the ride layer's (`qc_control.road`); the command line's
# earlier names for them stay as aliases.
StepRoad, BumpRoad, SineRoad = Step, Bump, Sine

#: The roads a scenario's TOML and the command line take by ``kind``: every
#: kind whose parameters are numbers (a `Profile`'s arrays are given in Python).
CLI_ROADS: dict[str, type[Road]] = {k: c for k, c in ROADS.items() if c is not Profile}

#: A road spec: a `qc_control.road.Road`.
RoadSpec = Road


def road_option(f) -> str:
    """The ``qc-control report`` option of a road parameter (a field of a `Road`)."""
    return f.metadata["option"] or "--road-" + f.name.replace("_", "-")


def road_from_mapping(values: Mapping[str, Any]) -> RoadSpec:
    """A `Road` from ``{'kind': ..., parameter: value, ...}``.

    A missing ``kind`` means no road. A key that is a parameter of another
    kind of road is refused, naming the kinds it applies to; any other key
    is refused as unknown.
    """
    values = dict(values)
    kind = values.pop("kind", "none")
    if not isinstance(kind, str) or kind.lower() not in CLI_ROADS:
        kinds = [k for k in CLI_ROADS if k != NoRoad.kind]
        raise ScenarioError(
            f"kind must be one of {', '.join(kinds)} or {NoRoad.kind}, got {kind!r}",
            _ROAD_SECTION,
            "kind",
        )
    cls = CLI_ROADS[kind.lower()]
    allowed = [f.name for f in fields(cls)]
    takes = (
        f"{cls.noun} takes {', '.join(allowed)}"
        if allowed
        else "without a road (kind = 'none') no parameter applies; set the road's kind"
    )
    for key, value in values.items():
        if key in allowed:
            continue
        users = [k for k, c in CLI_ROADS.items() if key in {f.name for f in fields(c)}]
        if users:
            where = "without a road" if cls is NoRoad else f"to {cls.noun}"
            raise ScenarioError(
                f"{key} = {value!r} does not apply {where}: it is a parameter of "
                f"{' and '.join(users)} roads; {takes}",
                _ROAD_SECTION,
                key,
            )
        raise ScenarioError(f"unknown [scenario.road] key {key!r}; {takes}", None, key)
    try:
        return cls(**values)
    except ParameterError as exc:
        raise ScenarioError(str(exc), _ROAD_SECTION, exc.name) from None


# ------------------------------------------------------------- scenario


#: The largest |x0| entry: its square (RMS errors, energies) stays far inside float range.
MAX_STATE = 1e150


#: The model of a scenario that names none (not written in its TOML or command).
DEFAULT_MODEL = "quarter"
#: Kept for the name of earlier versions: a model the Scenario runs is a registry entry.
ModelKind = ModelEntry
#: The nonlinear car's default road and run, as its registry entry states them.
NONLINEAR_ROAD: RoadSpec = road_from_mapping(get_model("nonlinear").defaults.road or {})
NONLINEAR_T_END = get_model("nonlinear").defaults.t_end
NONLINEAR_H = get_model("nonlinear").defaults.h


def vehicle_keys() -> tuple[str, ...]:
    """Every parameter name of every model in `MODELS`, each once, in order."""
    return tuple(parameter_keys())


#: The Scenario's fields that hold a model's own options (`ModelOption`) by name;
#: the options of other registered models are held in ``model_options``.
_OPTION_KEYS = ("tire", "bump_stop", "events")
RUN_KEYS = ("t_end", "h", "x0", "methods", "max_steps", "model", *_OPTION_KEYS, "solvers", "kind")
#: The scenario kinds (``kind`` in ``[scenario]``, ``--scenario``): each fills the values
#: a scenario does not give (`qc_control.studies.scenarios`).
KINDS = ("pothole", "stiff")


def run_keys() -> tuple[str, ...]:
    """The ``[scenario]`` keys: `RUN_KEYS` and every registered model's options."""
    options = (o.name for e in MODELS.values() for o in e.options)
    return tuple(dict.fromkeys((*RUN_KEYS, *options)))


#: The flat road keys of the ``[scenario]`` table of earlier versions.
_LEGACY_ROAD_KEYS = ("road", "road_class", "speed", "seed")
#: The nonlinear car's bump keys of earlier versions in ``[scenario]``: a bump road's keys.
_LEGACY_BUMP_KEYS = {"bump_height": "height", "bump_length": "length"}


def _model_name(model, vehicle) -> str:
    """The model's name: given, or read from the vehicle's type, else ``'quarter'``."""
    if model is None:
        entry = model_for_params(vehicle)
        return DEFAULT_MODEL if entry is None else entry.name
    try:
        return get_model(model).name
    except ValueError as exc:
        raise ScenarioError(str(exc), "scenario", "model") from None


def _vehicle(values, model: str):
    """The vehicle from its parameters, with a ScenarioError naming the one at fault."""
    cls = MODELS[model].params
    if values is None:
        return cls()
    if isinstance(values, cls):
        return values
    if isinstance(values, Mapping):
        names = {f.name for f in fields(cls)}
        for key in values:
            others = [k for k, m in MODELS.items() if key in {f.name for f in fields(m.params)}]
            if key not in names and others:
                raise ScenarioError(
                    f"{key} is a parameter of the {' and '.join(others)} car, not of the "
                    f"{model} car: choose the model (model = {others[0]!r} in [scenario], "
                    f"--model {others[0]})",
                    None,
                    key,
                )
        try:
            return cls.from_mapping(values)
        except ValueError as exc:
            raise ScenarioError(str(exc), None, _culprit(values, cls)) from None
    raise ScenarioError(
        f"vehicle must be a {cls.__name__} or a mapping of its parameters (model {model!r}), "
        f"got {type(values).__name__}",
        "scenario",
        "vehicle",
    )


def _culprit(values: Mapping, cls: type) -> str | None:
    """The first parameter that is bad on its own, if one is."""
    names = [f.name for f in fields(cls)]
    for key in values:
        if key not in names:
            return key
        try:
            cls(**{key: values[key]})
        except (TypeError, ValueError):
            return key
    return None


#: The default step is lowered below a method's stability limit by at most
#: this factor (10 ms to 1 ms); a limit further down is warned about instead.
_STABLE_DEFAULT_SPAN = 10.0


def _coarse_remedy(road: Road, limit: float) -> str:
    """What to change when the road is too fine for the grid: h, or the road
    alone when its ``limit`` underflowed to 0 s (a 1e308 Hz sine), which no h meets."""
    road_change = road.finer or "a coarser road"
    return f"give a smaller h, or {road_change}" if limit > 0 else f"give {road_change}"


def _sequence(value) -> list | None:
    """A list from a list, a tuple, an array or a comma-separated string; else None."""
    if isinstance(value, str):
        return [v.strip() for v in value.split(",") if v.strip()]
    if isinstance(value, (list, tuple, np.ndarray)):
        return list(value)
    return None


def _road(road: Any, default: Mapping[str, Any] | None) -> RoadSpec:
    """The scenario's road from what was given, over the model's default road.

    None (or an empty table) is the model's default road; a table of the
    default road's kind (or without a kind) takes the parameters it does
    not give from the default road.
    """
    if isinstance(road, Mapping) and not road:
        road = None
    if road is None:
        road = dict(default) if default else NoRoad()
    if isinstance(road, str):
        road = {"kind": road}
    if isinstance(road, Mapping):
        if default and road.get("kind", default["kind"]) == default["kind"]:
            road = {**default, **road}
        road = road_from_mapping(road)
    if not isinstance(road, Road):
        raise ScenarioError(
            f"road must be a qc_control.road.Road (e.g. qc.road.Bump(height=0.1)) or a table "
            f"with 'kind', got {road!r}",
            "scenario",
            "road",
        )
    return road


@dataclass(frozen=True)
class Scenario:
    """One method comparison: vehicle, initial state, road, time grid and methods.

    Every value is checked when the scenario is made; a bad one raises
    `ScenarioError` (a ``ValueError``) naming the field, the value and what
    was expected. Defaults left as None are resolved then, so a scenario
    always holds the values it runs with.

    Parameters
    ----------
    vehicle : parameters or mapping, default the model's default vehicle
        The vehicle's parameters: `QuarterCarParams` (the seed's Table 1 by
        default), `HalfCarParams` or `FullCarParams`, as ``model`` says.
    road : Road or mapping, default `NoRoad`
        The road input, with all its parameters: `StepRoad`, `BumpRoad`,
        `SineRoad` or `ISO8608Road`; a mapping ``{'kind': 'bump', ...}``
        is read by `road_from_mapping`.
    x0 : sequence of float, optional
        Initial state in the model's state order (the quarter car's
        ``[vs, vu, xs, xu]`` [m/s, m/s, m, m]). Default: the car at rest
        under a road, else the body released from 5 cm (the quarter car's
        `qc_control.studies.compare.DEFAULT_X0`).
    t_end : float, optional
        End time [s]; a whole number (at least 2) of steps ``h``. Default
        `qc_control.studies.compare.DEFAULT_T_END` (`NONLINEAR_T_END` for the
        nonlinear car).
    h : float, optional
        Step [s]. Default `qc_control.studies.compare.DEFAULT_H`; where the road
        needs a finer step (an ISO 8608 road, whose band must be sampled:
        `qc_control.ride.road.largest_step`), the largest step of the 1-2-5
        series (…, 10, 5, 2, 1, 0.5 ms, …) not above that limit, e.g. 5 ms
        at 20 m/s on the standard band (limit 8.8 ms).
    methods : sequence of str, default `qc_control.studies.compare.DEFAULT_METHODS`
        Method names (`qc_control.METHODS`), distinct. A comma-separated
        string is split.
    max_steps : int, default `MAX_STEPS`
        The largest ``t_end / h`` accepted: a run beyond it is refused
        before anything is allocated.
    model : str, optional
        A name in `MODELS`: ``'quarter'`` (default), ``'half'`` or
        ``'full'``; by default read from the type of ``vehicle``. On a half
        or full car the road is under every wheel, the rear wheels meeting
        it ``(a + b)/speed`` later (`qc_control.ride.road.axle_inputs`), so the
        road must have a speed (a bump or an ISO 8608 road); a full car's
        ISO 8608 road has correlated left and right tracks
        (`qc_control.ride.road.iso8608_tracks`, ``track_front`` apart).
        ``'nonlinear'``: the quarter car's parameters, with gravity and a
        unilateral tire; its default road is `NONLINEAR_ROAD` (give
        ``road='none'`` for its free response), and a bump's parameters not
        given are that bump's.
    tire : {'unilateral', 'linear'}, optional
        The nonlinear car's tire (default ``'unilateral'``).
    bump_stop : (clearance, stiffness), optional
        The nonlinear car's bump stop: the travel in compression before it
        touches [m] (>= 0) and its stiffness [N/m] (> 0), a
        `qc_control.BumpStop`. Default none.
    events : bool, optional
        Whether the nonlinear car's methods step to each switching time
        (default True; the convergence study runs both ways regardless).
    model_options : mapping, optional
        The options of a registered model that are not fields here
        (`qc_control.ModelOption`), by name; each checked by its option and
        defaulted. Held as ``((name, value), ...)``; `option` reads one.
    solvers : sequence of str, optional
        Peers run beside the methods over a ladder of tolerances
        (`qc_control.studies.peers.SOLVERS`); none by default.
    kind : {'pothole', 'stiff'}, optional
        A scenario of `qc_control.studies.scenarios`, whose values fill those
        not given: ``'pothole'``, the seed's car at rest into a 5 cm deep,
        0.3 m long pothole at t = 1 s at 20 m/s, 0-3 s at 1 ms; ``'stiff'``,
        the quarter car with a 1e7 N/m damper top mount on 60 s of an ISO
        8608 class C road at 20 m/s, h = 5 ms, with the L-stable tableaus
        known by name. Both run every peer.

    Examples
    --------
    >>> sc = Scenario(road=BumpRoad(height=0.1, speed=15.0))
    >>> sc.h, sc.x0, sc.steps
    (0.01, (0.0, 0.0, 0.0, 0.0), 1000)
    >>> sc.road_input()[1]
    'a 10 cm high, 1 m long 1 − cos bump met at t = 0.5 s at 15 m/s'
    >>> Scenario.from_toml_string(sc.to_toml()) == sc
    True
    """

    vehicle: Any = None
    road: RoadSpec = None  # type: ignore[assignment]  # resolved: NoRoad, or the nonlinear default
    # None resolves to the default in __post_init__: the attribute is always set
    x0: tuple[float, ...] = None  # type: ignore[assignment]
    t_end: float = None  # type: ignore[assignment]
    h: float = None  # type: ignore[assignment]
    methods: tuple[str, ...] = DEFAULT_METHODS
    max_steps: int = MAX_STEPS
    model: str = None  # type: ignore[assignment]
    tire: str | None = None
    bump_stop: tuple[float, float] | None = None
    events: bool | None = None
    model_options: Any = None  # resolved: a tuple of (name, value) pairs, hashable
    solvers: tuple[str, ...] = None  # type: ignore[assignment]  # resolved: () without peers
    kind: str | None = None

    def __post_init__(self):
        put = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        given_end = self.t_end is not None  # a grid error is then t_end's, else h's
        self._kind()
        put("model", _model_name(self.model, self.vehicle))
        put("vehicle", _vehicle(self.vehicle, self.model))
        defaults = self.entry.defaults
        road = _road(self.road, defaults.road)
        put("road", road)
        put("methods", self._methods(self.methods))
        put("t_end", defaults.t_end if self.t_end is None else self.t_end)
        put("t_end", _number("scenario", "t_end", self.t_end, "s", positive=True))
        limit = road.largest_step()
        chosen = self.h is None
        if chosen:
            put("h", self._default_step(defaults.h, limit))
        else:
            put("h", _number("scenario", "h", self.h, "s", positive=True))
        m = self.max_steps
        if isinstance(m, bool) or not isinstance(m, (int, np.integer)) or m < 2:
            raise ScenarioError(
                f"max_steps must be an integer >= 2, got {m!r}", "scenario", "max_steps"
            )
        put("max_steps", int(m))
        self._check_grid(chosen, given_end)
        t0 = getattr(road, "t0", None)
        if t0 is not None and t0 > self.t_end:
            # the run would end before the car meets the road: every figure flat, every
            # error 0, and a report that says nothing happened
            raise ScenarioError(
                f"t0 = {t0:g} s is after the run's end t_end = {self.t_end:g} s: the car "
                "would never meet the road; use an earlier t0 or a longer t_end",
                _ROAD_SECTION,
                "t0",
            )
        if self.h > limit * (1 + 1e-12):
            raise ScenarioError(
                f"h = {self.h!r} s is too coarse for {road.sampled()}: it must be <= "
                f"{limit:.4g} s ({_coarse_remedy(road, limit)})",
                "scenario",
                "h",
            )
        self._model_options()
        put("x0", self._x0(self.x0))
        if self.entry.road_layout != "single" and not isinstance(road, NoRoad):
            self._check_speed()
        try:
            put("solvers", check_solvers(self.solvers))
        except (TypeError, ValueError) as exc:
            raise ScenarioError(f"solvers: {exc}", "scenario", "solvers") from None

    def _kind(self) -> None:
        """Fill what a scenario kind (`KINDS`) sets and the scenario does not give."""
        put = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        if self.kind is None:
            return
        if self.kind not in KINDS:
            raise ScenarioError(
                f"kind must be one of {', '.join(KINDS)}, got {self.kind!r}", "scenario", "kind"
            )
        if self.model not in (None, DEFAULT_MODEL):
            raise ScenarioError(
                f"kind = {self.kind!r} is a run of the quarter car, not of the {self.model} car",
                "scenario",
                "kind",
            )
        run = POTHOLE if self.kind == "pothole" else STIFF_CAR
        if self.road is None or (isinstance(self.road, Mapping) and not self.road):
            put("road", run.road())
        put("t_end", run.t_end if self.t_end is None else self.t_end)
        put("h", run.h if self.h is None else self.h)
        put(
            "solvers",
            ("RK45", "DOP853", "LSODA", "Radau", "BDF", "control")
            if self.solvers is None
            else self.solvers,
        )
        if self.kind == "stiff":
            options = dict(self.model_options or {})
            options.setdefault("mount_stiffness", STIFF_CAR.mount_stiffness)
            put("model_options", options)
            if tuple(self.methods) == DEFAULT_METHODS:
                put("methods", stiff_car_methods())

    @property
    def entry(self) -> ModelEntry:
        """The registry entry of this scenario's model (`qc_control.models.registry`)."""
        return get_model(self.model)

    def _model_options(self) -> None:
        """Check (and default) the keys that apply to some models only (`ModelOption`):
        the fields ``tire``, ``bump_stop``, ``events`` and ``model_options``' entries."""
        entry = self.entry
        given = dict(self.model_options or {})
        given.update({k: getattr(self, k) for k in _OPTION_KEYS if getattr(self, k) is not None})
        for key, value in given.items():
            if entry.option(key) is None:
                users = [e.name for e in MODELS.values() if e.option(key) is not None]
                if not users:
                    raise ScenarioError(f"unknown [scenario] key {key!r}", "scenario", key)
                raise ScenarioError(
                    f"{key} = {value!r} applies to the {' and '.join(users)} car only: "
                    f"choose it (model = {users[0]!r} in [scenario], --model {users[0]})",
                    "scenario",
                    key,
                )
        extra = []
        for option in entry.options:
            value = given.get(option.name, option.default)
            try:
                checked = option.check(value)
            except ValueError as exc:
                raise ScenarioError(str(exc), "scenario", option.name) from None
            if option.name in _OPTION_KEYS:
                object.__setattr__(self, option.name, checked)
            else:
                extra.append((option.name, checked))
        object.__setattr__(self, "model_options", tuple(extra))
        if given:
            # an option valid alone may not fit the vehicle (a top mount needs a damper,
            # cs > 0): the build says so, and the error is the option's
            try:
                self.entry.model(self.vehicle, road=False, **self.option_arguments("build"))
            except ValueError as exc:
                raise ScenarioError(str(exc), "scenario", next(iter(given))) from None

    def option(self, name: str) -> Any:
        """The value of the model option ``name`` (a `ModelOption` of its entry)."""
        if name in _OPTION_KEYS:
            return getattr(self, name)
        return dict(self.model_options)[name]

    def option_arguments(self, target: str) -> dict[str, Any]:
        """This scenario's model options bound for ``target`` (``'build'`` or
        ``'compare'``), as the keyword arguments that take them."""
        return {
            o.name: o.argument(self.option(o.name))
            for o in self.entry.options
            if o.target == target
        }

    def _default_step(self, h: float, road_limit: float) -> float:
        """The model's default step, lowered to the 1-2-5 series below the road's
        limit and below every requested method's stability limit.

        A default beyond a method's limit would report growth, not accuracy.
        A limit more than `_STABLE_DEFAULT_SPAN` times below the default (a
        nearly undamped mode, a featherweight design) would make the
        convergence study's refinements too long a run: it is left to the
        warning (`beyond_limits`) instead.
        """
        if h > road_limit > 0:  # 0 s: no step samples the road, which the grid check refuses
            h = preferred_step(road_limit)
        stable = [limit for limit in self.step_limits().values() if 0 < limit < h]
        if not stable:
            return h
        step = preferred_step(min(stable))
        return step if step * _STABLE_DEFAULT_SPAN >= h else h

    def step_note(self) -> str:
        """Why the default step was lowered, in words; '' when it was not (or h was given)."""
        default = self.entry.defaults.h
        if self.h >= default or self.h != self._default_step(default, self.road.largest_step()):
            return ""
        if self.h <= self.road.largest_step() < default:
            return (
                f"h = {self.h:g} s, below the default {default:g} s, to sample "
                f"{self.road.sampled()}"
            )
        slowest = min(self.step_limits().items(), key=lambda item: item[1])
        return (
            f"h = {self.h:g} s, below the default {default:g} s, to stay within "
            f"{slowest[0]}'s stability limit h_max = {slowest[1]:.3g} s on this car"
        )

    def step_limits(self) -> dict[str, float]:
        """Each method's stability limit h_max [s] on this scenario's car.

        `qc_control.max_stable_step` of the car's state matrix, by method
        name; empty for a model without one (the nonlinear car, whose
        comparison reports the limits of its linearisation).
        """
        system = self.entry.model(self.vehicle).system
        if not isinstance(system, control.StateSpace):
            return {}
        return {m: max_stable_step(m, system) for m in self.methods}

    def beyond_limits(self) -> dict[str, float]:
        """The methods whose limit h_max [s] this scenario's step exceeds, with it."""
        return {m: h for m, h in self.step_limits().items() if self.h > h * (1 + 1e-12)}

    def _check_speed(self) -> None:
        if getattr(self.road, "speed", None) is None:
            raise ScenarioError(
                f"a {self.road.kind} road has no speed, but the {self.model} car's rear wheels "
                f"meet the road (a + b)/speed after the front ones: use a bump or an iso8608 "
                f"road",
                _ROAD_SECTION,
                "kind",
            )

    def _methods(self, methods) -> tuple[str, ...]:
        names = _sequence(methods)
        if names is None or not all(isinstance(m, str) for m in names):
            raise ScenarioError(
                f"methods must be a list of method names, got {methods!r}", "scenario", "methods"
            )
        if not names:
            raise ScenarioError("methods must name at least one method", "scenario", "methods")
        known = _named_tableaus()
        unknown = [m for m in names if m.lower() not in known]
        if unknown:
            raise ScenarioError(
                f"methods: unknown method {unknown[0]!r}; known methods are {', '.join(known)}",
                "scenario",
                "methods",
            )
        canonical = tuple(get_method(m).name for m in names)
        if len(set(canonical)) != len(canonical):
            raise ScenarioError(
                f"methods must be distinct, got {list(names)!r}", "scenario", "methods"
            )
        return canonical

    def _check_grid(self, chosen: bool, given_end: bool) -> None:
        """Refuse a grid beyond ``max_steps`` or one that is not whole steps.

        The error is the key the caller gave: ``t_end``, or ``h`` when only the
        step was given (its end time the default), so that a message about a
        given ``--h`` does not name a ``t_end`` nobody wrote.
        """
        t_end, h, limit = self.t_end, self.h, self.max_steps
        key = "h" if not chosen and not given_end else "t_end"
        ratio = t_end / h
        if not ratio <= limit + 0.5:
            count = f"{ratio:.3g}" if math.isfinite(ratio) else "more than 1.8e308"
            grid = (
                f"h = {h!r} s over the default end time {t_end:g} s"
                if key == "h"
                else f"t_end = {t_end:g} s at h = {h:g} s"
            )
            raise ScenarioError(
                f"{grid} is {count} steps per method (and more for the refinements h/2, h/4, "
                f"...), above max_steps = {limit:,}; raise max_steps (--max-steps) only if the "
                f"machine can hold such a run",
                "scenario",
                key,
            )
        steps = round(ratio)
        if steps < 2 or abs(steps * h - t_end) > 1e-9 * t_end:
            grid = (
                f"h = {h!r} s does not fit the default end time {t_end!r} s: the end time"
                if key == "h"
                else f"t_end = {t_end!r} s"
            )
            raise ScenarioError(
                f"{grid} must be a whole number (at least 2) of steps "
                f"h = {h!r} s, got {ratio:.6g} steps"
                + (" (the default step; give h to choose another)" if chosen else ""),
                "scenario",
                key,
            )

    def _x0(self, x0) -> tuple[float, ...]:
        build = self.option_arguments("build")  # an option may add states (a top mount)
        model = self.entry.model(self.vehicle, **build)
        names = list(model.system.state_labels)
        if x0 is None:
            if not isinstance(self.road, NoRoad):
                return (0.0,) * len(names)
            return self.entry.free_start(self.vehicle, **build)
        values = _sequence(x0)
        if values is not None and all(isinstance(v, str) for v in values):
            try:
                values = [float(v) for v in values]
            except ValueError:
                values = None
        if (
            values is None
            or len(values) != len(names)
            or not all(_is_number(v) and math.isfinite(v) for v in values)
        ):
            units = model.units
            raise ScenarioError(
                f"x0 must be {len(names)} comma-separated numbers, all finite: "
                f"{', '.join(names)} [{', '.join(units[n] for n in names)}]; got {x0!r}",
                "scenario",
                "x0",
            )
        big = [v for v in values if abs(v) > MAX_STATE]
        if big:
            raise ScenarioError(
                f"x0 = {big[0]!r} is beyond {MAX_STATE:.0e}: the comparison squares the "
                "states (RMS errors, energies), and the square of such a value overflows "
                "double precision; the car is linear, so a smaller x0 scales the response",
                "scenario",
                "x0",
            )
        return tuple(float(v) for v in values)

    # ------------------------------------------------------------ running

    @property
    def steps(self) -> int:
        """The number of steps ``t_end / h`` of the grid."""
        return round(self.t_end / self.h)

    def time_grid(self) -> np.ndarray:
        """The uniform output grid ``0, h, ..., t_end`` [s] (``steps + 1`` points)."""
        return np.linspace(0.0, self.t_end, self.steps + 1)

    def road_input(self, T=None) -> tuple[np.ndarray | None, str]:
        """``(road samples on T, description)``; ``(None, '')`` without a road.

        The samples follow the model's road layout (`ModelEntry.road_layout`):
        on a quarter car ``zr``; on a half car ``[zr_front, zr_rear]`` and on
        a full car ``[zr_fl, zr_fr, zr_rl, zr_rr]``, the rear wheels a
        wheelbase later. The description is written from the road's actual
        parameters. ``T`` defaults to `time_grid`.
        """
        T = self.time_grid() if T is None else T
        return road_inputs(self.road, T, self.entry, self.vehicle)

    def vehicle_model(self, *, road: bool = False) -> VehicleModel:
        """The `VehicleModel` this scenario runs, with this scenario's model options
        (the nonlinear car's tire and bump stop).

        With ``road=True`` a model that takes the road as a function of time
        (`ModelEntry.road_function`) gets this scenario's road so, evaluated
        at every stage, with its ``jumps`` (`Road.jumps`: a step's t0); an
        ISO 8608 road, which has no closed form, stays the input ``zr``.
        """
        if not road:
            return self.entry.model(self.vehicle, **self.option_arguments("build"))
        T = self.time_grid()[:2]
        return road_problem(
            self.vehicle, self.road, T, entry=self.entry, options=self.option_arguments("build")
        )[0]

    def problem(self) -> tuple[VehicleModel, np.ndarray, np.ndarray | None, str]:
        """What `run` compares the methods on: ``(vehicle, T, U, description)``.

        The vehicle model (with its road inputs under a road), the time grid,
        the road samples on it (None for the free response, or when the
        model takes the road as a function of time) and the road in words.
        """
        T = self.time_grid()
        vehicle, U, description = road_problem(
            self.vehicle, self.road, T, entry=self.entry, options=self.option_arguments("build")
        )
        return vehicle, T, U, description

    def run(self, progress: Callable[[str], None] | None = None) -> MethodComparison:
        """Run the comparison: `qc_control.compare_methods` on this scenario.

        Returns its `MethodComparison` with ``scenario`` this scenario (the
        report records it and its `command`).
        """
        vehicle, T, U, description = self.problem()
        cmp = compare_methods(
            vehicle,
            T,
            np.asarray(self.x0),
            U=U,
            methods=self.methods,
            progress=progress,
            input_description=description,
            solvers=self.solvers or None,
            **self.option_arguments("compare"),
        )
        if self.kind == "stiff" and cmp.ride is not None:  # on the road: a ride answer
            cmp = dataclasses.replace(cmp, ride_cost=stiff_car_ride_cost(cmp, progress=progress))
        return dataclasses.replace(cmp, scenario=self)  # the comparison is frozen

    # ------------------------------------------------------ reading, writing

    @classmethod
    def from_mapping(
        cls,
        values: Mapping[str, Any],
        *,
        overrides: Mapping[str, Any] | None = None,
        source: str | None = None,
    ) -> Scenario:
        """A scenario from a TOML-shaped mapping (see the module's layout).

        Parameters
        ----------
        values : mapping
            Vehicle parameters at the top level, a ``'scenario'`` table with
            the run's keys and a ``'road'`` table (``[scenario.road]``), or the
            earlier flat road keys.
        overrides : mapping, optional
            The same layout, applied over ``values`` (the command-line options
            over a config file). Damping given here (``zeta`` or ``cs``)
            replaces both of ``values``'; a road of another ``kind`` replaces
            ``values``' road, a road of the same kind (or none given) updates it.
        source : str, optional
            Where ``values`` came from: errors in values not overridden
            name it.

        Raises
        ------
        ScenarioError
            For an unknown key, a key that does not apply (a road parameter
            of another kind of road), or a bad value.
        """
        over = _canonical(overrides or {})
        try:
            base = _canonical(values, source)
        except ScenarioError as exc:
            raise ScenarioError(exc.detail, exc.section, exc.key, source) from None
        vehicle = dict(base["vehicle"])
        if {"zeta", "cs"} & set(over["vehicle"]):
            vehicle.pop("zeta", None)
            vehicle.pop("cs", None)
        vehicle.update(over["vehicle"])
        run = {**base["run"], **over["run"]}
        road = base["road"]
        if "kind" in over["road"] and over["road"]["kind"] != road.get("kind", "none"):
            road = dict(over["road"])
        else:
            road = {**road, **over["road"]}
        given = {None: over["vehicle"], "scenario": over["run"], _ROAD_SECTION: over["road"]}
        try:
            fixed = {k: v for k, v in run.items() if k in RUN_KEYS}
            extra = {k: v for k, v in run.items() if k not in RUN_KEYS}
            return cls(
                vehicle=cast(Any, vehicle),
                road=cast(Any, road),
                model_options=extra or None,
                **fixed,
            )
        except ScenarioError as exc:
            from_overrides = exc.key is not None and exc.key in given.get(exc.section, {})
            section, key, detail = exc.section, exc.key, exc.detail
            if section == _ROAD_SECTION and not from_overrides:
                section = base["road_section"]
                written = base["road_keys"].get(key, key)  # as the file spells it
                if key is not None and written != key and detail.startswith(f"{key} "):
                    detail = written + detail[len(key) :]
                key = written
            raise ScenarioError(detail, section, key, None if from_overrides else source) from None

    @classmethod
    def from_toml(cls, path, *, overrides: Mapping[str, Any] | None = None) -> Scenario:
        """Read a scenario from a TOML file; errors name the file.

        ``overrides`` as in `from_mapping`. A file of more than
        `MAX_CONFIG_BYTES` is refused, having read no more than that.
        """
        text = config_text(path)
        return cls.from_toml_string(text, overrides=overrides, source=str(path))

    @classmethod
    def from_toml_string(
        cls, text: str, *, overrides: Mapping[str, Any] | None = None, source: str | None = None
    ) -> Scenario:
        """A scenario from TOML text, e.g. `to_toml`'s."""
        data = _parse_toml(text, f"config file {source!r}" if source else "the scenario")
        return cls.from_mapping(data, overrides=overrides, source=source)

    def to_toml(self) -> str:
        """The scenario as TOML, in the layout `from_toml` reads.

        Floats are written with ``repr``, so they read back bit for bit:
        ``Scenario.from_toml_string(s.to_toml()) == s``. Both ``zeta`` and
        ``cs`` are written (they agree), so the damping is exact.
        """
        lines = [
            "# A qc-control scenario (qc_control.Scenario): one comparison run.",
            "# Redo it with: qc-control report --config <this file>",
            "# Floats are written exactly (repr). zeta and cs are both given, and agree;",
            "# to change the damping, keep only one of them.",
            "",
            *(f"{k} = {_toml_value(v)}" for k, v in self.vehicle.to_dict().items()),
            "",
            "[scenario]",
            *([f"model = {_toml_value(self.model)}"] if self.model != DEFAULT_MODEL else []),
            f"t_end = {_toml_value(self.t_end)}",
            f"h = {_toml_value(self.h)}",
            f"x0 = {_toml_value(self.x0)}",
            f"methods = {_toml_value(self.methods)}",
        ]
        if self.max_steps != MAX_STEPS:
            lines.append(f"max_steps = {self.max_steps}")
        if self.solvers:
            lines.append(f"solvers = {_toml_value(self.solvers)}")
        if self.kind is not None:
            lines.append(f"kind = {_toml_value(self.kind)}")
        for option in self.entry.options:
            value = self.option(option.name)
            if value is not None:
                lines.append(f"{option.name} = {_toml_value(value)}")
        if self.entry.defaults.road and isinstance(self.road, NoRoad):
            # no road is not this model's default: say so
            lines += ["", f"[{_ROAD_SECTION}]", f"kind = {_toml_value(NoRoad.kind)}"]
        elif not isinstance(self.road, NoRoad):
            lines += ["", f"[{_ROAD_SECTION}]", f"kind = {_toml_value(self.road.kind)}"]
            lines += [f"{k} = {_toml_value(v)}" for k, v in self.road.params().items()]
        return "\n".join(lines) + "\n"

    def command(self, *, out=None, config=None) -> str:
        """The ``qc-control report`` command that redoes this run exactly.

        Parameters
        ----------
        out : path, optional
            Add ``--out out``; by default the command writes ``report/``.
        config : path, optional
            Read the scenario from this TOML file (`to_toml`'s) instead of
            giving every value as an option.

        Every value is written with ``repr``, so the command gives the same
        numbers; defaults are written out, so it does not depend on them.
        """
        if config is not None:
            options: list[tuple[str, str | None]] = [("--config", str(config))]
        else:
            options = self._options()
        if out is not None:
            options.append(("--out", str(out)))
        return command_line(["report"], options)

    def _options(self) -> list[tuple[str, str | None]]:
        """``(option, value)`` pairs of ``qc-control report`` that give every value
        of this scenario (value None: a flag)."""
        options: list[tuple[str, str | None]] = []
        if self.model != DEFAULT_MODEL:
            options.append(("--model", self.model))
        options += [(option_name(k), repr(v)) for k, v in self.vehicle.to_dict().items()]
        options += [("--t-end", repr(self.t_end)), ("--h", repr(self.h))]
        options += [("--x0", ",".join(map(repr, self.x0))), ("--methods", ",".join(self.methods))]
        if self.max_steps != MAX_STEPS:
            options.append(("--max-steps", str(self.max_steps)))
        if self.solvers:
            options.append(("--solvers", ",".join(self.solvers)))
        if self.kind is not None:
            options.append(("--scenario", self.kind))
        for option in self.entry.options:
            value = self.option(option.name)
            if isinstance(value, bool):
                if value != option.default:
                    options.append((option_flag(option.name, option.default), None))
            elif value is not None:
                options.append((option_name(option.name), _cli_text(value)))
        if self.entry.defaults.road and isinstance(self.road, NoRoad):
            options.append(("--road", NoRoad.kind))
        if not isinstance(self.road, NoRoad):
            options.append(("--road", self.road.kind))
            options += [
                (road_option(f), _cli_text(getattr(self.road, f.name))) for f in fields(self.road)
            ]
        return options


def _named_tableaus() -> dict:
    """Every tableau known by name: `TABLEAUS` where the catalogue has it, else `METHODS`."""
    return getattr(catalogue, "TABLEAUS", METHODS)


def option_name(key: str) -> str:
    """A key's option: ``--ks-front`` for ``ks_front`` (one spelling, as ``--t-end``)."""
    return "--" + key.replace("_", "-")


def option_flag(key: str, default: bool) -> str:
    """The flag that turns a boolean option away from its default: ``--no-events``."""
    return option_name(f"no_{key}" if default else key)


def _cli_text(value) -> str:
    """A value as the command line gives it: tuples comma-separated, floats by repr."""
    if isinstance(value, tuple):
        return ",".join(map(repr, value))
    return value if isinstance(value, str) else repr(value)


def command_line(
    words: list[str], options: list[tuple[str, str | None]], *, windows: bool | None = None
) -> str:
    """``qc-control WORDS --option value ...`` as one line quoted for this platform's shell.

    Parameters
    ----------
    words : list of str
        The subcommand, e.g. ``['report']``.
    options : list of (option, value)
        Each option with its value as text, or None for a flag.
    windows : bool, optional
        Quote for Windows' ``cmd.exe`` (double quotes) rather than a POSIX shell
        (single quotes). By default, for the platform the line is written on, which
        is where a report's reader reruns it.
    """
    args = ["qc-control", *words]
    for name, value in options:
        args += [name] if value is None else _option(name, value)
    if windows is None:
        windows = sys.platform == "win32"
    return " ".join(map(_cmd_quote, args)) if windows else shlex.join(args)


#: Characters that cmd.exe or the C runtime's argument splitting read as more than
#: text outside double quotes: blanks split, the rest redirect, chain or escape.
_CMD_SPECIAL = frozenset(" \t&|<>^()%!\"',;=")


def _cmd_quote(arg: str) -> str:
    """``arg`` as one argument on a ``cmd.exe`` line, read back by the C runtime intact.

    Inside double quotes cmd.exe passes ``&|<>^()`` through; the C runtime then
    reads ``\\"`` as a quote and doubles backslashes only before a quote
    (`subprocess.list2cmdline` follows the same rules).
    """
    if arg and not _CMD_SPECIAL.intersection(arg):
        return arg
    escaped = re.sub(r'(\\*)"', r'\1\1\\"', arg)  # backslashes before a quote doubled
    escaped = re.sub(r"(\\+)$", r"\1\1", escaped)  # and before the closing quote
    return f'"{escaped}"'


def _option(name: str, value: str) -> list[str]:
    """``[--name, value]``, or ``[--name=value]`` for a value argparse would take for an option."""
    return [f"{name}={value}"] if value.startswith("-") else [name, value]


def _toml_value(value) -> str:
    """A TOML value: floats by repr (exact), strings as JSON (a TOML basic string)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {value!r} as TOML")  # pragma: no cover - a bug here


def _canonical(doc: Mapping[str, Any], source: str | None = None) -> dict[str, Any]:
    """``{'vehicle', 'run', 'road', 'road_section', 'road_keys'}`` from any supported layout.

    ``road_keys`` maps a road key to the key the document wrote it as (the
    deprecated ``bump_height`` for ``height``), so that an error names it.
    """
    if not isinstance(doc, Mapping):
        raise ScenarioError(f"a scenario must be a table (a mapping), got {doc!r}")
    vehicle, table = {}, {}
    keys = vehicle_keys()
    for key, value in doc.items():
        if key in keys:
            vehicle[key] = value
        elif key == "scenario":
            if not isinstance(value, Mapping):
                raise ScenarioError(f"'scenario' must be a table, got {value!r}", None, key)
            table = dict(value)
        else:
            hint = " (put the road in a [scenario.road] table)" if key == "road" else ""
            raise ScenarioError(
                f"unknown key {key!r}{hint}; expected the vehicle's parameters "
                f"{', '.join(keys)} and a [scenario] table",
                None,
                key,
            )
    road, section = table.pop("road", None), _ROAD_SECTION
    legacy = {k: table.pop(k) for k in (*_LEGACY_ROAD_KEYS[1:], *_LEGACY_BUMP_KEYS) if k in table}
    unknown = sorted(set(table) - set(run_keys()))
    if unknown:
        raise ScenarioError(
            f"unknown [scenario] key {unknown[0]!r}; expected {', '.join(run_keys())} and a "
            f"road (a [scenario.road] table with kind and its parameters)",
            None,
            unknown[0],
        )
    _warn_legacy(road, legacy, source)
    road_keys = {_LEGACY_BUMP_KEYS.get(k, k): k for k in legacy}
    if isinstance(road, Mapping):
        road = _table_and_bump(dict(road), legacy)
    elif road is None or isinstance(road, str):  # the flat layout of earlier versions
        road = _flat_road(road, legacy)
        section = "scenario"
    else:
        raise ScenarioError(
            f'road must be a [scenario.road] table (or a kind such as "bump"), got {road!r}',
            "scenario",
            "road",
        )
    return {
        "vehicle": vehicle,
        "run": table,
        "road": road,
        "road_section": section,
        "road_keys": road_keys,
    }


def _warn_legacy(road, legacy: Mapping[str, Any], source: str | None) -> None:
    """A `DeprecationWarning` for each flat road key of ``[scenario]``, naming its new place."""
    where = f"config file {source!r}: " if source else ""
    written = ({"road": road} if isinstance(road, str) else {}) | dict(legacy)
    for key, value in written.items():
        new = {"road": "kind"}.get(key, _LEGACY_BUMP_KEYS.get(key, key))
        kind = ' (with kind = "bump")' if key in _LEGACY_BUMP_KEYS else ""
        warnings.warn(
            f"{where}[scenario] {key} = {value!r} is deprecated and will be removed in the next "
            f"release: write {new} = {value!r} in a [scenario.road] table{kind}",
            DeprecationWarning,
            stacklevel=outside_level(),
        )


def outside_level() -> int:
    """The ``stacklevel`` of the first caller outside qc_control, for `warnings.warn`
    called from the function calling this: a deprecation then points at the
    user's line, however deep in the package the old spelling was read."""
    frame: FrameType | None = sys._getframe(1)
    level = 1
    while frame is not None and frame.f_globals.get("__name__", "").startswith("qc_control"):
        frame, level = frame.f_back, level + 1
    return level


def _table_and_bump(road: dict[str, Any], legacy: Mapping[str, Any]) -> dict[str, Any]:
    """A ``[scenario.road]`` table with the deprecated bump keys beside it merged in;
    any other flat road key beside a table is refused."""
    for key, value in legacy.items():
        name = _LEGACY_BUMP_KEYS.get(key)
        if name is None:
            raise ScenarioError(
                f"{key} beside a [scenario.road] table: put it in the table", "scenario", key
            )
        if name in road:
            raise ScenarioError(
                f"{key} and [scenario.road] {name} are the same value: give one", "scenario", key
            )
        _bump_only(key, road)
        road[name] = value
    return road


def _flat_road(kind: str | None, legacy: Mapping[str, Any]) -> dict[str, Any]:
    """The road of the flat layout: ``road = KIND`` and its keys in ``[scenario]``;
    ``bump_height`` and ``bump_length`` make it a bump road."""
    road: dict[str, Any] = {"kind": kind} if kind is not None else {}
    for key, value in legacy.items():
        if key in _LEGACY_BUMP_KEYS:
            _bump_only(key, road)
            road.setdefault("kind", "bump")
        road[_LEGACY_BUMP_KEYS.get(key, key)] = value
    return road


def _bump_only(key: str, road: Mapping[str, Any]) -> None:
    """Refuse a deprecated bump key on a road of another kind."""
    kind = road.get("kind", "bump")
    if not isinstance(kind, str) or kind.lower() != "bump":
        raise ScenarioError(
            f"{key} applies to a bump road, not to the road of kind {kind!r}", "scenario", key
        )


def vehicle_config(path: str | Path) -> dict[str, Any]:
    """A config file's vehicle: for commands that run no scenario (``modes``,
    ``control-report``).

    The top-level parameters and the ``[scenario]`` keys that choose and build
    the model (``model`` and the models' options, such as ``mount_stiffness``);
    the run's keys (``t_end``, ``h``, the road, ...) are left out, so that a
    report's ``scenario.toml`` serves these commands and its run is not
    checked where it does not apply. Errors name the file.
    """
    data = _parse_toml(config_text(path), f"config file {str(path)!r}")
    table = data.get("scenario")
    if isinstance(table, Mapping):
        options = {o.name for e in MODELS.values() for o in e.options}
        data["scenario"] = {k: v for k, v in table.items() if k == "model" or k in options}
    return data


def config_text(path: str | Path) -> str:
    """The text of the config file ``path``, read with a bound on its size.

    No more than `MAX_CONFIG_BYTES` and one byte are read, so a path to a
    device (an endless stream of zeros or random bytes) is refused at once
    rather than read until memory runs out; a regular file is measured
    before it is opened.

    Raises
    ------
    ScenarioError
        Naming the file: it cannot be read, is larger than `MAX_CONFIG_BYTES`,
        or is not UTF-8 text.
    """
    path = Path(path)
    name = str(path)
    too_large = (
        f"config file {name!r} is not a scenario config: it holds more than "
        f"{MAX_CONFIG_BYTES:,} bytes (a config is a few lines of TOML)"
    )
    try:
        if path.is_file() and path.stat().st_size > MAX_CONFIG_BYTES:
            raise ScenarioError(too_large)
        with path.open("rb") as fh:
            data = fh.read(MAX_CONFIG_BYTES + 1)
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise ScenarioError(f"config file {name!r} cannot be read: {reason}") from None
    if len(data) > MAX_CONFIG_BYTES:
        raise ScenarioError(too_large)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(
            f"config file {name!r} is not a TOML text file (not UTF-8: byte "
            f"{data[exc.start]:#04x} at position {exc.start})"
        ) from None


def _parse_toml(text: str, where: str) -> dict[str, Any]:
    """TOML ``text`` as a dict; errors begin with ``where`` (the file, or "the scenario")."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{where} is not valid TOML: {exc}") from None
    except RecursionError:  # the parser recurses once per level of an array or inline table
        raise ScenarioError(
            f"{where} is not a scenario config: its arrays or tables are nested more deeply "
            "than the TOML reader can follow"
        ) from None


def read_config(path: str | Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """Read a TOML file into ``(parameter values, scenario table)``, unresolved.

    Parameter keys (``ms``, ``mu``, ``ks``, ``ku``, ``zeta``, ``cs``) stand at
    the top level; an optional ``[scenario]`` table is returned as it is
    (its reader checks it). Any other top-level key, or a bad value, raises
    ``ValueError`` naming the file and the key or value.
    """
    path = Path(path)
    data = _parse_toml(config_text(path), f"config file {str(path)!r}")
    scenario = data.pop("scenario", {})
    if not isinstance(scenario, dict):
        raise ValueError(f"config file {str(path)!r}: 'scenario' must be a table")
    try:
        QuarterCarParams.from_mapping(data)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"config file {str(path)!r}: {exc}") from None
    return data, scenario


def load_config(path: str | Path) -> tuple[QuarterCarParams, dict[str, Any]]:
    """Read a TOML config: ``(QuarterCarParams, scenario table)``.

    See `read_config` for the file's layout and errors.

    Examples
    --------
    A file holding ``ms = 350.0`` and ``zeta = 0.3`` gives
    ``QuarterCarParams(ms=350.0, zeta=0.3)`` and ``{}``.
    """
    values, scenario = read_config(path)
    return QuarterCarParams(**values), scenario
