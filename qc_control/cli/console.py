"""The ``qc-control`` entry point: one line for Ctrl-C, a bug report for a bug.

Importing the library (python-control, scipy, matplotlib) takes seconds, so
the command's module is imported inside the handlers: a Ctrl-C while it
loads gets the same one line as a Ctrl-C during the run. Before it, the top
level (`qc_control.cli.commands`, the standard library only) answers
``--version``, ``--help`` and a missing or unknown command without loading
the library. This module imports only the standard library at its top.
"""

from __future__ import annotations

import sys
import traceback

__all__ = ["main"]

#: qc_control.cli.commands.PROG, spelled here too: the Ctrl-C line must print even when a
#: Ctrl-C stops that import
PROG = "qc-control"


def main(argv=None) -> int:
    """Entry point of ``qc-control``; returns the exit status (see `qc_control.cli.parser`)."""
    words = sys.argv[1:] if argv is None else list(argv)
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
