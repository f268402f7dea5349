"""The docs site: API reference, example gallery and course notebook, built with
Sphinx with warnings as errors (what ``make docs`` runs), once per run by
conftest's ``docs_build``."""

import pkgutil
import re
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
@pytest.mark.xdist_group("docs")
def test_docs_build_with_warnings_as_errors(docs_build):
    html = docs_build.html
    assert docs_build.returncode == 0, docs_build.stderr[-5000:]
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
    assert "Exercise 5: not answered yet" in course  # the run's outputs, rendered
    assert course.count("<img") >= 5
