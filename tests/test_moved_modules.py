"""The module paths of qc_control 0.1 import, with what they had and a
DeprecationWarning naming the new path (issue 38 item 6).

The reference is 0.1 itself: the list of its flat modules is read from git
history in the commit that moved them (49f95e9, "Sub-packages that show the
layers"), written out here as the release's file names.
"""

from __future__ import annotations

import importlib
import subprocess
import sys
import warnings

import pytest

import qc_control as qc
from qc_control._moved import MOVED

#: qc_control 0.1's top-level modules (``git ls-tree 49f95e9~1 qc_control/``), but
#: for ``cli`` and ``ride``, which are packages of the same name now.
RELEASE_0_1 = """compare console control_study controllers damping halfcar integrate
interconnect iso2631 limits lti messages methods metrics modal model nlkernel nlsweep
nonlinear order_conditions plotting recurrence response road scenario spectral
stability sweeps vehicle""".split()


def test_every_module_of_the_release_has_a_new_home():
    assert sorted(MOVED) == sorted(RELEASE_0_1)


@pytest.mark.parametrize("old", sorted(n for n, new in MOVED.items() if new is not None))
def test_an_old_path_imports_what_it_had_and_warns_naming_the_new(old, monkeypatch):
    monkeypatch.delitem(sys.modules, f"qc_control.{old}", raising=False)
    new = importlib.import_module(f"qc_control.{MOVED[old]}")
    with pytest.warns(
        DeprecationWarning,
        match=rf"qc_control\.{old} is deprecated.*import qc_control\.{MOVED[old]}$",
    ) as seen:
        module = importlib.import_module(f"qc_control.{old}")
    public = getattr(new, "__all__", [n for n in vars(new) if not n.startswith("_")])
    assert public and all(getattr(module, name) is getattr(new, name) for name in public)
    assert seen[0].category is DeprecationWarning
    # the new module is untouched: its own name, not the old path's
    assert new.__name__ == f"qc_control.{MOVED[old]}"


def test_the_warning_points_at_the_users_import_line(tmp_path):
    script = tmp_path / "old_script.py"
    script.write_text("import qc_control\nfrom qc_control.methods import get_method\n")
    run = subprocess.run(
        [sys.executable, "-W", "always::DeprecationWarning", str(script)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    assert f"{script}:2: DeprecationWarning: qc_control.methods is deprecated" in run.stderr


def test_public_names_stay_what_they_are_after_an_old_import(monkeypatch):
    """``import qc_control.integrate`` (0.1's module) leaves ``qc.integrate`` the
    function, and ``import qc_control.road`` the roads module, without a warning."""
    from qc_control.numerics.integrate import integrate
    from qc_control.ride import road

    for old in ("integrate", "road"):
        monkeypatch.delitem(sys.modules, f"qc_control.{old}", raising=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        importlib.import_module("qc_control.integrate")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        importlib.import_module("qc_control.road")
    assert qc.integrate is integrate and qc.road is road


def test_a_name_that_never_was_is_still_an_import_error():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("qc_control.no_such_module")


def test_the_command_lines_scenario_module_hands_on_the_moved_scenario(monkeypatch):
    """``qc_control.cli.scenario`` (where `Scenario` and its TOML lived) imports with
    a warning naming the new homes, and hands on what it had: the same objects."""
    from qc_control.ride import road
    from qc_control.studies import scenario, scenario_command, scenario_toml

    monkeypatch.delitem(sys.modules, "qc_control.cli.scenario", raising=False)
    with pytest.warns(DeprecationWarning, match=r"import qc_control\.studies\.scenario") as seen:
        import qc_control.cli.scenario as old
    assert seen[0].filename == __file__  # the importing line, not the import system
    assert old.Scenario is scenario.Scenario is qc.Scenario
    assert old.ScenarioError is scenario_toml.ScenarioError is qc.ScenarioError
    assert old.read_config is qc.read_config and old.load_config is qc.load_config
    assert old.command_line is scenario_command.command_line
    assert old.road_from_mapping is scenario_toml.road_from_mapping
    for name in old.__all__:
        assert getattr(old, name) is not None, name
    with pytest.warns(DeprecationWarning, match=r"use qc_control\.road\.Bump"):
        assert old.BumpRoad is road.Bump
