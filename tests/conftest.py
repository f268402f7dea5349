"""Shared fixtures and strategies."""

import copy
import os
import shutil
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

# Bytecode is written, whatever the shell says: uv installs the dependencies without
# compiling them, and where PYTHONDONTWRITEBYTECODE is set (this machine's shell, some
# CI images) every interpreter the suite starts (the xdist workers, each subprocess
# test, the docs build, the notebook's kernel) compiled numpy, scipy, control,
# matplotlib and pandas afresh. Set here, before they are imported, it reaches this
# process and, by the environment, every one it starts. Measured: importing what
# `qc-control report` needs costs 7.6-9.2 s of CPU without bytecode, 2.6 s with it.
sys.dont_write_bytecode = False
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)

import matplotlib  # noqa: E402
import pytest  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

matplotlib.use("Agg")  # no screen on CI

from qc_control import QuarterCarParams  # noqa: E402

#: Physically plausible vehicles, from a kart to a truck axle (SI units).
#: Damping is kept > 0 so every mode decays; cs = 0 is tested separately.
valid_params = st.builds(
    QuarterCarParams,
    ms=st.floats(50.0, 5000.0),
    mu=st.floats(10.0, 1000.0),
    ks=st.floats(5e3, 5e5),
    ku=st.floats(5e4, 5e6),
    zeta=st.floats(0.01, 2.0),
)

#: Doctests that run a whole comparison, by node id (a docstring can't carry a marker).
SLOW_DOCTESTS = {"qc_control/__init__.py::qc_control"}  # the quickstart: about 3 s


#: The course notebook, executed once per run (`course_run`).
COURSE = Path(__file__).parent.parent / "examples" / "course.ipynb"
#: The instructor's answers to the notebook's exercises, each computed with
#: qc_control as a student would.
SOLUTIONS = {
    "1": "answer_1 = qc.modal_analysis(params).body.fn",
    "2": 'answer_2 = qc.max_stable_step("euler", sys)',
    "3": """
e = []
for h in (0.01, 0.005):
    Th = np.linspace(0.0, 10.0, round(10.0 / h) + 1)
    r = qc.initial_response(sys, Th, X0, method="heun")
    ex = control.initial_response(sys, Th, X0)
    e.append(np.max(np.abs(output_signal(r, "xs") - output_signal(ex, "xs"))))
answer_3 = (e[1], np.log2(e[0] / e[1]))
""",
    "4": 'answer_4 = qc.numerical_modes("euler", 0.01, sys).loc["body bounce", "zeta_h"]',
    "5": "answer_5 = zetas[np.argmin(comfort)]",
    "6": """
def xs_error(m, n):  # the largest |xs| error of n steps over 10 s
    Th = np.linspace(0.0, 10.0, n + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = qc.initial_response(sys, Th, X0, method=m)
    ex = control.initial_response(sys, Th, X0)
    return np.max(np.abs(output_signal(r, "xs") - output_signal(ex, "xs"))), r.nfev

costs = {}
for m, tab in qc.METHODS.items():
    e, _ = xs_error(m, 1000)  # h = 0.01 s, inside every limit
    n = int(np.ceil(1000 * (e / 1e-3) ** (1 / tab.order)))  # e ~ C h^p
    e, nfev = xs_error(m, n)
    while e > 1e-3:  # the prediction confirmed, or the step shortened by 2 %
        n = int(np.ceil(n * 1.02))
        e, nfev = xs_error(m, n)
    costs[m] = (nfev, 10.0 / n)
best = min(costs, key=lambda m: costs[m][0])
answer_6 = (best, costs[best][1])
""",
}


@pytest.fixture(scope="session")
def course_run(tmp_path_factory):
    """The course notebook executed once, as a student runs it, in a fresh kernel.

    The shipped cells run first; then, in the same kernel, each exercise's
    answer (`SOLUTIONS`) and a copy of its check cell (tagged
    ``answered-check-N``), and a wrong answer to exercise 1 with its check
    (``wrong-check-1``). Returns ``shipped`` (the shipped cells with their
    outputs: what the docs render), ``answered`` (the whole executed
    notebook) and ``files_written`` (what the run left in its folder).
    """
    import nbformat

    nbclient = pytest.importorskip("nbclient", reason="the test extra is not installed")
    nb = nbformat.read(COURSE, as_version=4)
    n_shipped = len(nb.cells)
    checks = {}
    for cell in nb.cells:
        for tag in cell.get("metadata", {}).get("tags", []):
            if tag.startswith("check-"):
                checks[tag.removeprefix("check-")] = cell.source

    def cell(source, tag=None):
        new = nbformat.v4.new_code_cell(source.strip())
        if tag:
            new.metadata["tags"] = [tag]
        return new

    for n, code in SOLUTIONS.items():
        nb.cells += [cell(code), cell(checks[n], f"answered-check-{n}")]
    nb.cells += [
        cell("answer_1 = 2.0  # Hz: the wheel's, not the body's"),
        cell(checks["1"], "wrong-check-1"),
    ]
    folder = tmp_path_factory.mktemp("course")
    # at most 120 s per cell, in the notebook's own folder-less temporary directory
    nbclient.NotebookClient(
        nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(folder)}}
    ).execute()
    shipped = copy.deepcopy(nb)
    shipped.cells = shipped.cells[:n_shipped]
    return SimpleNamespace(
        shipped=shipped, answered=nb, files_written=sorted(p.name for p in folder.iterdir())
    )


#: The guide's kernels inherit this environment from the build (``docs/conf.py`` adds the
#: IProgress filter to PYTHONWARNINGS in the build's own process).
DOCS_ENV = {"MPLBACKEND": "Agg", "PATH": str(Path(sys.executable).parent)}


def guide_in_one_kernel(guide: Path, cache: Path, folder: Path, env: dict) -> list[str]:
    """Execute the guide's pages one after the other in one Jupyter kernel, into a
    jupyter-cache at ``cache`` that the docs build reads (``nb_execution_mode=cache``).

    ``make docs`` starts a kernel for each page; here one kernel runs them all,
    which saves each page's start (the kernel, and importing numpy, control,
    matplotlib, pandas and qc_control: about 3 s of CPU a page). Before each
    page the kernel forgets the namespace (``%reset -f``: a page that uses a
    name it did not define or import still fails), moves to a new empty
    folder of its own (as ``nb_execution_in_temp``) and forgets which warnings
    it has shown (each page shows its own). What it keeps is what a process
    keeps: the modules imported so far and their state (caches, matplotlib's
    rcParams; a submodule an earlier page imported is an attribute of its
    package). A page whose cells raise is left out of the cache, so the build
    runs it again in a kernel of its own and fails on it as ``make docs``
    does. Returns the pages cached.
    """
    import nbclient
    import nbformat
    from jupyter_cache import get_cache
    from jupyter_cache.base import CacheBundleIn
    from myst_nb.core.read import is_myst_markdown_notebook, read_myst_markdown_notebook
    from myst_parser.config.main import MdParserConfig

    config = MdParserConfig(enable_extensions={"dollarmath", "amsmath"})  # as docs/conf.py
    pages, merged = [], nbformat.v4.new_notebook()
    for path in sorted(guide.glob("*.md")):
        text = path.read_text(encoding="utf-8")
        if not is_myst_markdown_notebook(text):
            continue
        nb = read_myst_markdown_notebook(text, config=config, add_source_map=True, path=path)
        merged.metadata.setdefault("kernelspec", nb.metadata.get("kernelspec"))
        workdir = folder / path.stem
        workdir.mkdir()
        # `%reset` ends in two full garbage collections, which walk every object
        # the process holds: 200,000-300,000 once the pages have imported control,
        # pandas, Dask and Panel, 0.25-0.37 s of CPU a page. What survives the
        # reset (modules and their state) is then frozen, out of every later
        # collection, which so walks only what the last page made; that page's
        # own garbage is still collected at the next reset.
        merged.cells.append(
            nbformat.v4.new_code_cell(
                "%reset -f\n"
                f"__import__('os').chdir({str(workdir)!r})\n"
                "with __import__('warnings').catch_warnings():  # forgets the ones shown once\n"
                "    pass\n"
                "__import__('gc').freeze()"
            )
        )
        start = len(merged.cells)
        merged.cells += [c for c in nb.cells if c.cell_type == "code"]
        pages.append((path, nb, start))
    nbclient.NotebookClient(
        merged, timeout=300, allow_errors=True, record_timing=False,
        resources={"metadata": {"path": str(folder)}},
    ).execute(env=env)  # fmt: skip
    db = get_cache(str(cache))
    cached = []
    for path, nb, start in pages:
        code = [c for c in nb.cells if c.cell_type == "code"]
        ran = merged.cells[start : start + len(code)]
        failed = any(
            o.output_type == "error" and "raises-exception" not in c.metadata.get("tags", [])
            for c in ran
            for o in c.outputs
        )
        if failed:
            continue
        for n, (cell, done) in enumerate(zip(code, ran), 1):
            cell.outputs, cell.execution_count = done.outputs, n
        nb.metadata["language_info"] = merged.metadata.get("language_info", {})
        db.cache_notebook_bundle(CacheBundleIn(nb, str(path)), check_validity=False)
        cached.append(path.stem)
    return cached


@pytest.fixture(scope="session")
def docs_build(tmp_path_factory, course_run):
    """The docs site built once per run (``sphinx-build -W``): the user guide
    (every cell executed), API reference, gallery and course notebook, from a
    copy of the sources so that the build's generated files stay out of the tree.

    The gallery runs every example here, with an output folder under the
    build directory (``docs/_build/gallery_output/NAME``); tests/test_examples.py
    reads what they wrote and printed. The course notebook is the one
    `course_run` executed, its outputs rendered as they are: myst-nb's
    per-notebook setting keeps the build from executing it again. The guide's
    pages run one after the other in one kernel (`guide_in_one_kernel`), and
    the build renders their outputs from that run: this is the one difference
    from ``make docs``, which gives each page a kernel of its own.
    Returns ``src`` (the copied docs folder), ``html``, ``returncode``,
    ``stderr``, ``cached`` (the guide's pages that ran in the shared kernel)
    and ``executed_by_build`` (those the build ran in a kernel of their own).
    """
    for name in ("sphinx", "numpydoc", "sphinx_gallery", "myst_nb"):
        pytest.importorskip(name, reason="the docs extra is not installed: `make docs` installs it")
    import nbformat

    root = Path(__file__).parent.parent
    tmp = tmp_path_factory.mktemp("site")
    ignore = shutil.ignore_patterns(
        "_build", "auto_examples", "notebooks", "sg_execution_times.rst", "*_output"
    )
    shutil.copytree(root / "docs", tmp / "docs", ignore=ignore)
    shutil.copytree(root / "examples", tmp / "examples", ignore=ignore)
    shutil.copytree(root / "benchmarks", tmp / "benchmarks", ignore=ignore)  # Performance page
    executed = copy.deepcopy(course_run.shipped)
    executed.metadata["mystnb"] = {"execution_mode": "off"}
    nbformat.write(executed, tmp / "examples" / "course.ipynb")
    env = dict(DOCS_ENV, PYTHONWARNINGS="ignore:IProgress not found")  # as docs/conf.py
    cache = tmp / "guide_cache"
    pages = tmp_path_factory.mktemp("guide_pages")
    cached = guide_in_one_kernel(tmp / "docs" / "guide", cache, pages, env)
    html = tmp / "docs" / "_build" / "html"
    run = subprocess.run(
        # -j auto: the pages and the examples are read and run on every core, which
        # the rest of the suite leaves idle once it has finished
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-j", "auto", "-b", "html"]
        + ["-D", "nb_execution_mode=cache", "-D", f"nb_execution_cache_path={cache}"]
        + [str(tmp / "docs"), str(html)],
        capture_output=True,
        text=True,
        timeout=1800,
        env=DOCS_ENV,
    )
    from jupyter_cache import get_cache

    # a page the cache did not hold, the build executed and recorded in the cache's project
    executed_by_build = [Path(r.uri).stem for r in get_cache(str(cache)).list_project_records()]
    return SimpleNamespace(
        src=tmp / "docs",
        html=html,
        returncode=run.returncode,
        stderr=run.stderr,
        cached=cached,
        executed_by_build=executed_by_build,
    )


def gallery_run(docs_build, name: str) -> tuple[str, Path]:
    """What example ``name`` printed in the docs build, and the folder it wrote.

    The gallery runs every example once per run of the suite (`docs_build`);
    a test of an example reads that run rather than running it again.
    """
    assert docs_build.returncode == 0, docs_build.stderr[-5000:]
    page = (docs_build.src / "auto_examples" / f"{name}.rst").read_text(encoding="utf-8")
    return printed_blocks(page), docs_build.src / "_build" / "gallery_output" / name


def printed_blocks(page: str) -> str:
    """The captured stdout of a gallery page: its output blocks, dedented and joined.

    sphinx-gallery writes each block's stdout under ``.. rst-class::
    sphx-glr-script-out`` as a ``code-block`` indented by 4 spaces.
    """
    lines = []
    for block in page.split(".. rst-class:: sphx-glr-script-out")[1:]:
        body = block.split(".. code-block:: none\n", 1)[1].splitlines()[1:]
        for line in body:
            if line and not line.startswith("    "):
                break
            lines.append(line[4:])
        while lines and not lines[-1]:
            lines.pop()
    return "\n".join(lines) + "\n"


@pytest.fixture
def seed_params():
    return QuarterCarParams()


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def pytest_configure(config):
    os.environ.setdefault("MPLBACKEND", "Agg")


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.nodeid in SLOW_DOCTESTS:
            item.add_marker(pytest.mark.slow)
