"""The ``qc-control`` command: argument parsing only; the library does the work.

Every bad input ends in one line on stderr and exit status 2, never a
traceback.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import fields

from .model import QuarterCarParams, read_config

__all__ = ["main"]

_PROG = "qc-control"


class UsageError(Exception):
    """Bad command-line input: printed as one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage block
        raise UsageError(message)


def _add_params(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("vehicle (SI units; defaults: the seed's Table 1)")
    for f in fields(QuarterCarParams):
        group.add_argument(
            f"--{f.name}", type=float, metavar="X", help=f"{f.name}, overrides the config file"
        )
    group.add_argument(
        "--config",
        metavar="FILE.toml",
        help="TOML file with top-level ms, mu, ks, ku, zeta or cs"
        " (and a [scenario] table for 'report')",
    )


def _params(args) -> tuple[QuarterCarParams, dict]:
    """The vehicle from ``--config`` and the options; options win."""
    values, scenario = read_config(args.config) if args.config else ({}, {})
    given = {
        f.name: getattr(args, f.name)
        for f in fields(QuarterCarParams)
        if getattr(args, f.name) is not None
    }
    if {"cs", "zeta"} & set(given):  # damping on the command line replaces the file's
        values.pop("cs", None)
        values.pop("zeta", None)
    return QuarterCarParams(**{**values, **given}), scenario


def _cmd_modes(args) -> int:
    from .modal import modal_analysis

    params, _ = _params(args)
    print(modal_analysis(params))
    return 0


_SCENARIO_KEYS = {"h", "t_end", "x0", "methods", "road", "road_class", "speed", "seed"}
_ROADS = ("step", "bump", "sine", "iso8608")
#: Default steps tried, largest first, when an ISO 8608 road needs a finer one.
_NICE_STEPS = (0.01, 0.005, 0.002, 0.001, 5e-4, 2e-4, 1e-4)


def _floats(text: str, name: str, count: int) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in str(text).split(","))
    except ValueError:
        raise UsageError(f"{name} must be {count} comma-separated numbers, got {text!r}") from None
    if len(values) != count:
        raise UsageError(
            f"{name} must be {count} comma-separated numbers (vs,vu,xs,xu), "
            f"got {len(values)} in {text!r}"
        )
    return values


def _scenario(args, table: dict) -> dict:
    """h, t_end, x0, methods from the options, else the config's [scenario], else defaults."""
    from .compare import DEFAULT_H, DEFAULT_METHODS, DEFAULT_T_END, DEFAULT_X0
    from .methods import get_method

    unknown = sorted(set(table) - _SCENARIO_KEYS)
    if unknown:
        raise UsageError(
            f"unknown [scenario] key {unknown[0]!r}; expected one of {sorted(_SCENARIO_KEYS)}"
        )
    pick = lambda name, default: (
        getattr(args, name)
        if getattr(args, name) is not None  # noqa
        else table.get(name, default)
    )
    road = pick("road", None)
    if road is not None and road not in _ROADS:
        raise UsageError(f"--road must be one of {', '.join(_ROADS)}, got {road!r}")
    road_class, speed, seed = pick("road_class", "C"), pick("speed", 20.0), pick("seed", 0)
    if road != "iso8608" and (args.road_class is not None or args.seed is not None):
        raise UsageError("--road-class and --seed apply to --road iso8608 only")
    if (
        isinstance(speed, bool)
        or not isinstance(speed, (int, float))
        or not math.isfinite(speed)
        or speed <= 0
    ):
        raise UsageError(f"--speed must be a finite number > 0 m/s, got {speed!r}")
    h = pick("h", None)
    if h is None:
        h = DEFAULT_H
        if road == "iso8608":
            from .road import largest_step

            limit = largest_step(speed)
            h = next((c for c in _NICE_STEPS if c <= limit), _NICE_STEPS[-1])
    t_end = pick("t_end", DEFAULT_T_END)
    for name, value in (("h", h), ("t-end", t_end)):
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
            or value <= 0
        ):
            raise UsageError(f"--{name} must be a finite number > 0 s, got {value!r}")
    steps = round(t_end / h)
    if steps < 2 or abs(steps * h - t_end) > 1e-9 * t_end:
        raise UsageError(f"--t-end {t_end!r} s must be a whole number (>= 2) of steps --h {h!r} s")
    x0 = pick("x0", DEFAULT_X0 if road is None else (0.0, 0.0, 0.0, 0.0))
    x0 = _floats(x0 if isinstance(x0, str) else ",".join(map(str, x0)), "--x0", 4)
    if not all(math.isfinite(v) for v in x0):
        raise UsageError(f"--x0 must be finite, got {x0!r}")
    methods = pick("methods", DEFAULT_METHODS)
    if isinstance(methods, str):
        methods = [m.strip() for m in methods.split(",") if m.strip()]
    tabs = [get_method(m) for m in methods]
    if not tabs:
        raise UsageError("--methods must name at least one method")
    return {
        "h": float(h),
        "t_end": float(t_end),
        "steps": int(steps),
        "x0": x0,
        "methods": tuple(t.name for t in tabs),
        "road": road,
        "road_class": road_class,
        "speed": float(speed),
        "seed": seed,
    }


def _road_input(sc: dict, T):
    """(zr samples, description) for the scenario's road, or (None, '')."""
    from . import road

    kind = sc["road"]
    if kind is None:
        return None, ""
    if kind == "step":
        return road.step(T), "a 5 cm road step at t = 0.5 s"
    if kind == "bump":
        return (
            road.bump(T, speed=sc["speed"]),
            f"a 5 cm, 1 m long 1 − cos bump at t = 0.5 s, at {sc['speed']:g} m/s",
        )
    if kind == "sine":
        return road.sine(T), "a sinusoidal road, 1 cm amplitude at 1 Hz"
    return (
        road.iso8608(T, sc["road_class"], sc["speed"], sc["seed"]),
        f"an ISO 8608 class {str(sc['road_class']).upper()} road at {sc['speed']:g} m/s "
        f"(seed {sc['seed']})",
    )


def _cmd_report(args) -> int:
    import shlex

    import numpy as np
    import pandas as pd

    from .compare import compare_methods
    from .report import MARKER, ReportError, write_report

    params, table = _params(args)
    sc = _scenario(args, table)
    out = args.out
    # fail before the work, not after it
    from pathlib import Path

    target = Path(out)
    if target.exists() and (
        not target.is_dir() or (any(target.iterdir()) and not (target / MARKER).exists())
    ):
        raise ReportError(
            f"refusing to overwrite {out!r}: it is not a qc-control report "
            f"(no {MARKER} file); choose another --out"
        )
    T = np.linspace(0.0, sc["t_end"], sc["steps"] + 1)
    U, description = _road_input(sc, T)  # validated before any output

    def progress(message):
        print(f"  {message}", file=sys.stderr, flush=True)

    print(
        f"qc-control report: comparing {', '.join(sc['methods'])} at h = {sc['h']:g} s "
        f"over 0-{sc['t_end']:g} s" + (f" on {description}" if description else ""),
        file=sys.stderr,
        flush=True,
    )
    cmp = compare_methods(
        params,
        T,
        sc["x0"],
        U=U,
        methods=sc["methods"],
        progress=progress,
        input_description=description,
    )
    command = "qc-control " + shlex.join(args.argv)
    path = write_report(cmp, out, command=command)
    with pd.option_context(
        "display.width", 160, "display.max_columns", 20, "display.float_format", "{:.4g}".format
    ):
        print(cmp.summary())
    print(
        f"\nwrote {path / 'report.md'}, {path / 'report.html'} and the CSV tables and "
        f"figures in {path}"
    )
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog=_PROG, description="Quarter-car suspension tools on python-control.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    modes = sub.add_parser("modes", help="print the modal table (frequencies, damping, shapes)")
    _add_params(modes)
    modes.set_defaults(run=_cmd_modes)

    report = sub.add_parser(
        "report", help="compare the methods against the exact response and write the report"
    )
    _add_params(report)
    sc = report.add_argument_group("scenario (defaults: the seed's, body released from 5 cm)")
    sc.add_argument("--h", type=float, metavar="S", help="step size [s] (default 0.01)")
    sc.add_argument("--t-end", type=float, metavar="S", help="end time [s] (default 10)")
    sc.add_argument(
        "--x0", metavar="VS,VU,XS,XU", help="initial state [m/s, m/s, m, m] (default 0,0,0.05,0)"
    )
    sc.add_argument(
        "--methods", metavar="A,B,...", help="methods to compare (default euler,midpoint,heun,rk4)"
    )
    rd = report.add_argument_group("road input (default: none, the free response)")
    rd.add_argument(
        "--road",
        metavar="KIND",
        help="step, bump, sine or iso8608; the car then starts at rest unless --x0 is given",
    )
    rd.add_argument("--road-class", metavar="A-H", help="ISO 8608 class (default C)")
    rd.add_argument(
        "--speed",
        type=float,
        metavar="M/S",
        help="vehicle speed for bump and iso8608 [m/s] (default 20)",
    )
    rd.add_argument("--seed", type=int, metavar="N", help="ISO 8608 road seed (default 0)")
    report.add_argument(
        "--out",
        default="report",
        metavar="DIR",
        help="report directory (default report/); replaced only if it holds an earlier report",
    )
    report.set_defaults(run=_cmd_report)
    return parser


def main(argv=None) -> int:
    """Entry point of ``qc-control``; returns the exit status."""
    try:
        argv = sys.argv[1:] if argv is None else list(argv)
        args = build_parser().parse_args(argv)
        args.argv = argv
        return args.run(args)
    except (UsageError, ValueError, TypeError) as exc:
        print(f"{_PROG}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{_PROG}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
