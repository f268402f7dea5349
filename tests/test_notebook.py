"""The course notebook runs from top to bottom, and its exercise checks work.

Executed once per run with nbclient in a fresh kernel, as a student runs
it (the ``course_run`` fixture of ``conftest.py``): the notebook as shipped
(every check says "not answered yet"), then, in the same kernel, each
exercise's answer followed by its check (every check says "correct") and a
wrong answer (refused). The docs build renders the shipped cells of this
same run (tests/test_docs.py), so the notebook is executed once, not three
times. The checks live in `qc_control.studies.exercises` (tested against
independent references in ``tests/test_exercises.py``); the answers in
``conftest.SOLUTIONS`` are computed with qc_control as a student would.
"""

import nbformat
import pytest
from conftest import COURSE, SOLUTIONS

NOTEBOOK = COURSE
SECTIONS = [
    "## 1. The model and its modes",
    "## 2. The four methods",
    "## 3. Errors and orders",
    "## 4. Stability limits and numerical damping",
    "## 5. Roads and comfort",
    "## Exercises",
]
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("docs")]


def tagged(nb, tag):
    return [c for c in nb.cells if tag in c.get("metadata", {}).get("tags", [])]


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


def test_runs_as_shipped_and_every_check_waits_for_an_answer(course_run):
    nb = course_run.shipped
    errors = [o for c in nb.cells for o in c.get("outputs", []) if o.output_type == "error"]
    assert not errors
    images = [o for c in nb.cells for o in c.get("outputs", []) if "image/png" in o.get("data", {})]
    assert len(images) >= 5  # every section draws
    for n in SOLUTIONS:
        (check,) = tagged(nb, f"check-{n}")
        assert printed(check).strip() == f"Exercise {n}: not answered yet"
    assert course_run.files_written == []  # it writes no files


def test_the_checks_accept_right_answers_and_refuse_a_wrong_one(course_run):
    answered = course_run.answered
    for n in SOLUTIONS:
        (check,) = tagged(answered, f"answered-check-{n}")
        assert printed(check).strip() == f"Exercise {n}: correct", printed(check)
    (wrong,) = tagged(answered, "wrong-check-1")
    assert printed(wrong).startswith("Exercise 1: not yet.")
