"""The module paths of qc_control 0.1, kept importable for one more minor release.

The flat modules of 0.1 (``qc_control.methods``, ``qc_control.controllers``,
``qc_control.console`` ...) moved into the sub-packages that show the layers
(``numerics``, ``models``, ``responses``, ``ride``, ``studies``, ``report``,
``cli``). A user's ``from qc_control.methods import get_method`` must not
break without a word: `MovedModules`, a finder on ``sys.meta_path``, answers
an old path with the module at its new one (the same object, so everything
it had is there) and a `DeprecationWarning` naming the new path, pointed at
the user's import line.

``qc_control.road`` is not here: it is the public name of the roads
(``qc.road``), and ``import qc_control.road`` keeps working through this
finder without a warning. ``qc_control.cli`` and ``qc_control.ride`` are
packages of their own now; their 0.1 contents are reached through them.

The policy (CHANGELOG.md): an old path warns for at least one minor release
and is removed in the next.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings
from types import FrameType, ModuleType

__all__ = ["MOVED", "MovedModules"]

#: Old module (below qc_control) -> its new home; None: a current name, no warning.
MOVED: dict[str, str | None] = {
    "road": None,
    "compare": "studies.compare",
    "console": "cli.console",
    "control_study": "studies.control_study",
    "controllers": "models.controllers",
    "damping": "studies.damping",
    "halfcar": "models.halfcar",
    "integrate": "numerics.integrate",
    "interconnect": "numerics.interconnect",
    "iso2631": "ride.iso2631",
    "limits": "numerics.limits",
    "lti": "numerics.lti",
    "messages": "numerics.messages",
    "methods": "numerics.methods",
    "metrics": "ride.metrics",
    "modal": "models.modal",
    "model": "models.quarter",
    "nlkernel": "models.nlkernel",
    "nlsweep": "studies.nlsweep",
    "nonlinear": "models.nonlinear",
    "order_conditions": "numerics.order_conditions",
    "plotting": "report.plotting",
    "recurrence": "numerics.recurrence",
    "response": "responses.timeresp",
    "scenario": "studies.scenario",
    "spectral": "ride.spectral",
    "stability": "numerics.stability",
    "sweeps": "studies.sweeps",
    "vehicle": "models.vehicle",
}


def _internal(frame: FrameType) -> bool:
    """A frame of the import system, which `warnings.warn` does not count in
    ``stacklevel`` (its own rule: 'importlib' and '_bootstrap' in the file name)."""
    name = frame.f_code.co_filename
    return "importlib" in name and "_bootstrap" in name


def _caller_level() -> int:
    """The ``stacklevel``, counted as `warnings.warn` counts it, of the first
    frame outside the import system and this module: the user's import line."""
    frame: FrameType | None = sys._getframe(1)
    level = 1
    while frame is not None and (_internal(frame) or frame.f_globals.get("__name__") == __name__):
        frame = frame.f_back
        if frame is not None and not _internal(frame):
            level += 1
    return level


class _Alias(importlib.abc.Loader):
    """Loads an old path as a module holding what the new one holds.

    The module is a module of its own (the import system names it by the old
    path; the new module's name, spec and loader stay as they are), whose
    names are the new module's objects, and which hands on any other name
    the new module gains later.
    """

    def __init__(self, old: str, new: str, warn: bool):
        self.old, self.new, self.warn = old, new, warn

    def create_module(self, spec) -> None:
        if self.warn:
            warnings.warn(
                f"{self.old} is deprecated and will be removed in the next minor release: "
                f"import {self.new}",
                DeprecationWarning,
                stacklevel=_caller_level(),
            )
        return None  # the default module, named by the old path

    def exec_module(self, module: ModuleType) -> None:
        new = importlib.import_module(self.new)
        own = {"__name__", "__spec__", "__loader__", "__package__", "__path__", "__file__"}
        module.__dict__.update({k: v for k, v in vars(new).items() if k not in own})
        module.__getattr__ = lambda name: getattr(new, name)  # type: ignore[method-assign]


class MovedModules(importlib.abc.MetaPathFinder):
    """Finds ``qc_control.<old>`` for each name of `MOVED`."""

    def find_spec(self, fullname, path=None, target=None):
        package, _, name = fullname.rpartition(".")
        if package != "qc_control" or name not in MOVED:
            return None
        new = MOVED[name]
        target_name = f"qc_control.{new or 'ride.road'}"
        return importlib.util.spec_from_loader(
            fullname, _Alias(fullname, target_name, new is not None)
        )


def install() -> None:
    """Put the finder on ``sys.meta_path`` once, after the usual finders, so
    that a module that exists is always found first."""
    if not any(isinstance(f, MovedModules) for f in sys.meta_path):
        sys.meta_path.append(MovedModules())
