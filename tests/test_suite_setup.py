"""How the suite runs: on every core, with the shared artefacts on one worker,
and the package marked as typed (the quick checks; tests/test_wheel.py
builds and installs the wheel itself)."""

import os
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


@pytest.mark.slow  # two xdist workers start: about 3 s
def test_a_group_stays_on_one_worker(tmp_path):
    """`--dist loadgroup` sends a group's tests to one worker (each writes which),
    so that the docs build and the notebook run happen once per suite, not once
    per worker. pytest 9.2 with pytest-xdist 3.8 splits them (pytest-xdist #1386)."""
    pytest.importorskip("xdist", reason="the test extra installs pytest-xdist")
    (tmp_path / "test_grouped.py").write_text(
        "import os, pytest\n"
        "@pytest.mark.xdist_group('g')\n"
        "@pytest.mark.parametrize('i', range(6))\n"
        "def test_in_group(i, tmp_path_factory):\n"
        "    worker = os.environ.get('PYTEST_XDIST_WORKER', 'none')\n"
        "    (tmp_path_factory.getbasetemp().parent.parent / f'ran-{i}-{worker}').touch()\n",
        encoding="utf-8",
    )
    # only pytest-xdist among the installed plugins: the three interpreters (the
    # controller and two workers) skip importing the others (hypothesis, playwright,
    # anyio...), which this file does not use (measured, this file's CPU: 13.1 s -> 10.6 s)
    env = {**os.environ, "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1"}
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "xdist", "-n", "2", "--dist", "loadgroup",
         "-p", "no:cacheprovider", "--basetemp", str(tmp_path / "base"), "test_grouped.py"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert run.returncode == 0, run.stdout + run.stderr
    workers = {p.name.rsplit("-", 1)[1] for p in tmp_path.glob("ran-*")}
    assert len(list(tmp_path.glob("ran-*"))) == 6
    assert len(workers) == 1, f"the group ran on {sorted(workers)}"
