"""A scenario's TOML file: its layout, reading it (and earlier layouts), writing values.

A `qc_control.Scenario` (`qc_control.studies.scenario`) reads and writes
this file; ``qc-control report --config`` reads it and a report records its
run in it (``scenario.toml``). The TOML keys are the file format: the
errors here name the key and the table that holds it (`ScenarioError`).

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

A key left out takes the Scenario's default (`qc_control.studies.scenario`:
the nonlinear car's own road and grid, for one).

The flat keys of earlier versions in ``[scenario]`` (``road = "iso8608"``,
``road_class``, ``speed``, ``seed``, and the nonlinear car's ``bump_height``
and ``bump_length``) are read for one more release, each with a
``DeprecationWarning`` naming its key in ``[scenario.road]``.
"""

from __future__ import annotations

import json
import sys
import warnings
from collections.abc import Mapping
from dataclasses import fields
from pathlib import Path
from types import FrameType
from typing import Any

from ..models.quarter import QuarterCarParams
from ..models.registry import MODELS, parameter_keys
from ..numerics.checks import ParameterError
from ..ride.road import ROADS, NoRoad, Profile, Road

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "ScenarioError",
    "ROAD_SECTION",
    "CLI_ROADS",
    "MAX_STEPS",
    "MAX_CONFIG_BYTES",
    "DEFAULT_MODEL",
    "OPTION_KEYS",
    "RUN_KEYS",
    "road_from_mapping",
    "vehicle_keys",
    "run_keys",
    "toml_value",
    "scenario_text",
    "canonical_layout",
    "merged_layout",
    "error_in_layout",
    "outside_level",
    "vehicle_config",
    "config_text",
    "parse_toml",
    "read_config",
    "load_config",
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


#: The table of a scenario's road in its TOML file.
ROAD_SECTION = "scenario.road"

#: The model of a scenario that names none (not written in its TOML or command).
DEFAULT_MODEL = "quarter"

#: The roads a scenario's TOML and the command line take by ``kind``: every
#: kind whose parameters are numbers (a `Profile`'s arrays are given in Python).
CLI_ROADS: dict[str, type[Road]] = {k: c for k, c in ROADS.items() if c is not Profile}


def road_from_mapping(values: Mapping[str, Any]) -> Road:
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
            ROAD_SECTION,
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
                ROAD_SECTION,
                key,
            )
        raise ScenarioError(f"unknown [scenario.road] key {key!r}; {takes}", None, key)
    try:
        return cls(**values)
    except ParameterError as exc:
        raise ScenarioError(str(exc), ROAD_SECTION, exc.name) from None


def vehicle_keys() -> tuple[str, ...]:
    """Every parameter name of every model in `MODELS`, each once, in order."""
    return tuple(parameter_keys())


#: The Scenario's fields that hold a model's own options (`ModelOption`) by name;
#: the options of other registered models are held in ``model_options``.
OPTION_KEYS = ("tire", "bump_stop", "events")
RUN_KEYS = (
    "t_end", "h", "x0", "methods", "max_steps", "model", *OPTION_KEYS, "solvers", "kind",
    "comfort", "seat_height", "exposure",
)  # fmt: skip


def run_keys() -> tuple[str, ...]:
    """The ``[scenario]`` keys: `RUN_KEYS` and every registered model's options."""
    options = (o.name for e in MODELS.values() for o in e.options)
    return tuple(dict.fromkeys((*RUN_KEYS, *options)))


#: The flat road keys of the ``[scenario]`` table of earlier versions.
_LEGACY_ROAD_KEYS = ("road", "road_class", "speed", "seed")
#: The nonlinear car's bump keys of earlier versions in ``[scenario]``: a bump road's keys.
_LEGACY_BUMP_KEYS = {"bump_height": "height", "bump_length": "length"}


def toml_value(value) -> str:
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
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {value!r} as TOML")  # pragma: no cover - a bug here


def canonical_layout(doc: Mapping[str, Any], source: str | None = None) -> dict[str, Any]:
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
    road, section = table.pop("road", None), ROAD_SECTION
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


def merged_layout(
    values: Mapping[str, Any], overrides: Mapping[str, Any] | None, source: str | None
) -> dict[str, Any]:
    """``overrides`` over ``values`` (each a TOML document's mapping), as
    `canonical_layout` gives them, with ``given``: the keys the overrides gave.

    Damping given in the overrides (``zeta`` or ``cs``) replaces both of
    ``values``'; a road of another ``kind`` replaces ``values``' road, a road
    of the same kind (or none given) updates it. An error in ``values`` names
    ``source``.
    """
    over = canonical_layout(overrides or {})
    try:
        base = canonical_layout(values, source)
    except ScenarioError as exc:
        raise ScenarioError(exc.detail, exc.section, exc.key, source) from None
    vehicle = dict(base["vehicle"])
    if {"zeta", "cs"} & set(over["vehicle"]):
        vehicle.pop("zeta", None)
        vehicle.pop("cs", None)
    vehicle.update(over["vehicle"])
    road = base["road"]
    if "kind" in over["road"] and over["road"]["kind"] != road.get("kind", "none"):
        road = dict(over["road"])
    else:
        road = {**road, **over["road"]}
    return {
        **base,
        "vehicle": vehicle,
        "run": {**base["run"], **over["run"]},
        "road": road,
        "given": {None: over["vehicle"], "scenario": over["run"], ROAD_SECTION: over["road"]},
    }


def error_in_layout(
    exc: ScenarioError, layout: Mapping[str, Any], source: str | None
) -> ScenarioError:
    """``exc`` located in the document (`merged_layout`'s) the bad value came from.

    A value the overrides gave is theirs (no file named); a road key of the file
    is named in its table and spelling (the flat ``[scenario] bump_height`` of an
    earlier layout for ``height``).
    """
    from_overrides = exc.key is not None and exc.key in layout["given"].get(exc.section, {})
    section, key, detail = exc.section, exc.key, exc.detail
    if section == ROAD_SECTION and not from_overrides:
        section = layout["road_section"]
        written = layout["road_keys"].get(key, key)  # as the file spells it
        if key is not None and written != key and detail.startswith(f"{key} "):
            detail = written + detail[len(key) :]
        key = written
    return ScenarioError(detail, section, key, None if from_overrides else source)


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
    data = parse_toml(config_text(path), f"config file {str(path)!r}")
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


def parse_toml(text: str, where: str) -> dict[str, Any]:
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
    data = parse_toml(config_text(path), f"config file {str(path)!r}")
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


def scenario_text(scenario) -> str:
    """A `qc_control.Scenario` as TOML, in the layout `canonical_layout` reads.

    Floats are written with ``repr``, so they read back bit for bit. Both
    ``zeta`` and ``cs`` are written (they agree), so the damping is exact;
    a key at its default (``model``, ``max_steps``) is left out.
    """
    lines = [
        "# A qc-control scenario (qc_control.Scenario): one comparison run.",
        "# Redo it with: qc-control report --config <this file>",
        "# Floats are written exactly (repr). zeta and cs are both given, and agree;",
        "# to change the damping, keep only one of them.",
        "",
        *(f"{k} = {toml_value(v)}" for k, v in scenario.vehicle.to_dict().items()),
        "",
        "[scenario]",
        *([f"model = {toml_value(scenario.model)}"] if scenario.model != DEFAULT_MODEL else []),
        f"t_end = {toml_value(scenario.t_end)}",
        f"h = {toml_value(scenario.h)}",
        f"x0 = {toml_value(scenario.x0)}",
        f"methods = {toml_value(scenario.methods)}",
    ]
    if scenario.max_steps != MAX_STEPS:
        lines.append(f"max_steps = {scenario.max_steps}")
    if scenario.solvers:
        lines.append(f"solvers = {toml_value(scenario.solvers)}")
    if scenario.kind is not None:
        lines.append(f"kind = {toml_value(scenario.kind)}")
    if scenario.comfort:  # the ride assessment; left out when off, as older files have it
        lines.append("comfort = true")
        lines += [
            f"{key} = {toml_value(getattr(scenario, key))}"
            for key in ("seat_height", "exposure")
            if getattr(scenario, key) is not None
        ]
    for option in scenario.entry.options:
        value = scenario.option(option.name)
        if value is not None:
            lines.append(f"{option.name} = {toml_value(value)}")
    if scenario.entry.defaults.road and isinstance(scenario.road, NoRoad):
        # no road is not this model's default: say so
        lines += ["", f"[{ROAD_SECTION}]", f"kind = {toml_value(NoRoad.kind)}"]
    elif not isinstance(scenario.road, NoRoad):
        lines += ["", f"[{ROAD_SECTION}]", f"kind = {toml_value(scenario.road.kind)}"]
        lines += [f"{k} = {toml_value(v)}" for k, v in scenario.road.params().items()]
    return "\n".join(lines) + "\n"
