"""Report layout a lecturer would print: matrices that stay aligned on paper
and on a phone, and no empty "B = []" on a free response."""

import re

import numpy as np
import pytest
from qc_control.road import Bump
from reports_shared import run_untimed

from qc_control.report.comparison import _matrix, _system_blocks
from qc_control.report.document import _CSS, Code
from qc_control.studies.scenario import Scenario


def parse(text: str, shape) -> np.ndarray:
    """The matrix back from its printed blocks of columns."""
    out = np.full(shape, np.nan)
    start = 0
    for block in text.split("\n\n"):
        head, *rows = block.splitlines()
        cols = re.search(r"columns (\d+)–(\d+)", head)
        start, stop = (int(cols[1]) - 1, int(cols[2])) if cols else (0, shape[1])
        for i, row in enumerate(rows):
            out[i, start:stop] = [float(v) for v in row.split()]
    return out


@pytest.mark.parametrize("model", ["quarter", "half", "full"])
def test_a_matrix_prints_in_aligned_blocks_that_fit_the_page(model):
    sc = Scenario(model=model, road=Bump(speed=10.0))
    A = np.asarray(sc.entry.model(sc.vehicle, road=True).system.A)
    text = _matrix("A", A)
    for block in text.split("\n\n"):
        rows = block.splitlines()[1:]
        assert len(rows) == A.shape[0]  # one line per row: never wrapped
        assert len({len(r) for r in rows}) == 1  # right-aligned columns
        assert all(len(line) <= 96 for line in block.splitlines())  # the PDF's code width
    # six significant digits: the printed entries are A's to 5e-6 relative
    np.testing.assert_allclose(parse(text, A.shape), A, rtol=5e-6, atol=1e-12 * abs(A).max())


@pytest.fixture(scope="module")
def free_response():
    """The seed's car released from 5 cm for 1 s (no wall times: none is read here)."""
    return run_untimed(Scenario(t_end=1.0))


def test_a_free_response_shows_no_empty_b(free_response):
    cmp = free_response
    (code,) = [b for b in _system_blocks(cmp) if isinstance(b, Code)]
    assert "A =" in code.text and "B" not in code.text


def test_a_forced_response_shows_b():
    cmp = run_untimed(Scenario(road=Bump(), t_end=1.0, methods=["rk4"]))
    (code,) = [b for b in _system_blocks(cmp) if isinstance(b, Code)]
    assert "\nB =\n" in code.text


def test_preformatted_text_scrolls_rather_than_wraps_a_row():
    assert re.search(r"pre \{[^}]*white-space: pre;", _CSS)


@pytest.mark.slow  # a whole report with its PDF: about 4 s
def test_a_wide_table_in_the_pdf_splits_into_column_groups_not_below_7_pt(tmp_path, monkeypatch):
    import pandas as pd

    from qc_control.report import pdf
    from qc_control.report.document import Table

    sizes, parts = [], []
    original = pdf._Writer._table_part

    def spy(self, caption, cols, head, body, numeric, widths, headers, font, bold):
        sizes.append(font.size)
        parts.append(caption)
        return original(self, caption, cols, head, body, numeric, widths, headers, font, bold)

    monkeypatch.setattr(pdf._Writer, "_table_part", spy)
    # 24 columns of 9-digit numbers: wider than an A4 page at any legible size
    frame = pd.DataFrame(
        np.arange(72 * 24, dtype=float).reshape(72, 24) * 1234.56789,
        columns=[f"column {j} [m]" for j in range(24)],
    )
    pdf.to_pdf("wide", [Table(frame, "A wide table")], tmp_path, tmp_path / "w.pdf")
    assert len(parts) > 1 and all(p.startswith("A wide table (columns") for p in parts)
    assert min(sizes) >= 7.0


def test_coinciding_methods_are_described_in_words_not_symbols(free_response):
    from qc_control.report.findings import _coincidence

    (text,) = _coincidence(free_response)
    # the wording: "largest state difference 0 m, which is rounding" and "T_2(hA)"
    assert "which is rounding" not in text and "T_2" not in text
    assert "identical to the last bit" in text  # Midpoint and Heun: bit for bit on a free response
    assert "x ← (I + hA + (hA)^2/2)·x" in text


@pytest.mark.parametrize(
    "model, title",
    [
        ("quarter", "Quarter car: fixed-step methods against the exact response"),
        ("half", "Half car: fixed-step methods against the exact response"),
        ("full", "Full car: fixed-step methods against the exact response"),
        ("nonlinear", "Nonlinear quarter car: fixed-step methods against a solve_ivp reference"),
    ],
)
def test_the_title_names_the_vehicle_and_its_reference(model, title):
    """The issue: a half-car report was titled "Quarter car"; a nonlinear run,
    measured against solve_ivp, was said to be against "the exact response"."""
    from types import SimpleNamespace

    from qc_control.report import report_title

    sc = Scenario(model=model, road=Bump(speed=10.0))
    vehicle = sc.entry.model(sc.vehicle, road=True)
    study = object() if model == "nonlinear" else None  # what a nonlinear comparison carries
    assert report_title(SimpleNamespace(model=vehicle, nonlinear=study)) == title
