"""MathJax served from the built site (``sphinx-mathjax-offline``), declared
safe for Sphinx's parallel build.

The package only points ``mathjax_path`` at its copy and copies the files
when the build has finished; it touches no shared state while pages are
read or written, but says nothing of parallel builds, so Sphinx would build
serially. This shim says it, and the site builds on every core (``-j auto``).
"""

from __future__ import annotations

import importlib


def setup(app):
    importlib.import_module("sphinx-mathjax-offline").setup(app)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
