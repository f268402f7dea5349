"""Where an example script writes, and how it shows a figure, wherever it runs.

The examples run as scripts (``python examples/x.py OUT_DIR``), in the docs'
gallery, and as the gallery's downloadable notebooks. In a Jupyter kernel
``sys.argv`` is the kernel's own (``ipykernel_launcher.py -f kernel.json``),
so an example that read ``sys.argv[1]`` wrote into a folder named ``-f``.
`output_folder` takes the folder from its argument, else from the command
line of a script, else the default; `show_inline` displays a figure in a
notebook and does nothing elsewhere; `save_and_show` does both for a figure
an example writes.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["output_folder", "show_inline", "save_and_show", "in_notebook"]


def in_notebook(argv: list[str] | None = None) -> bool:
    """Whether this runs in a Jupyter kernel (whose argv is the kernel's, not ours)."""
    argv = sys.argv if argv is None else argv
    return bool(argv) and Path(argv[0]).name in ("ipykernel_launcher.py", "ipykernel_launcher")


def output_folder(name: str, out=None, argv: list[str] | None = None) -> Path:
    """The folder an example writes into, created with its parents.

    Parameters
    ----------
    name : str
        The example's name; the default folder is ``./<name>_output``.
    out : str or path-like, optional
        The folder; wins over everything else.
    argv : list of str, optional
        The command line (default `sys.argv`): a script's only argument is
        the folder. In a Jupyter kernel it is ignored.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    TypeError
        If ``name`` is not a non-empty string.
    """
    if not isinstance(name, str) or not name:
        raise TypeError(f"name must be the example's name, a non-empty string; got {name!r}")
    argv = sys.argv if argv is None else list(argv)
    if out is None and not in_notebook(argv):
        parser = argparse.ArgumentParser(prog=Path(argv[0]).name if argv else name)
        parser.add_argument("out", nargs="?", metavar="OUT_DIR", help=f"default ./{name}_output")
        out = parser.parse_args(argv[1:]).out
    folder = Path(out if out is not None else f"{name}_output")
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def show_inline(fig) -> None:
    """Display ``fig`` in a notebook (a `matplotlib.figure.Figure` has no window
    of its own); outside one, the saved file is the figure, and this does nothing."""
    ipython = sys.modules.get("IPython")  # imported by any kernel; never by us
    shell = ipython.get_ipython() if ipython is not None else None
    if shell is None:
        return
    # what IPython.display.display does: format with the kernel's formatters
    # (the inline backend's PNG for a Figure) and publish the result
    data, metadata = shell.display_formatter.format(fig)
    shell.display_pub.publish(data=data, metadata=metadata)


def save_and_show(fig, path, dpi: int = 110) -> Path:
    """Write ``fig`` to ``path`` (the figure an example hands in) and display it
    when this runs in a notebook (`show_inline`). Returns the path."""
    path = Path(path)
    fig.savefig(path, dpi=dpi)
    show_inline(fig)
    return path
