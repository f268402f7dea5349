"""The course notebook runs from top to bottom, and its exercise checks work.

Executed with nbclient in a fresh kernel, as a student runs it: once as
shipped (every check says "not answered yet"), and once with the answers
filled in (every check says "correct", and a wrong answer is refused).
The checks live in `qc_control.studies.exercises` (tested against
independent references in ``tests/test_exercises.py``); here the answers are
computed with qc_control as a student would.
"""

from pathlib import Path

import nbformat
import pytest

nbclient = pytest.importorskip("nbclient", reason="the test extra (nbclient) is not installed")

NOTEBOOK = Path(__file__).parent.parent / "examples" / "course.ipynb"
SECTIONS = [
    "## 1. The model and its modes",
    "## 2. The four methods",
    "## 3. Errors and orders",
    "## 4. Stability limits and numerical damping",
    "## 5. Roads and comfort",
    "## Exercises",
]
#: The instructor's answers, each computed with qc_control as a student would.
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

pytestmark = pytest.mark.slow


def tagged(nb, tag):
    return [c for c in nb.cells if tag in c.get("metadata", {}).get("tags", [])]


def execute(nb, tmp_path):
    """Run every cell in a fresh kernel, in ``tmp_path``; at most 120 s per cell."""
    client = nbclient.NotebookClient(
        nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    return nb


def printed(cell) -> str:
    return "".join(o.get("text", "") for o in cell.get("outputs", []) if o.output_type == "stream")


def test_the_notebook_walks_the_seed_paper_and_is_stored_clean():
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbformat.validate(nb)
    text = "\n".join(c.source for c in nb.cells if c.cell_type == "markdown")
    positions = [text.index(s) for s in SECTIONS]
    assert positions == sorted(positions)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert all(not c.outputs and c.execution_count is None for c in code)  # no stale outputs
    for n in SOLUTIONS:  # each exercise: an answer cell, then its check cell
        (answer,) = tagged(nb, f"answer-{n}")
        (check,) = tagged(nb, f"check-{n}")
        assert nb.cells.index(check) == nb.cells.index(answer) + 1
        assert answer.source.strip() == f"answer_{n} = None"


def test_runs_as_shipped_and_every_check_waits_for_an_answer(tmp_path):
    nb = execute(nbformat.read(NOTEBOOK, as_version=4), tmp_path)
    errors = [o for c in nb.cells for o in c.get("outputs", []) if o.output_type == "error"]
    assert not errors
    images = [o for c in nb.cells for o in c.get("outputs", []) if "image/png" in o.get("data", {})]
    assert len(images) >= 5  # every section draws
    for n in SOLUTIONS:
        (check,) = tagged(nb, f"check-{n}")
        assert printed(check).strip() == f"Exercise {n}: not answered yet"
    assert list(tmp_path.iterdir()) == []  # it writes no files


def test_the_checks_accept_right_answers_and_refuse_a_wrong_one(tmp_path):
    nb = nbformat.read(NOTEBOOK, as_version=4)
    for n, code in SOLUTIONS.items():
        (answer,) = tagged(nb, f"answer-{n}")
        answer.source = code.strip()
    (check_1,) = tagged(nb, "check-1")
    nb.cells += [
        nbformat.v4.new_code_cell("answer_1 = 2.0  # Hz: the wheel's, not the body's"),
        nbformat.v4.new_code_cell(check_1.source),
    ]
    nb = execute(nb, tmp_path)
    for n in SOLUTIONS:
        (check,) = tagged(nb, f"check-{n}")
        assert printed(check).strip() == f"Exercise {n}: correct", printed(check)
    assert printed(nb.cells[-1]).startswith("Exercise 1: not yet.")
