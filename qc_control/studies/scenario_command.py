"""A scenario as the ``qc-control report`` command that redoes it, quoted for the shell.

`qc_control.Scenario.command` writes its run as a command line, and a
report quotes it; the command line (`qc_control.cli.parser`) spells its
options with the same `option_name` and `option_flag`, so the two agree.
Every value is written with ``repr``, so the command gives the same numbers.
"""

from __future__ import annotations

import re
import shlex
import sys
from dataclasses import fields

from ..ride.road import NoRoad
from .scenario_toml import DEFAULT_MODEL, MAX_STEPS

__all__ = ["command_line", "command_options", "option_flag", "option_name", "road_option"]


def road_option(f) -> str:
    """The ``qc-control report`` option of a road parameter (a field of a `Road`)."""
    return f.metadata["option"] or "--road-" + f.name.replace("_", "-")


def option_name(key: str) -> str:
    """A key's option: ``--ks-front`` for ``ks_front`` (one spelling, as ``--t-end``)."""
    return "--" + key.replace("_", "-")


def option_flag(key: str, default: bool) -> str:
    """The flag that turns a boolean option away from its default: ``--no-events``."""
    return option_name(f"no_{key}" if default else key)


def _text(value) -> str:
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


def command_options(scenario) -> list[tuple[str, str | None]]:
    """``(option, value)`` pairs of ``qc-control report`` that give every value
    of ``scenario`` (a `qc_control.Scenario`; value None: a flag)."""
    options: list[tuple[str, str | None]] = []
    if scenario.model != DEFAULT_MODEL:
        options.append(("--model", scenario.model))
    options += [(option_name(k), repr(v)) for k, v in scenario.vehicle.to_dict().items()]
    options += [("--t-end", repr(scenario.t_end)), ("--h", repr(scenario.h))]
    options += [
        ("--x0", ",".join(map(repr, scenario.x0))),
        ("--methods", ",".join(scenario.methods)),
    ]
    if scenario.max_steps != MAX_STEPS:
        options.append(("--max-steps", str(scenario.max_steps)))
    if scenario.solvers:
        options.append(("--solvers", ",".join(scenario.solvers)))
    if scenario.kind is not None:
        options.append(("--scenario", scenario.kind))
    for option in scenario.entry.options:
        value = scenario.option(option.name)
        if isinstance(value, bool):
            if value != option.default:
                options.append((option_flag(option.name, option.default), None))
        elif value is not None:
            options.append((option_name(option.name), _text(value)))
    if scenario.entry.defaults.road and isinstance(scenario.road, NoRoad):
        options.append(("--road", NoRoad.kind))
    if not isinstance(scenario.road, NoRoad):
        options.append(("--road", scenario.road.kind))
        options += [
            (road_option(f), _text(getattr(scenario.road, f.name))) for f in fields(scenario.road)
        ]
    return options
