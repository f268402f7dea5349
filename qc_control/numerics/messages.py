"""Values as error messages show them: short, and only when they say something."""

from __future__ import annotations

import reprlib

import numpy as np

__all__ = ["show", "install_hint"]

_REPR = reprlib.Repr()
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = 6
_REPR.maxstring = _REPR.maxother = 40

_PLAIN = (str, bytes, bool, int, float, complex, list, tuple, dict, np.ndarray, np.generic)


def show(value) -> str:
    """A user's value for an error message.

    The repr, shortened, of a plain value (a number, string, list, tuple,
    dict or array); for any other object, only its type, since the repr of
    a system or a function says little and may run over many lines.

    Examples
    --------
    >>> show(["a", "b"]), show("abc"), show(list(range(100)))
    ("['a', 'b']", "'abc'", '[0, 1, 2, 3, 4, 5, ...]')
    >>> show(object())
    'an object'
    """
    if value is None or isinstance(value, _PLAIN):
        return _REPR.repr(value)
    name = type(value).__name__
    return f"{'an' if name[:1].lower() in 'aeiou' else 'a'} {name}"


def install_hint(extra: str) -> str:
    """How to install an optional extra, in quotes every shell takes.

    Single quotes fail in Windows' cmd.exe (``'qc-control[robust]'`` is
    passed on with its quotes); double quotes work there, in PowerShell and
    in POSIX shells. From a clone, the README's editable install.

    Examples
    --------
    >>> install_hint("robust")
    'pip install "qc-control[robust]" (from a clone: pip install -e ".[robust]")'
    """
    return f'pip install "qc-control[{extra}]" (from a clone: pip install -e ".[{extra}]")'
