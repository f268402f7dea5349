"""How the suite runs: on every core, with the shared artefacts on one worker,
and the package marked as typed (the quick checks; tests/test_wheel.py
builds and installs the wheel itself)."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).parent.parent


@pytest.mark.skipif(shutil.which("make") is None, reason="no make on this machine")
def test_make_test_runs_on_every_core_with_the_artefact_groups_together():
    run = subprocess.run(
        ["make", "-n", "-B", "test"], cwd=ROOT, capture_output=True, text=True, check=True
    )
    (line,) = [x for x in run.stdout.splitlines() if "-m pytest" in x]
    # loadgroup: the tests marked xdist_group("docs") share one docs build and one
    # notebook run, and the wheel's tests one installed environment
    assert re.search(r"-n auto\b", line) and "--dist loadgroup" in line, line


def test_the_package_is_marked_typed_and_the_marker_ships():
    assert (ROOT / "qc_control" / "py.typed").is_file()
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert "py.typed" in config["tool"]["setuptools"]["package-data"]["qc_control"]
    extras = " ".join(config["project"]["optional-dependencies"]["test"])
    for tool in ("pytest-xdist", "build", "twine"):
        assert re.search(rf"\b{tool}\b", extras), tool
