"""The docs site: API reference, example gallery and course notebook, built with
Sphinx with warnings as errors (what ``make docs`` runs)."""

import pkgutil
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import qc_control

ROOT = Path(__file__).parent.parent
DOCS = ROOT / "docs"


def test_every_public_module_is_in_the_api_reference():
    listed = set(re.findall(r"^\.\. automodule:: (\S+)", (DOCS / "api.rst").read_text(), re.M))
    modules = {
        m.name
        for m in pkgutil.walk_packages(qc_control.__path__, "qc_control.")
        if not m.name.rpartition(".")[2].startswith("_")
    }
    missing = sorted(modules - listed)
    assert not missing, f"add {missing} to docs/api.rst"


@pytest.mark.slow
def test_docs_build_with_warnings_as_errors(tmp_path):
    for name in ("sphinx", "numpydoc", "sphinx_gallery", "myst_nb"):
        pytest.importorskip(name, reason="the docs extra is not installed: `make docs` installs it")
    # a copy of the sources, so that the build's generated files stay out of the tree
    ignore = shutil.ignore_patterns(
        "_build", "auto_examples", "notebooks", "sg_execution_times.rst", "*_output"
    )
    shutil.copytree(DOCS, tmp_path / "docs", ignore=ignore)
    shutil.copytree(ROOT / "examples", tmp_path / "examples", ignore=ignore)
    html = tmp_path / "docs" / "_build" / "html"
    run = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html"]
        + [str(tmp_path / "docs"), str(html)],
        capture_output=True,
        text=True,
        timeout=1200,
        env={"MPLBACKEND": "Agg", "PATH": str(Path(sys.executable).parent)},
    )
    assert run.returncode == 0, run.stderr[-5000:]
    api = (html / "api.html").read_text(encoding="utf-8")
    for name in (
        "qc_control.models.quarter.quarter_car",
        "qc_control.report.plotting.plot_outputs",
    ):
        assert f'id="{name}"' in api, name
    for script in (ROOT / "examples").glob("*.py"):  # each example ran and drew
        page = (html / "auto_examples" / f"{script.stem}.html").read_text(encoding="utf-8")
        assert re.search(r'<img [^>]*src="\.\./_images/sphx_glr_' + script.stem, page), script
    course = (html / "notebooks" / "course.html").read_text(encoding="utf-8")
    assert "Exercise 5: not answered yet" in course  # executed during the build
    assert course.count("<img") >= 5
