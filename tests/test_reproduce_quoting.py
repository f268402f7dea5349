"""The report's "Reproduce" line is quoted for the shell of the platform it was
written on: a POSIX shell's single quotes break in Windows' cmd.exe, where
only double quotes group words.

The Windows line is read back by a parser written here from Microsoft's rules
for the C runtime ("Parsing C command-line arguments"): arguments are split at
blanks outside double quotes; 2n backslashes before a quote give n backslashes
and the quote opens or closes a group; 2n + 1 give n backslashes and a
literal quote; backslashes elsewhere are literal.
"""

import shlex
import sys

import pytest

from qc_control.studies.scenario_command import command_line

#: Values a design name, a path or a number can bring into the line.
AWKWARD = [
    "passive (seed),skyhook semi-active",  # the controller comparison's design list
    "H∞ (β = 0.5)",
    "a&b|c<d>e^f",  # cmd.exe's operators
    'say "hi"',
    "C:\\Users\\ana\\My reports\\",  # a trailing backslash before the closing quote
    'back\\\\slash\\"quote',
    "100%",
    "",
    "-0.05,0,0,0",  # a value that looks like an option
]


def msvcrt_split(line: str) -> list[str]:
    """``line`` split into arguments as the Microsoft C runtime splits it."""
    args: list[str] = []
    current: list[str] = []
    in_quotes = started = False
    i = 0
    while i < len(line):
        ch = line[i]
        if ch == "\\":
            j = i
            while j < len(line) and line[j] == "\\":
                j += 1
            run = j - i
            if j < len(line) and line[j] == '"':
                current.append("\\" * (run // 2))
                if run % 2:
                    current.append('"')
                    j += 1
            else:
                current.append("\\" * run)
            started, i = True, j
            continue
        if ch == '"':
            in_quotes, started = not in_quotes, True
        elif ch in " \t" and not in_quotes:
            if started:
                args.append("".join(current))
            current, started = [], False
        else:
            current.append(ch)
            started = True
        i += 1
    if started:
        args.append("".join(current))
    return args


def _options(values):
    return [(f"--opt{i}", v) for i, v in enumerate(values)] + [("--flag", None)]


def _expected(values):
    expected = ["qc-control", "report"]
    for i, value in enumerate(values):
        name = f"--opt{i}"
        expected += [f"{name}={value}"] if value.startswith("-") else [name, value]
    return [*expected, "--flag"]


@pytest.mark.parametrize("value", AWKWARD)
def test_a_windows_line_reads_back_as_the_same_arguments(value):
    line = command_line(["report"], _options([value]), windows=True)
    assert msvcrt_split(line) == _expected([value]), line
    assert "'" not in line.replace(value, "")  # no POSIX quoting around anything


@pytest.mark.parametrize("value", AWKWARD)
def test_a_posix_line_reads_back_as_the_same_arguments(value):
    line = command_line(["report"], _options([value]), windows=False)
    assert shlex.split(line) == _expected([value]), line


def test_cmd_operators_are_inside_double_quotes():
    """cmd.exe acts on ``& | < > ^`` before the program sees them, except
    inside double quotes."""
    line = command_line(["report"], [("--designs", "a&b|c")], windows=True)
    assert line == 'qc-control report --designs "a&b|c"'


def test_plain_values_are_left_bare():
    line = command_line(["report"], [("--h", "0.01"), ("--road", "bump")], windows=True)
    assert line == "qc-control report --h 0.01 --road bump"


def test_the_default_is_the_platform_the_line_is_written_on():
    options = [("--designs", "passive (seed),skyhook")]
    windows = sys.platform == "win32"
    assert command_line(["report"], options) == command_line(["report"], options, windows=windows)
