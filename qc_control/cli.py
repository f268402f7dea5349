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
        group.add_argument(f"--{f.name}", type=float, metavar="X",
                           help=f"{f.name}, overrides the config file")
    group.add_argument("--config", metavar="FILE.toml",
                       help="TOML file with top-level ms, mu, ks, ku, zeta or cs"
                            " (and a [scenario] table for 'report')")


def _params(args) -> tuple[QuarterCarParams, dict]:
    """The vehicle from ``--config`` and the options; options win."""
    values, scenario = read_config(args.config) if args.config else ({}, {})
    given = {f.name: getattr(args, f.name) for f in fields(QuarterCarParams)
             if getattr(args, f.name) is not None}
    if {"cs", "zeta"} & set(given):  # damping on the command line replaces the file's
        values.pop("cs", None)
        values.pop("zeta", None)
    return QuarterCarParams(**{**values, **given}), scenario


def _cmd_modes(args) -> int:
    from .modal import modal_analysis

    params, _ = _params(args)
    print(modal_analysis(params))
    return 0


_SCENARIO_KEYS = {"h", "t_end", "x0", "methods"}


def _floats(text: str, name: str, count: int) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in str(text).split(","))
    except ValueError:
        raise UsageError(f"{name} must be {count} comma-separated numbers, got {text!r}") from None
    if len(values) != count:
        raise UsageError(f"{name} must be {count} comma-separated numbers (vs,vu,xs,xu), "
                         f"got {len(values)} in {text!r}")
    return values


def _scenario(args, table: dict) -> dict:
    """h, t_end, x0, methods from the options, else the config's [scenario], else defaults."""
    from .compare import DEFAULT_H, DEFAULT_METHODS, DEFAULT_T_END, DEFAULT_X0
    from .methods import get_method

    unknown = sorted(set(table) - _SCENARIO_KEYS)
    if unknown:
        raise UsageError(f"unknown [scenario] key {unknown[0]!r}; expected one of "
                         f"{sorted(_SCENARIO_KEYS)}")
    h = args.h if args.h is not None else table.get("h", DEFAULT_H)
    t_end = args.t_end if args.t_end is not None else table.get("t_end", DEFAULT_T_END)
    for name, value in (("h", h), ("t-end", t_end)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value) or value <= 0:
            raise UsageError(f"--{name} must be a finite number > 0 s, got {value!r}")
    steps = round(t_end / h)
    if steps < 2 or abs(steps * h - t_end) > 1e-9 * t_end:
        raise UsageError(f"--t-end {t_end!r} s must be a whole number (>= 2) of steps "
                         f"--h {h!r} s")
    x0 = args.x0 if args.x0 is not None else table.get("x0", DEFAULT_X0)
    x0 = _floats(x0 if isinstance(x0, str) else ",".join(map(str, x0)), "--x0", 4)
    if not all(math.isfinite(v) for v in x0):
        raise UsageError(f"--x0 must be finite, got {x0!r}")
    methods = args.methods if args.methods is not None else table.get("methods", DEFAULT_METHODS)
    if isinstance(methods, str):
        methods = [m.strip() for m in methods.split(",") if m.strip()]
    tabs = [get_method(m) for m in methods]
    if not tabs:
        raise UsageError("--methods must name at least one method")
    return {"h": float(h), "t_end": float(t_end), "steps": int(steps), "x0": x0,
            "methods": tuple(t.name for t in tabs)}


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
    if target.exists() and (not target.is_dir() or (any(target.iterdir())
                                                    and not (target / MARKER).exists())):
        raise ReportError(f"refusing to overwrite {out!r}: it is not a qc-control report "
                          f"(no {MARKER} file); choose another --out")
    T = np.linspace(0.0, sc["t_end"], sc["steps"] + 1)

    def progress(message):
        print(f"  {message}", file=sys.stderr, flush=True)

    print(f"qc-control report: comparing {', '.join(sc['methods'])} at h = {sc['h']:g} s "
          f"over 0-{sc['t_end']:g} s", file=sys.stderr, flush=True)
    cmp = compare_methods(params, T, sc["x0"], methods=sc["methods"], progress=progress)
    command = "qc-control " + shlex.join(args.argv)
    path = write_report(cmp, out, command=command)
    with pd.option_context("display.width", 160, "display.max_columns", 20,
                           "display.float_format", "{:.4g}".format):
        print(cmp.summary())
    print(f"\nwrote {path / 'report.md'}, {path / 'report.html'} and the CSV tables and "
          f"figures in {path}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog=_PROG, description="Quarter-car suspension tools on python-control.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    modes = sub.add_parser("modes", help="print the modal table (frequencies, damping, shapes)")
    _add_params(modes)
    modes.set_defaults(run=_cmd_modes)

    report = sub.add_parser("report", help="compare the methods against the exact response "
                                           "and write the report")
    _add_params(report)
    sc = report.add_argument_group("scenario (defaults: the seed's, body released from 5 cm)")
    sc.add_argument("--h", type=float, metavar="S", help="step size [s] (default 0.01)")
    sc.add_argument("--t-end", type=float, metavar="S", help="end time [s] (default 10)")
    sc.add_argument("--x0", metavar="VS,VU,XS,XU", help="initial state [m/s, m/s, m, m] "
                                                       "(default 0,0,0.05,0)")
    sc.add_argument("--methods", metavar="A,B,...",
                    help="methods to compare (default euler,midpoint,heun,rk4)")
    report.add_argument("--out", default="report", metavar="DIR",
                        help="report directory (default report/); replaced only if it "
                             "holds an earlier report")
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
