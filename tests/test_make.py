"""The Makefile's targets, read with ``make -n -B`` (print every command, run none).

``make report`` must install qc_control alone (not the test extras, which
made a 493 MB venv), each kind of install keeps its own stamp, and the
README says how to reach what was installed.
"""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent

pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="no make on this machine")


def commands(target: str) -> str:
    run = subprocess.run(
        ["make", "-n", "-B", target], cwd=ROOT, capture_output=True, text=True, check=True
    )
    return run.stdout


def installs(text: str) -> list[str]:
    """What each install line installs: uv first, and pip the same where uv cannot."""
    lines = [line for line in text.splitlines() if " install " in line and " -e " in line]
    found = []
    for line in lines:
        by_uv, by_pip = line.split(" || ")
        assert "-m uv pip install" in by_uv and "-m pip install" in by_pip, line
        (what,) = set(re.findall(r"--quiet (-e \S+)", line))
        found.append(what)
    return found


def stamp(text: str) -> str:
    (touched,) = re.findall(r"^touch (\S+)$", text, re.M)
    return touched


def test_report_installs_qc_control_without_extras():
    text = commands("report")
    assert installs(text) == ["-e ."]
    assert "qc-control report --out report" in text


def test_each_kind_of_install_has_its_own_stamp():
    kinds = {t: commands(t) for t in ("report", "test", "docs", "notebook")}
    assert installs(kinds["test"]) == ["-e '.[test,docs]'"]
    assert installs(kinds["docs"]) == ["-e '.[docs]'"]
    assert installs(kinds["notebook"]) == ["-e '.[notebook]'"]
    stamps = {t: stamp(text) for t, text in kinds.items()}
    assert len(set(stamps.values())) == 4, stamps


def test_docs_and_html_check_targets():
    assert re.search(r"sphinx-build -W .*docs docs/_build/html", commands("docs"))
    html = commands("check-html")
    assert "apt-get install -y chromium" in html and "tests/test_html_browser.py" in html


def test_the_readme_says_how_to_reach_the_installed_tools():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    for words in (
        ".venv/bin/qc-control",
        "source .venv/bin/activate",
        ".venv/bin/python examples/",
    ):
        assert words in readme, words
    assert re.search(r"times are (from )?one machine", readme)  # timings flagged


def _copy_makefile(tmp_path: Path) -> Path:
    (tmp_path / "Makefile").write_text((ROOT / "Makefile").read_text(encoding="utf-8"))
    (tmp_path / "pyproject.toml").write_text("")
    return tmp_path


def _fake_python(path: Path, version: str) -> Path:
    """A ``python`` that says it is ``version`` (major.minor) and runs nothing else."""
    major, minor = version.split(".")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        "#!/bin/sh\n"
        f'case "$1" in --version) echo "Python {version}.0";; '
        f"-c) [ {major}{minor.zfill(2)} -ge 310 ];; esac\n"
    )
    path.chmod(0o755)
    return path


@pytest.mark.skipif(shutil.which("sh") is None, reason="needs a POSIX shell")
def test_a_venv_of_a_too_old_python_is_made_again(tmp_path):
    """Issue 39 item 10: a .venv made by Python 3.9 was reused by every later
    make; it is removed, saying so, before anything is installed in it."""
    here = _copy_makefile(tmp_path)
    _fake_python(here / ".venv" / "bin" / "python", "3.9")
    run = subprocess.run(["make", "-n", "report"], cwd=here, capture_output=True, text=True)
    assert "was made by a Python older than 3.10" in run.stdout + run.stderr
    assert not (here / ".venv").exists()


@pytest.mark.skipif(shutil.which("sh") is None, reason="needs a POSIX shell")
def test_a_too_old_python_is_refused_before_making_the_venv(tmp_path):
    here = _copy_makefile(tmp_path)
    old = _fake_python(tmp_path / "bin" / "python3.9", "3.9")
    run = subprocess.run(
        ["make", ".venv/bin/python", f"PYTHON={old}"], cwd=here, capture_output=True, text=True
    )
    assert run.returncode != 0
    assert "is not Python 3.10 or newer (Python 3.9.0)" in run.stderr
    assert "PYTHON=python3.12" in run.stderr and not (here / ".venv").exists()


def test_a_venv_of_a_recent_python_is_kept(tmp_path):
    here = _copy_makefile(tmp_path)
    _fake_python(here / ".venv" / "bin" / "python", "3.11")
    run = subprocess.run(["make", "-n", "report"], cwd=here, capture_output=True, text=True)
    assert "older than" not in run.stdout + run.stderr and (here / ".venv").exists()
