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


@pytest.fixture(scope="session")
def docs_build(tmp_path_factory, course_run):
    """The docs site built once per run (``sphinx-build -W``): the user guide
    (every cell executed), API reference, gallery and course notebook, from a
    copy of the sources so that the build's generated files stay out of the tree.

    The gallery runs every example here, with an output folder under the
    build directory (``docs/_build/gallery_output/NAME``); tests/test_examples.py
    reads what they wrote and printed. The course notebook is the one
    `course_run` executed, its outputs rendered as they are: myst-nb's
    per-notebook setting keeps the build from executing it again.
    Returns ``src`` (the copied docs folder), ``html``, ``returncode`` and
    ``stderr``.
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
    html = tmp / "docs" / "_build" / "html"
    run = subprocess.run(
        # -j auto: the pages and the examples are read and run on every core, which
        # the rest of the suite leaves idle once it has finished
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-j", "auto", "-b", "html"]
        + [str(tmp / "docs"), str(html)],
        capture_output=True,
        text=True,
        timeout=1800,
        env={"MPLBACKEND": "Agg", "PATH": str(Path(sys.executable).parent)},
    )
    return SimpleNamespace(
        src=tmp / "docs", html=html, returncode=run.returncode, stderr=run.stderr
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
