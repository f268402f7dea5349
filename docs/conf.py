"""Sphinx configuration of the qc_control docs: the user guide (MyST pages
executed by myst-nb), the API reference (numpydoc), the examples as a gallery
(sphinx-gallery) and the course notebook (myst-nb).

Build with ``make docs`` (warnings are errors, numpydoc's included). Everything
builds and reads offline: the guide's code, the examples and the notebook run
on this machine, and the formulas are typeset by a copy of MathJax served from
the site itself (``sphinx-mathjax-offline``), so nothing is fetched.
"""

from __future__ import annotations

import os
import shutil
import sys
import warnings
from pathlib import Path
from typing import Any

HERE = Path(__file__).parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE / "_ext"))

import numpydoc.docscrape_sphinx as numpydoc_sphinx  # noqa: E402
from jinja2.sandbox import SandboxedEnvironment  # noqa: E402

import qc_control  # noqa: E402

project = "qc_control"
author = "qc_control contributors"
copyright = "qc_control contributors, MIT licence"
release = version = qc_control.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    # MathJax 3 from the package (sphinx-mathjax-offline), copied into _static/mathjax:
    # formulas render with no network (a course machine, a train), where the default
    # loads it from a CDN; through a shim that declares it safe for parallel builds
    "mathjax_offline",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "myst_nb",
]

# The course notebook lives with the examples; Sphinx reads sources only from
# docs/, so a copy is placed here on each build (docs/notebooks is ignored by git).
(HERE / "notebooks").mkdir(exist_ok=True)
shutil.copyfile(ROOT / "examples" / "course.ipynb", HERE / "notebooks" / "course.ipynb")

exclude_patterns = [
    "_build",
    "_ext",
    "**.ipynb_checkpoints",
    # sphinx-gallery writes a notebook of each example for download: not a page
    "auto_examples/*.ipynb",
]

# --- API reference --------------------------------------------------------------
# numpydoc reports a malformed docstring (an unknown section heading, say) with a
# Python warning, which Sphinx's -W does not see: make it an error, so the build
# fails on it as on any Sphinx warning.
warnings.filterwarnings("error", category=UserWarning, module=r"numpydoc(\..*)?$")
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # numpydoc's Parameters sections say it, once
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
default_role = "py:obj"  # `name` in a docstring links when Sphinx knows it


class _CompiledOnce(SandboxedEnvironment):
    """numpydoc's template environment, each template compiled once per build.

    numpydoc makes a new Jinja environment for every docstring it renders and
    every signature it reads (``numpydoc.docscrape_sphinx.get_doc_object``), and
    so compiles its one template anew each time: 1,168 times here, 1.7 s of CPU.
    The template is numpydoc's own (``templates_path`` sets no other), the same
    for every object; the pages built are the same, byte for byte.
    """

    compiled: dict[str, Any] = {}

    def get_template(self, name, parent=None, globals=None):
        if parent is not None or globals is not None:
            return super().get_template(name, parent, globals)
        if name not in self.compiled:
            self.compiled[name] = super().get_template(name)
        return self.compiled[name]


numpydoc_sphinx.SandboxedEnvironment = _CompiledOnce

# --- gallery: every script in examples/, run during the build ------------------
sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"\.py$",  # run them all, not only plot_*.py
    "reset_argv": "qc_gallery.example_argv",
    "image_scrapers": ("qc_gallery.png_scraper",),
    "abort_on_example_error": True,
    "download_all_examples": False,
    "remove_config_comments": True,
    "line_numbers": False,
    "min_reported_time": 1e9,  # machine-dependent times stay out of the pages
    # nor a page of them: it loads jQuery and DataTables from CDNs, and the site
    # must work offline
    "write_computation_times": False,
    # the examples run side by side on a parallel build (sphinx-build -j)
    "parallel": True,
}

# --- the notebook: executed during the build, by a local kernel ----------------
# qc_control's sweeps import tqdm.auto, which warns in a kernel without ipywidgets
# (the docs extra installs none); the warning would print this machine's paths
# into the pages. The kernels inherit this filter from the environment.
os.environ["PYTHONWARNINGS"] = ",".join(
    filter(None, [os.environ.get("PYTHONWARNINGS"), "ignore:IProgress not found"])
)

# The kernels that run the pages talk to the build over IPC (Unix sockets in the
# user's Jupyter runtime folder) rather than TCP on 127.0.0.1: ipykernel 7 logs
# "Kernel is running over TCP without encryption" once per kernel started (14 in a
# build), and names IPC as the remedy. The kernel and the build are one user's
# processes on one machine, which IPC keeps to that user; no warning is filtered, so
# any other the kernels log still shows. ZeroMQ has no IPC transport on Windows:
# there the kernels stay on TCP, and the message with them.
if os.name == "posix":
    from jupyter_client.manager import KernelManager

    KernelManager.transport.default_value = "ipc"  # the trait's default, read per kernel

# The guide's pages are MyST notebooks too: every code cell runs in the build, so a
# page that drifts from the code fails it (nb_execution_raise_on_error).
nb_execution_mode = "force"
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_in_temp = True
nb_merge_streams = True
myst_enable_extensions = ["dollarmath", "amsmath"]  # $...$ and $$...$$ in the notebook

html_theme = "alabaster"  # ships with Sphinx: nothing more to install
html_theme_options = {"page_width": "1180px", "sidebar_width": "230px"}
html_title = f"qc_control {release}"
html_static_path: list[str] = []
html_show_sourcelink = False


def _add_architecture(app, docname, source):
    """Put docs/architecture.md (the design note, owned elsewhere) in the
    contents once it exists; until then the contents do not name it."""
    if docname == "index" and (HERE / "architecture.md").exists():
        source[0] = source[0].replace("\n   api\n", "\n   api\n   architecture\n")


# These docstrings write |x| for a norm or a magnitude, which reStructuredText reads
# as a substitution (an error under -W). Their bars are escaped outside inline
# literals; a docstring that writes ``|x|`` (or escapes the bars) needs no entry here.
_BARS = {
    "qc_control.models.modal.Mode",
    "qc_control.studies.compare.result.MethodComparison",
    "qc_control.ride.comfort.Transmissibility.to_frame",
    "qc_control.ride.comfort.ride_metrics_spectral",
}


def _escape_bars(app, what, name, obj, options, lines):
    if name not in _BARS:
        return
    for i, line in enumerate(lines):
        parts = line.split("``")
        parts[::2] = [p.replace("|", "\\|") for p in parts[::2]]  # outside ``literals``
        lines[i] = "``".join(parts)


def setup(app):
    app.connect("source-read", _add_architecture)
    app.connect("autodoc-process-docstring", _escape_bars, priority=400)  # before numpydoc
