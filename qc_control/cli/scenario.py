"""Deprecated: `qc_control.Scenario` and its TOML moved to `qc_control.studies.scenario`.

A scenario is a library object, not a part of the command line. This module
answers the old path for one more minor release (the deprecation policy in
CHANGELOG.md), with a `DeprecationWarning` naming the new homes:

- `qc_control.studies.scenario`: `Scenario` and its defaults;
- `qc_control.studies.scenario_toml`: the TOML file (`ScenarioError`,
  `read_config`, `load_config`, `config_text`, `road_from_mapping`, ...);
- `qc_control.studies.scenario_command`: the command that redoes a run
  (`command_line`, `option_name`, `option_flag`, `road_option`).

``StepRoad``, ``BumpRoad`` and ``SineRoad`` are `qc_control.road.Step`,
`~qc_control.road.Bump` and `~qc_control.road.Sine`, with a warning of their own.
"""

from __future__ import annotations

import warnings
from typing import Any

from ..models.registry import MODELS
from ..numerics.steps import whole_step
from ..ride.road import ROADS, ISO8608Road, NoRoad, Road
from ..studies import scenario as _new
from ..studies.compare import DEFAULT_METHODS, MethodComparison, compare_methods
from ..studies.scenario import (
    KINDS,
    MAX_STATE,
    NONLINEAR_H,
    NONLINEAR_ROAD,
    NONLINEAR_T_END,
    ModelKind,
    Scenario,
)
from ..studies.scenario_command import command_line, option_flag, option_name, road_option
from ..studies.scenario_toml import (
    CLI_ROADS,
    DEFAULT_MODEL,
    MAX_CONFIG_BYTES,
    MAX_STEPS,
    RUN_KEYS,
    ScenarioError,
    config_text,
    load_config,
    outside_level,
    read_config,
    road_from_mapping,
    run_keys,
    vehicle_config,
    vehicle_keys,
)

warnings.warn(
    "qc_control.cli.scenario is deprecated and will be removed in the next minor release: "
    "import qc_control.studies.scenario (Scenario), qc_control.studies.scenario_toml (its "
    "TOML) or qc_control.studies.scenario_command (its command)",
    DeprecationWarning,
    stacklevel=2,  # the importer's line: the import system's own frames are not counted
)

#: A road spec of earlier versions: a `qc_control.road.Road`.
RoadSpec = Road

# StepRoad, BumpRoad and SineRoad are answered by __getattr__, with their own warning
__all__ = [
    "Scenario",
    "read_config",
    "load_config",
    "ScenarioError",
    "Road",
    "NoRoad",
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
    "KINDS",
    "MAX_STATE",
    "DEFAULT_METHODS",
    "MethodComparison",
    "compare_methods",
    "outside_level",
    "road_option",
    "vehicle_keys",
]


def __getattr__(name: str) -> Any:
    """The road kinds' earlier names (``BumpRoad``), each warning with its new one."""
    if name in ("StepRoad", "BumpRoad", "SineRoad"):
        return getattr(_new, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
