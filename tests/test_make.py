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
