"""The docs site: the user guide, API reference, example gallery and course
notebook, built with Sphinx with warnings as errors (what ``make docs`` runs),
once per run by conftest's ``docs_build``, then read offline in headless
Chromium: the formulas typeset with nothing fetched, no raw TeX left on the
page.

One difference from ``make docs``: the suite runs the guide's pages one after
the other in one kernel, each with a fresh namespace and folder
(conftest's ``guide_in_one_kernel``), where ``make docs`` gives each page a
kernel of its own; the build renders the outputs of that run."""

import os
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

# the browser fixture and the network rule of the report's check (Debian's Chromium,
# installed in the fixture where the tests run as root, as in CI)
from test_html_browser import _local, browser  # noqa: F401

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


@pytest.fixture(scope="module")
def site(docs_build):
    """The built site's HTML folder (the build, once per run, must have passed)."""
    assert docs_build.returncode == 0, docs_build.stderr[-5000:]
    return docs_build.html


@pytest.mark.slow
@pytest.mark.xdist_group("docs")
def test_docs_build_with_warnings_as_errors(site):
    html = site
    api = (html / "api.html").read_text(encoding="utf-8")
    for name in (
        "qc_control.models.quarter.quarter_car",
        "qc_control.report.plotting.plot_outputs",
    ):
        assert f'id="{name}"' in api, name
    # numpydoc read FixedStepResponse's attribute section (a malformed heading dropped it)
    fixed_step = api.split('id="qc_control.responses.common.FixedStepResponse"')[1]
    fixed_step = fixed_step.split('id="qc_control.responses.common.', 1)[0]  # to the next name
    assert "Attributes" in fixed_step
    for attribute in ("max_stable_step", "step_rule", "event_labels", "success, message"):
        assert attribute in fixed_step, attribute
    for script in (ROOT / "examples").glob("*.py"):  # each example ran and drew
        page = (html / "auto_examples" / f"{script.stem}.html").read_text(encoding="utf-8")
        assert re.search(r'<img [^>]*src="\.\./_images/sphx_glr_' + script.stem, page), script
    course = (html / "notebooks" / "course.html").read_text(encoding="utf-8")
    assert "Exercise 5: not answered yet" in course  # the run's outputs, rendered
    assert course.count("<img") >= 5


@pytest.mark.slow
@pytest.mark.xdist_group("docs")
def test_every_guide_page_ran_its_code(site, docs_build):
    """Each guide page is in the site with its cells' outputs: the build ran them."""
    pages = sorted(p.stem for p in (DOCS / "guide").glob("*.md") if p.stem != "index")
    # every page ran in the shared kernel without an error, and the build rendered
    # that run (a page it had to run again would be one the shared kernel ran otherwise)
    assert docs_build.cached == pages
    assert docs_build.executed_by_build == []
    for page in (DOCS / "guide").glob("*.md"):
        if page.stem == "index":
            continue
        built = (site / "guide" / f"{page.stem}.html").read_text(encoding="utf-8")
        assert "cell_output" in built, f"{page.name}: no cell output in the built page"
    # a number the reader is told to expect, computed in the build
    start = (site / "guide" / "getting-started.html").read_text(encoding="utf-8")
    assert "max |xs error| = 0.000192 m with 2000 RHS evaluations" in start


@pytest.mark.slow  # a kernel started and five pages run in it: about 2 s
def test_the_shared_kernel_gives_each_page_a_fresh_namespace_and_folder(tmp_path):
    """What `guide_in_one_kernel` keeps from one page to the next is no more
    than a process keeps: a name the page did not define or import fails it
    (it is left out of the cache, so the build runs it alone and fails on it),
    each page starts in an empty folder of its own, and a warning shown once
    on one page is shown again on the next."""
    from conftest import DOCS_ENV, guide_in_one_kernel
    from jupyter_cache import get_cache

    lib, guide, pages = (tmp_path / name for name in ("lib", "guide", "pages"))
    for folder in (lib, guide, pages):
        folder.mkdir()
    # a warning raised inside a module, as the library's are: Python shows it once
    # per place in that module unless the warnings' registry is forgotten
    (lib / "warner.py").write_text(
        "import warnings\n\ndef warn():\n    warnings.warn('from a module', UserWarning)\n"
    )
    front = "---\nfile_format: mystnb\nkernelspec: {name: python3, display_name: Python 3}\n---\n"
    for name, code in {
        "a": "import numpy as np\nopen('left-behind.txt', 'w').close()",
        "b": "import os\nassert os.listdir('.') == [], os.listdir('.')",
        "c": "np.zeros(1)  # imported by page a only",
        "d": "import warner\nwarner.warn()  # page d",
        "e": "import warner\nwarner.warn()  # page e: the same place in warner.py",
    }.items():
        cell = f"```{{code-cell}} ipython3\n{code}\n```\n"
        (guide / f"{name}.md").write_text(f"{front}# {name}\n\n{cell}", encoding="utf-8")
    env = dict(DOCS_ENV, PYTHONPATH=str(lib))
    cached = guide_in_one_kernel(guide, tmp_path / "cache", pages, env)
    assert cached == ["a", "b", "d", "e"]
    assert (pages / "a" / "left-behind.txt").exists()
    db = get_cache(str(tmp_path / "cache"))
    for record in db.list_cache_records():
        if record.uri.endswith(("d.md", "e.md")):
            (cell,) = db.get_cache_bundle(record.pk).nb.cells
            assert "UserWarning: from a module" in str(cell.outputs), (record.uri, cell.outputs)


#: docs/conf.py, then a kernel started as myst-nb starts one (nbclient), running a
#: cell that warns: what the kernel logged to the build's stderr, and the cell's output.
_KERNEL_UNDER_CONF = """
import runpy, sys, nbformat
from nbclient import NotebookClient
runpy.run_path(sys.argv[1])
nb = nbformat.v4.new_notebook()
nb.cells.append(nbformat.v4.new_code_cell("import warnings; warnings.warn('a cell warns')"))
NotebookClient(nb, timeout=120).execute()
print(nb.cells[0].outputs[0]["text"])
"""


@pytest.mark.slow  # docs/conf.py imported and one kernel started: about 3 s
@pytest.mark.skipif(os.name != "posix", reason="ZeroMQ has no IPC transport on Windows")
def test_the_builds_kernels_log_no_tcp_warning_and_keep_every_other(tmp_path):
    """Issue 39 item 12: each kernel of the build logged "Kernel is running over TCP
    without encryption" (14 in a build). Under docs/conf.py a kernel talks over IPC
    and logs nothing of the kind, and a warning raised in a cell still shows."""
    run = subprocess.run(
        [sys.executable, "-c", _KERNEL_UNDER_CONF, str(DOCS / "conf.py")],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
        check=True,
    )
    assert "without encryption" not in run.stderr, run.stderr
    assert "UserWarning: a cell warns" in run.stdout


#: Pages with formulas: a guide page with display and inline math ($$ and $),
#: one whose math is in its own paragraph, and the notebook's (dollarmath).
MATH_PAGES = ("guide/responses.html", "guide/roads.html", "notebooks/course.html")

#: After MathJax: how many formulas the page marks for typesetting, how many it
#: typeset, and the text a reader sees outside code (code and its output may
#: hold TeX on purpose, a matplotlib label say).
TYPESET = """async () => {
  const prose = () => {
    const clone = document.body.cloneNode(true);
    clone.querySelectorAll("pre, code, script, style, mjx-container").forEach(e => e.remove());
    return clone.textContent;
  };
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
    await MathJax.startup.promise;
  }
  return {
    marked: document.querySelectorAll(".math").length,
    typeset: document.querySelectorAll("mjx-container").length,
    errors: document.querySelectorAll("mjx-merror").length,
    text: prose(),
    mathjax: Boolean(window.MathJax && MathJax.version),
  };
}"""


@pytest.mark.slow
@pytest.mark.xdist_group("docs")
@pytest.mark.parametrize("name", MATH_PAGES)
def test_formulas_render_offline(site, browser, name):  # noqa: F811
    """The page opened from disk with the browser offline: MathJax (served
    from the site) typesets every formula, and no raw TeX is left in the text
    a reader sees."""
    context = browser.new_context(viewport={"width": 1280, "height": 900}, offline=True)
    requested: list[str] = []
    context.on("request", lambda request: requested.append(request.url))
    try:
        tab = context.new_page()
        tab.goto((site / name).as_uri(), wait_until="load")
        verdict = tab.evaluate(TYPESET)
    finally:
        context.close()
    remote = [url for url in requested if not _local(url)]
    assert remote == [], remote  # nothing reached for the network
    assert verdict["mathjax"], "MathJax did not load from the site"
    assert verdict["marked"] > 0, "no formula on the page: choose a page with math"
    assert verdict["typeset"] >= verdict["marked"], verdict["typeset"]
    assert verdict["errors"] == 0
    for raw in ("\\frac", "$$", "\\(", "\\[", "\\lambda", "\\sqrt"):
        assert raw not in verdict["text"], f"raw TeX {raw!r} on {name}"


def _code_cells(page: Path) -> list[list[str]]:
    """The lines of each ``{code-cell}`` of a MyST page."""
    cells, inside = [], None
    for line in page.read_text(encoding="utf-8").splitlines():
        if inside is None and line.startswith("```{code-cell}"):
            inside = []
        elif inside is not None and line.startswith("```"):
            cells.append(inside)
            inside = None
        elif inside is not None:
            inside.append(line)
    return cells


def test_a_cell_that_draws_a_figure_shows_it():
    """Issue 39 item 12: the Roads page's transmissibility figure was missing,
    its cell ending in ``fig = ...figure()``: a cell shows only its last value.
    No guide cell ends by assigning a figure it then never shows."""
    hidden = []
    for page in sorted((DOCS / "guide").glob("*.md")):
        for cell in _code_cells(page):
            code = [ln for ln in cell if ln.strip() and not ln.lstrip().startswith(("#", ":"))]
            if not code:
                continue
            last = code[-1]
            if re.match(r"\s*\w+\s*=.*(figure\(|subplots\(|_figure\()", last):
                hidden.append(f"{page.name}: {last.strip()}")
    assert not hidden, hidden


@pytest.mark.slow
@pytest.mark.xdist_group("docs")
def test_the_site_loads_nothing_from_the_internet(site):
    """Issue 39 item 12: a generated timing page loaded jQuery from a CDN. No page
    of the built site has a script, style sheet or image from another host."""
    remote = re.compile(r'<(?:script|link|img)\b[^>]*(?:src|href)="(?:https?:)?//[^"]*"')
    found = []
    for page in sorted(site.rglob("*.html")):
        for tag in remote.findall(page.read_text(encoding="utf-8")):
            if "<link" in tag and 'rel="canonical"' in tag:
                continue
            found.append(f"{page.relative_to(site)}: {tag[:100]}")
    assert not found, found[:10]
