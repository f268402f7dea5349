"""The top level of ``qc-control``: its name, its version and its commands, without the library.

``qc-control --version``, ``qc-control --help`` and a missing or unknown
command need none of python-control, scipy, matplotlib or pandas, whose
import is most of a command's start (about 2 s of CPU). The entry point,
`qc_control.cli.console`, asks `answer` first and loads the library only for
a command to run; `qc_control.cli.parser` builds the whole parser on the same
top level (`top_level`), so both read ``argv``'s first words alike and say
the same. This module imports only the standard library.
"""

from __future__ import annotations

import argparse
import functools
import re
import sys
from importlib.metadata import version
from typing import Any

__all__ = [
    "PROG",
    "COMMANDS",
    "UsageError",
    "CommandParser",
    "version_line",
    "top_level",
    "error_line",
    "answer",
]

#: The program's name, as the user types it.
PROG = "qc-control"

#: The commands by name, in ``--help``'s order, each with its line of ``--help``.
COMMANDS = {
    "modes": "print the modal table (frequencies, damping, shapes)",
    "report": "compare the methods against the exact response and write the report",
    "control-report": "compare passive, semi-active and active suspensions (skyhook ... H∞) "
    "and write the report",
    "identify": "fit the quarter car to measured records and write the report",
    "iri": "print a road profile's International Roughness Index",
    "explore": "open the interactive explorer in a browser (needs qc-control[explore])",
}


class UsageError(Exception):
    """Bad command-line input: printed as one line, exit status 2."""


class CommandParser(argparse.ArgumentParser):
    """An argument parser whose complaint is a `UsageError` (one line), not
    argparse's usage block and exit.

    A value such as ``-0.05,1e5`` (``--bump-stop``'s gap and stiffness) or
    ``-1e-3`` is a value, not an option: argparse takes only ``-5`` and ``-.5``
    for numbers, and read ``--bump-stop -0.05,1e5`` as a missing argument.
    """

    #: A negative number, or a comma-separated list starting with one.
    _NEGATIVE = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(,[-+]?[\d.eE+-]+)*$")

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = self._NEGATIVE

    def error(self, message):
        raise UsageError(message)


@functools.cache  # each read scans the installed distributions: ~2 ms, once a process
def version_line() -> str:
    """``'qc-control 0.1.0 (python-control 0.10.2)'``: both read from the installed
    distributions' metadata, so python-control is not imported for it."""
    return f"{PROG} {version('qc-control')} (python-control {version('control')})"


def top_level() -> tuple[CommandParser, Any]:
    """The parser of ``qc-control``'s first words, and its sub-parsers action.

    ``--version`` and the command's name; each command's parser is added to
    the action (``add_parser(name, help=COMMANDS[name], ...)``) by its caller.
    """
    parser = CommandParser(
        prog=PROG,
        description="Quarter-car suspension tools on python-control.",
        allow_abbrev=False,  # a reproduce command must mean the same in every version
    )
    parser.add_argument("--version", action="version", version=version_line())
    sub = parser.add_subparsers(dest="command", required=True, parser_class=CommandParser)
    return parser, sub


def error_line(exc: BaseException) -> str:
    """The one line that reports bad input: ``'qc-control: error: ...'``, its
    message's line breaks and runs of blanks made single spaces."""
    return f"{PROG}: error: {' '.join(str(exc).split())}"


def answer(argv: list[str]) -> int | None:
    """The exit status when the top level alone answers ``argv``, else None.

    ``--version`` and ``--help`` before any command print their text (status
    0); no command or an unknown one is one line on stderr (status 2), in
    the words of the whole parser. A known command's words, its ``--help``
    among them, are left to `qc_control.cli.parser`: None.
    """
    parser, sub = top_level()
    for name, help in COMMANDS.items():
        # each command's own options are unknown here (no --help of its own):
        # they are left over, for the whole parser
        sub.add_parser(name, help=help, add_help=False)
    try:
        parser.parse_known_args(argv)
    except SystemExit as exc:  # --version, --help
        return exc.code if isinstance(exc.code, int) else 0
    except UsageError as exc:
        print(error_line(exc), file=sys.stderr)
        return 2
    return None
