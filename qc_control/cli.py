"""The ``qc-control`` command: argument parsing only; the library does the work.

Every bad input ends in one line on stderr and exit status 2, never a
traceback.
"""

from __future__ import annotations

import argparse
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


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog=_PROG, description="Quarter-car suspension tools on python-control.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    modes = sub.add_parser("modes", help="print the modal table (frequencies, damping, shapes)")
    _add_params(modes)
    modes.set_defaults(run=_cmd_modes)
    return parser


def main(argv=None) -> int:
    """Entry point of ``qc-control``; returns the exit status."""
    try:
        args = build_parser().parse_args(argv)
        return args.run(args)
    except (UsageError, ValueError, TypeError) as exc:
        print(f"{_PROG}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{_PROG}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
