"""The user guide (``docs/guide/``) and the README that points into it.

The guide's pages are MyST notebooks: the docs build executes every code cell
(``tests/test_docs.py``). Here, without Sphinx, the pages are checked for what
makes them a guide (each in the contents, each executable, each link alive),
the README for what makes it a front door, and the values a page's cells leave
behind against independent references, as a reader would paste them.
"""

import ast
import itertools
import re
from pathlib import Path

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control.studies.compare import MethodComparison

ROOT = Path(__file__).parent.parent
DOCS = ROOT / "docs"
GUIDE = DOCS / "guide"
README = ROOT / "README.md"

CODE_CELL = re.compile(r"^```\{code-cell\}[^\n]*\n(.*?)^```", re.S | re.M)
#: The topics issue 23 lists, one page each.
TOPICS = (
    "getting-started",
    "responses",
    "methods",
    "nonlinear",
    "control",
    "identification",
    "vehicles",
    "roads",
    "sweeps",
    "command-line",
    "errors",
    "performance",
)


def code_cells(page: Path) -> list[str]:
    """A page's code cells, without their ``:option:`` lines."""
    cells = CODE_CELL.findall(page.read_text(encoding="utf-8"))
    return ["\n".join(ln for ln in c.splitlines() if not ln.startswith(":")) for c in cells]


def run_cells(page: Path, count: int, folder: Path, monkeypatch) -> dict:
    """Run a page's first ``count`` code cells in order, in ``folder``, as a reader would."""
    monkeypatch.chdir(folder)
    namespace: dict = {}
    for i, cell in enumerate(code_cells(page)[:count]):
        try:
            exec(compile(cell, f"{page.name} cell {i}", "exec"), namespace)
        except Exception as exc:  # name the cell that broke
            raise AssertionError(f"{page.name} cell {i} failed: {exc!r}\n{cell}") from exc
    return namespace


def test_every_topic_has_an_executed_page_in_the_contents():
    """Each topic of issue 23 has a page, and every page (a later topic's too)
    is in the guide's contents and runs in the build."""
    toctree = (GUIDE / "index.md").read_text(encoding="utf-8")
    listed = re.findall(r"^([a-z-]+)$", toctree.split("```{toctree}")[1], re.M)
    assert set(TOPICS) <= set(listed), set(TOPICS) - set(listed)
    pages = sorted(p.stem for p in GUIDE.glob("*.md") if p.stem != "index")
    assert sorted(listed) == pages, "list every page of docs/guide/ in its index.md"
    for topic in listed:
        page = GUIDE / f"{topic}.md"
        text = page.read_text(encoding="utf-8")
        # myst-nb executes a Markdown page only when its front matter says it is a notebook
        assert text.startswith("---\nfile_format: mystnb\n"), page
        assert code_cells(page), f"{page.name} has no code cell: nothing of it is checked"
        # a ```python fence would be shown, not run: every Python example is a code cell
        assert "```python" not in text, f"{page.name}: make the python block a code-cell"


def test_every_code_cell_is_valid_python():
    for page in GUIDE.glob("*.md"):
        for i, cell in enumerate(code_cells(page)):
            ast.parse(cell, f"{page.name} cell {i}")


def _relative_links(text: str) -> list[str]:
    targets = re.findall(r"\]\(([^)\s]+)\)", text)
    return [t.split("#")[0] for t in targets if not re.match(r"[a-z]+:", t) and t[0] != "#"]


def test_the_links_between_pages_lead_somewhere():
    for page in [README, *GUIDE.glob("*.md")]:
        for target in _relative_links(page.read_text(encoding="utf-8")):
            assert (page.parent / target).exists(), f"{page.name} links to {target}: not found"


def test_the_readme_is_a_front_door():
    """Under 10 KB, with both routes in (``make``, and a plain venv for a machine
    without it, Windows paths spelled), and a link to every guide page."""
    text = README.read_text(encoding="utf-8")
    size = len(text.encode("utf-8"))
    assert size < 10_000, f"README.md is {size} bytes; the guide is the place for more"
    for route in (
        "make report",
        "make test",
        "python3 -m venv .venv",
        ".venv/bin/python -m pip install -e .",
        "py -m venv .venv",
        ".venv\\Scripts\\python -m pip install -e .",
        ".venv\\Scripts\\qc-control report",
    ):
        assert route in text, route
    links = set(_relative_links(text))
    missing = [t for t in TOPICS if f"docs/guide/{t}.md" not in links]
    assert not missing, f"the README's table of the guide leaves out {missing}"


def test_the_home_page_example_calls_what_exists():
    """``docs/index.rst``'s example is not executed by the build (it is reST):
    every ``qc.NAME`` it calls is public and every ``cmp.NAME`` a member of
    `MethodComparison` (it once called a ``cmp.write`` that never existed)."""
    text = (DOCS / "index.rst").read_text(encoding="utf-8")
    block = text.split(".. code-block:: python")[1].split("\n\n.. ")[0]
    tree = ast.parse("\n".join(line[4:] for line in block.splitlines()))
    owners = {"qc": qc, "cmp": MethodComparison}
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
            owner = owners.get(node.value.id)
            if owner is not None:
                assert hasattr(owner, node.attr), f"{node.value.id}.{node.attr} does not exist"


@pytest.mark.slow  # a 60 s road at 5 ms, RK4 and python-control's exact response: about 3 s
def test_the_road_response_is_rk4_on_the_exact_response(tmp_path, monkeypatch):
    """The roads page's ``resp`` is RK4 at h = 5 ms on the ISO 8608 class C road
    ``zr``; python-control's exact response to the same samples is the reference."""
    namespace = run_cells(GUIDE / "roads.md", 1, tmp_path, monkeypatch)
    T, zr, resp, p = (namespace[k] for k in ("T", "zr", "resp", "params"))
    assert resp.method.name == "rk4"
    exact = control.forced_response(qc.quarter_car(p, road=True), T, zr)
    for label in ("xs", "body_acc", "susp_travel"):
        got = resp.outputs[list(resp.output_labels).index(label)]
        ref = exact.outputs[list(exact.output_labels).index(label)]
        gap = np.max(np.abs(got - ref)) / np.max(np.abs(ref))
        # Measured: 1.1e-6 of the peak for body_acc (the worst), 1.2e-7 for xs.
        # 1e-5 holds that with margin, and is far below a second-order
        # method's gap on the same road (Heun: 2e-3), so it tells RK4 apart.
        assert gap < 1e-5, (label, gap)


@pytest.mark.slow  # a sweep of 1,000 designs over 10,001 samples: about 2 s
def test_the_sweep_covers_its_grid_without_rejections(tmp_path, monkeypatch):
    """The sweeps page's ``result`` is a sweep over 40 ks by 25 zeta."""
    result = run_cells(GUIDE / "sweeps.md", 1, tmp_path, monkeypatch)["result"]
    assert result.errors.empty
    assert len(result.metrics) == 40 * 25
    grid = set(itertools.product(np.linspace(15e3, 45e3, 40), np.linspace(0.1, 0.6, 25)))
    got = set(zip(result.metrics["ks"], result.metrics["zeta"]))
    assert got == grid
    assert result.metrics["stable"].all()  # RK4 at h = 1 ms is far inside every limit
