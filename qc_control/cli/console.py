"""The ``qc-control`` entry point: one line for Ctrl-C, a bug report for a bug.

Importing the library (python-control, scipy, matplotlib) takes seconds, so
the command's module is imported inside the handlers: a Ctrl-C while it
loads gets the same one line as a Ctrl-C during the run. Before it, the top
level (`qc_control.cli.commands`, the standard library only) answers
``--version``, ``--help`` and a missing or unknown command without loading
the library. This module imports only the standard library at its top.
"""

from __future__ import annotations

import codecs
import sys
import traceback

__all__ = ["main", "SPELLED"]

#: How a character the terminal cannot show is spelt instead. Windows gives a
#: piped or redirected stdout (``| more``, ``> help.txt``) the ANSI code page,
#: cp1252, which has no ∞, √ or ζ: the help and the tables would end in a
#: UnicodeEncodeError. Characters not listed become '?'.
SPELLED = {
    "∞": "inf", "√": "sqrt", "ζ": "zeta", "ω": "omega", "λ": "lambda", "σ": "sigma",
    "π": "pi", "Δ": "Delta", "Σ": "Sum", "Φ": "Phi", "Γ": "Gamma", "≤": "<=", "≥": ">=",
    "≠": "!=", "≈": "~", "−": "-", "–": "-", "—": "-", "→": "->", "←": "<-", "⇔": "<=>",
    "‖": "||", "·": "*", "×": "x", "²": "^2", "³": "^3", "⁻¹": "^-1", "ᵀ": "^T", "⚠": "!",
    "…": "...", "µ": "u",
}  # fmt: skip
_LONGEST = max(map(len, SPELLED))


def _spell(error: UnicodeError) -> tuple[str | bytes, int]:
    """The codec error handler ``qc-control-spell``: `SPELLED`, else '?'.

    A lone surrogate U+DC80-U+DCFF is a byte the C locale could not decode
    (a non-ASCII path given on the command line): it is written back as that
    byte, as Python's own ``surrogateescape`` does, so the path prints as typed.
    """
    if not isinstance(error, UnicodeEncodeError):
        raise error
    text = error.object
    end = error.start
    while end < error.end and "\udc80" <= text[end] <= "\udcff":
        end += 1
    if end > error.start:
        return bytes(ord(c) - 0xDC00 for c in text[error.start : end]), end
    for size in range(_LONGEST, 0, -1):
        piece = text[error.start : error.start + size]
        if piece in SPELLED:
            return SPELLED[piece], error.start + len(piece)
    return "?", error.start + 1


codecs.register_error("qc-control-spell", _spell)


_FAILING = ("strict", "surrogateescape", "backslashreplace")


def _terminal_safe() -> None:
    """Let stdout and stderr write every character, whatever they encode to."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        # the C locale (LC_ALL=C, PYTHONUTF8=0) gives stdout ASCII with surrogateescape,
        # which fails on a ∞ as strict does; stderr's backslashreplace shows \u221e
        if reconfigure is not None and getattr(stream, "errors", "strict") in _FAILING:
            reconfigure(errors="qc-control-spell")


#: qc_control.cli.commands.PROG, spelled here too: the Ctrl-C line must print even when a
#: Ctrl-C stops that import
PROG = "qc-control"


def main(argv=None) -> int:
    """Entry point of ``qc-control``; returns the exit status (see `qc_control.cli.parser`)."""
    words = sys.argv[1:] if argv is None else list(argv)
    _terminal_safe()
    try:
        # deferred, light (the standard library only): --version, --help and a missing or
        # unknown command are answered before the library loads
        from .commands import answer

        status = answer(words)
        if status is not None:
            return status
        # deferred: the whole library loads here, inside the Ctrl-C handler
        from .parser import run

        return run(words)
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except Exception:
        traceback.print_exc()
        print(
            f"{PROG}: internal error: this is a bug in qc-control, not a problem with your "
            "input; please report it with the traceback above",
            file=sys.stderr,
        )
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
