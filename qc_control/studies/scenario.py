"""One comparison run as data: the vehicle, its start, the road, the grid and the methods.

A `Scenario` is what ``qc-control report`` runs and what a report records.
It is validated once, when it is made; it reads from and writes to TOML
(`Scenario.from_toml`, `Scenario.to_toml`: the file's layout and its
earlier versions are `qc_control.studies.scenario_toml`'s), and
`Scenario.command` gives the exact command that redoes it
(`qc_control.studies.scenario_command`). `Scenario.run` calls
`qc_control.compare_methods` and returns its `MethodComparison` with
``cmp.scenario`` set.

Its road is a `qc_control.road.Road` (``Scenario(road=qc.road.Bump(height=0.1))``);
a road kind's name or a table ``{'kind': 'bump', ...}`` is still read, with a
`DeprecationWarning` naming the `Road` to give instead.

With ``model = "nonlinear"`` (`qc_control.nonlinear_quarter_car_model`:
gravity, a unilateral tire, an optional bump stop) the defaults are the
lift-off case: a 1 − cos bump 20 cm high and 8 m long at 20 m/s, met at
0.1 s, over 0-0.8 s at h = 2 ms (`NONLINEAR_ROAD`, `NONLINEAR_T_END`,
`NONLINEAR_H`); the road is then a function of time (a closed form at
every stage), except an ISO 8608 road, which is sampled.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from typing import Any, cast

import control
import numpy as np

from ..models.registry import MODELS, ModelEntry, get_model, model_for_params
from ..models.vehicle import VehicleModel
from ..numerics import checks
from ..numerics import methods as catalogue
from ..numerics.checks import ParameterError
from ..numerics.methods import METHODS, get_method
from ..numerics.stability import max_stable_step
from ..numerics.steps import preferred_step
from ..ride import road as roads
from ..ride.guidance import RUNNING_RMS_WINDOW
from ..ride.iso2631 import band_top

# ROADS and ISO8608Road: 0.1's names of this module (``from qc_control.scenario import
# ROADS``), which answers that old path; the road kinds are `qc_control.road`'s
from ..ride.road import ROADS, ISO8608Road, NoRoad, Road  # noqa: F401
from .compare import DEFAULT_METHODS, MethodComparison, compare_methods
from .on_road import road_inputs, road_problem
from .peers import check_solvers
from .scenario_command import command_line, command_options
from .scenario_toml import (
    DEFAULT_MODEL,
    MAX_STEPS,
    OPTION_KEYS,
    ROAD_SECTION,
    RUN_KEYS,
    ScenarioError,
    config_text,
    error_in_layout,
    load_config,
    merged_layout,
    outside_level,
    parse_toml,
    read_config,
    road_from_mapping,
    scenario_text,
)
from .scenarios import POTHOLE, STIFF_CAR, stiff_car_methods, stiff_car_ride_cost

__all__ = [
    "Scenario",
    "ScenarioError",
    "read_config",
    "load_config",
    "road_from_mapping",
    "ModelKind",
    "KINDS",
    "MAX_STATE",
    "MAX_STEPS",
    "DEFAULT_MODEL",
    "NONLINEAR_ROAD",
    "NONLINEAR_T_END",
    "NONLINEAR_H",
]


#: Annex B's Figure B.1 covers daily exposures of 10 min to 24 h [h].
EXPOSURE_HOURS = (10.0 / 60.0, 24.0)

#: The largest magnitude of an x0 entry: its square (RMS errors, energies) stays far
#: inside the range of a float.
MAX_STATE = 1e150


#: Kept for the name of earlier versions: a model the Scenario runs is a registry entry.
ModelKind = ModelEntry
#: The nonlinear car's default road and run, as its registry entry states them.
NONLINEAR_ROAD: Road = road_from_mapping(get_model("nonlinear").defaults.road or {})
NONLINEAR_T_END = get_model("nonlinear").defaults.t_end
NONLINEAR_H = get_model("nonlinear").defaults.h


#: The names of the road kinds in 0.1 (`qc_control.scenario`) and in the command
#: line's module: each answers with its kind of `qc_control.road` and a warning.
_ROAD_ALIASES = {"StepRoad": "Step", "BumpRoad": "Bump", "SineRoad": "Sine"}


def __getattr__(name: str) -> Any:
    """``StepRoad``, ``BumpRoad`` and ``SineRoad`` of earlier versions: the road kinds
    `qc_control.road.Step`, `~qc_control.road.Bump` and `~qc_control.road.Sine`,
    with a `DeprecationWarning` naming them."""
    if name not in _ROAD_ALIASES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    new = _ROAD_ALIASES[name]
    warnings.warn(
        f"{name} is deprecated and will be removed in the next minor release: "
        f"use qc_control.road.{new}",
        DeprecationWarning,
        stacklevel=outside_level(),
    )
    return getattr(roads, new)


#: The scenario kinds (``kind`` in ``[scenario]``, ``--scenario``): each fills the values
#: a scenario does not give (`qc_control.studies.scenarios`).
KINDS = ("pothole", "stiff")


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
            raise ScenarioError(str(exc), None, _parameter_named(exc)) from None
    raise ScenarioError(
        f"vehicle must be a {cls.__name__} or a mapping of its parameters (model {model!r}), "
        f"got {type(values).__name__}",
        "scenario",
        "vehicle",
    )


def _parameter_named(exc: ValueError) -> str | None:
    """The parameter a refusal names: its `ParameterError`'s ``.name``."""
    return exc.name if isinstance(exc, ParameterError) else None


#: The default step is lowered below a method's stability limit by at most
#: this factor (10 ms to 1 ms); a limit further down is warned about instead.
_STABLE_DEFAULT_SPAN = 10.0


def _coarse_remedy(road: Road, limit: float) -> str:
    """What to change when the road is too fine for the grid: h, or the road
    alone when its ``limit`` underflowed to 0 s (a 1e308 Hz sine), which no h meets."""
    road_change = road.finer or "a coarser road"
    return f"give a smaller h, or {road_change}" if limit > 0 else f"give {road_change}"


def _checked(check: Callable, key: str, value, *args, **kwargs) -> Any:
    """``check(key, value, ...)`` (a `qc_control.numerics.checks` checker), its
    refusal a `ScenarioError` of the ``[scenario]`` key it names."""
    try:
        return check(key, value, *args, **kwargs)
    except ParameterError as exc:
        raise ScenarioError(str(exc), "scenario", exc.name) from None


def _all_finite(values) -> bool:
    """Whether every entry is a finite real number (`qc_control.numerics.checks.finite`)."""
    try:
        for value in values:
            checks.finite("x0", value)
    except ParameterError:
        return False
    return True


def _sequence(value) -> list | None:
    """A list from a list, a tuple, an array or a comma-separated string; else None."""
    if isinstance(value, str):
        return [v.strip() for v in value.split(",") if v.strip()]
    if isinstance(value, (list, tuple, np.ndarray)):
        return list(value)
    return None


def _road(road: Any, default: Mapping[str, Any] | None) -> Road:
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


def _kind_road(kind: Any, default: Mapping[str, Any] | None) -> Mapping[str, Any] | None:
    """The road a road table fills what it omits from: a scenario kind's run's
    (`KINDS`: ``--scenario pothole --speed 10`` is the pothole at 10 m/s), else
    the model's ``default``."""
    if kind == "pothole":
        return POTHOLE.road()
    if kind == "stiff":
        return STIFF_CAR.road()
    return default


def _warn_road_form(given: Any, road: Road) -> None:
    """A `DeprecationWarning` for a road given by its kind's name or as a table
    (``road='bump'``, ``road={'kind': 'bump', ...}``): the `Road` it makes is the
    form to give. A TOML file's ``[scenario.road]`` table is its format, read
    by `Scenario.from_mapping` into a `Road` without a warning."""
    if isinstance(given, str) or (isinstance(given, Mapping) and given):
        warnings.warn(
            f"Scenario(road={given!r}) is deprecated and will be removed in the next minor "
            f"release: give a qc_control.road.Road, road=qc_control.road.{road!r}",
            DeprecationWarning,
            stacklevel=outside_level(),
        )


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
    road : qc_control.road.Road, default `NoRoad` (the model's own road, if it has one)
        The road input, with all its parameters: a `qc_control.road.Step`,
        `~qc_control.road.Bump`, `~qc_control.road.Sine`,
        `~qc_control.road.ISO8608Road` or `~qc_control.road.Profile`. A kind's
        name (``'bump'``) or a table ``{'kind': 'bump', ...}`` (read by
        `road_from_mapping`, the model's own road filling what it omits) is
        deprecated: it warns, naming the `Road` to give.
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
    comfort : bool, default False
        Assess the exact reference's ride to ISO 2631-1:1997 into the
        comparison's ``comfort`` (`compare_methods`' ``comfort``); it needs
        a road.
    seat_height : float, optional
        With ``comfort``: the seat's height above a half or full car's
        pitch and roll axes [m], which gives the seat's fore-aft and
        lateral motion (default: those axes are not assessed).
    exposure : float, optional
        With ``comfort``: the daily exposure [h] of Annex B's health
        guidance, from 10 min to 24 h (default: no health zone).

    Examples
    --------
    >>> from qc_control.road import Bump
    >>> sc = Scenario(road=Bump(height=0.1, speed=15.0))
    >>> sc.h, sc.x0, sc.steps
    (0.01, (0.0, 0.0, 0.0, 0.0), 1000)
    >>> sc.road_input()[1]
    'a 10 cm high, 1 m long 1 − cos bump met at t = 0.5 s at 15 m/s'
    >>> Scenario.from_toml_string(sc.to_toml()) == sc
    True
    """

    vehicle: Any = None
    road: Road = None  # type: ignore[assignment]  # resolved: NoRoad, or the nonlinear default
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
    comfort: bool = False
    seat_height: float | None = None
    exposure: float | None = None

    def __post_init__(self):
        put = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        given_end = self.t_end is not None  # a grid error is then t_end's, else h's
        given_road = self.road  # a kind (`KINDS`) may fill it
        self._kind()
        put("model", _model_name(self.model, self.vehicle))
        put("vehicle", _vehicle(self.vehicle, self.model))
        defaults = self.entry.defaults
        road = _road(self.road, defaults.road)
        _warn_road_form(given_road, road)
        put("road", road)
        put("methods", self._methods(self.methods))
        put("t_end", defaults.t_end if self.t_end is None else self.t_end)
        put("t_end", _checked(checks.positive, "t_end", self.t_end, "s"))
        limit = road.largest_step()
        chosen = self.h is None
        if chosen:
            put("h", self._default_step(defaults.h, limit))
        else:
            put("h", _checked(checks.positive, "h", self.h, "s"))
        put("max_steps", _checked(checks.integer, "max_steps", self.max_steps, minimum=2))
        self._check_grid(chosen, given_end)
        t0 = getattr(road, "t0", None)
        if t0 is not None and t0 > self.t_end:
            # the run would end before the car meets the road: every figure flat, every
            # error 0, and a report that says nothing happened
            raise ScenarioError(
                f"t0 = {t0:g} s is after the run's end t_end = {self.t_end:g} s: the car "
                "would never meet the road; use an earlier t0 or a longer t_end",
                ROAD_SECTION,
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
        self._comfort()

    def _comfort(self) -> None:
        """Check the ride assessment's choice: a road under the car, a finite seat
        height, an exposure within Annex B's Figure B.1 (10 min to 24 h)."""
        put = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        if not isinstance(self.comfort, bool):
            raise ScenarioError(
                f"comfort must be true or false, got {self.comfort!r}", "scenario", "comfort"
            )
        for key in ("seat_height", "exposure"):
            if getattr(self, key) is not None and not self.comfort:
                raise ScenarioError(
                    f"{key} applies to the ride assessment only: set comfort = true (--comfort)",
                    "scenario",
                    key,
                )
        if self.comfort and isinstance(self.road, NoRoad):
            raise ScenarioError(
                "comfort needs a road: ISO 2631-1 assesses a ride, and this run has none "
                "(give a road, e.g. --road iso8608, or --scenario pothole)",
                "scenario",
                "comfort",
            )
        if self.comfort:
            self._comfort_grid()
        if self.seat_height is not None:
            put("seat_height", _checked(checks.finite, "seat_height", self.seat_height, "m"))
        if self.exposure is not None:
            low, high = EXPOSURE_HOURS
            put(
                "exposure",
                _checked(
                    checks.number,
                    "exposure",
                    self.exposure,
                    "h",
                    low=low,
                    high=high,
                    # the bound 0.166667 h alone does not read as Figure B.1's 10 min
                    description="daily hours; Annex B's Figure B.1 covers 10 min to 24 h",
                ),
            )

    def _comfort_grid(self) -> None:
        """Refuse, before the run, a grid the assessment cannot weigh: shorter than
        the running RMS's window (§6.3.1; the nonlinear car's 0.8 s bump run) or
        coarser than Wk's band, the vertical every car has, reaching 12.5 Hz."""
        window = RUNNING_RMS_WINDOW
        if self.t_end < window * (1 - 1e-9):
            raise ScenarioError(
                f"t_end = {self.t_end:g} s is shorter than the {window:g} s window of ISO "
                "2631-1's running RMS (§6.3.1), which comfort needs: give t_end >= "
                f"{window:g} s (--t-end)",
                "scenario",
                "t_end",
            )
        top = band_top("Wk")
        if 2 * top * self.h > 1 + 1e-12:  # Nyquist 1/(2h) below the band's top
            why = f"ISO 2631-1's Wk reaches {top:g} Hz, so h must be <= {1 / (2 * top):g} s"
            raise ScenarioError(
                f"h = {self.h:g} s is too coarse for comfort: {why}", "scenario", "h"
            )

    def comfort_request(self) -> dict[str, float] | bool:
        """`compare_methods`' ``comfort`` for this scenario: False, or the
        ride assessment's ``seat`` [m] and ``duration`` [s] that are given."""
        if not self.comfort:
            return False
        request = {"seat": self.seat_height}
        if self.exposure is not None:
            request["duration"] = self.exposure * 3600.0
        return {k: v for k, v in request.items() if v is not None}

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
        given.update({k: getattr(self, k) for k in OPTION_KEYS if getattr(self, k) is not None})
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
            if option.name in OPTION_KEYS:
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
        if name in OPTION_KEYS:
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
                ROAD_SECTION,
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
        if values is None or len(values) != len(names) or not _all_finite(values):
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
            comfort=self.comfort_request(),
            **self.option_arguments("compare"),
        )
        if self.kind == "stiff" and cmp.ride is not None:  # on the road: a ride answer
            cmp = dataclasses.replace(cmp, ride_cost=stiff_car_ride_cost(cmp, progress=progress))
        return dataclasses.replace(cmp, scenario=self)  # a new comparison: it may be frozen

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
        layout = merged_layout(values, overrides, source)
        run, road = layout["run"], layout["road"]
        try:
            fixed = {k: v for k, v in run.items() if k in RUN_KEYS}
            extra = {k: v for k, v in run.items() if k not in RUN_KEYS}
            if road:  # the file's table, as the Road it describes over the model's default
                model = get_model(_model_name(fixed.get("model"), layout["vehicle"]))
                road = _road(road, _kind_road(fixed.get("kind"), model.defaults.road))
            return cls(
                vehicle=cast(Any, layout["vehicle"]),
                road=cast(Any, road or None),
                model_options=extra or None,
                **fixed,
            )
        except ScenarioError as exc:
            raise error_in_layout(exc, layout, source) from None

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
        data = parse_toml(text, f"config file {source!r}" if source else "the scenario")
        return cls.from_mapping(data, overrides=overrides, source=source)

    def to_toml(self) -> str:
        """The scenario as TOML, in the layout `from_toml` reads
        (`qc_control.studies.scenario_toml.scenario_text`).

        Floats are written with ``repr``, so they read back bit for bit:
        ``Scenario.from_toml_string(s.to_toml()) == s``. Both ``zeta`` and
        ``cs`` are written (they agree), so the damping is exact.
        """
        return scenario_text(self)

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
            options = command_options(self) + self._comfort_options()
        if out is not None:
            options.append(("--out", str(out)))
        return command_line(["report"], options)

    def _comfort_options(self) -> list[tuple[str, str | None]]:
        """The command line's ``--comfort``, ``--seat-height`` and ``--exposure``."""
        if not self.comfort:
            return []
        options: list[tuple[str, str | None]] = [("--comfort", None)]
        if self.seat_height is not None:
            options.append(("--seat-height", repr(self.seat_height)))
        if self.exposure is not None:
            options.append(("--exposure", repr(self.exposure)))
        return options


def _named_tableaus() -> dict:
    """Every tableau known by name: `TABLEAUS` where the catalogue has it, else `METHODS`."""
    return getattr(catalogue, "TABLEAUS", METHODS)
