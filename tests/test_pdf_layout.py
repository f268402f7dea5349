"""The PDF's pages as a lecturer prints them: no heading stranded at the foot
of a page, no page left half empty because a figure was kept with what
follows, a matrix's columns aligned.

The checks read the layout decisions `qc_control.report.pdf._render` records
for each page (`PageRecord`): the blocks drawn on it, the fraction of the
text area it fills, and what the piece that opened the next page needed
against the room that was left. Small block lists with figures of known size
test each rule; one half-car report tests them together.
"""

import numpy as np
import pandas as pd
import pytest
from PIL import Image as PILImage
from reports_shared import HALF_CAR_GROUP, half_car_report

from qc_control.report import build_blocks, figure_specs, pdf
from qc_control.report.comparison import _matrix
from qc_control.report.document import Code, Heading, Image, Paragraph, Table


def figure(folder, name: str, w_px: int = 1200, h_px: int = 900) -> Image:
    """A PNG of the report's kind (150 dpi) on disk, and its block."""
    PILImage.new("RGB", (w_px, h_px), "white").save(folder / name, dpi=(150, 150))
    return Image(name, f"A figure {w_px} x {h_px} px")


def lines(n: int) -> Paragraph:
    """A paragraph of ``n`` lines (one per line break; none is wrapped)."""
    return Paragraph("\n".join(f"line {i}" for i in range(n)))


def render(tmp_path, blocks) -> list:
    return pdf._render("Layout", blocks, tmp_path, tmp_path / "layout.pdf")


def page_of(records, index: int) -> int:
    """The page on which block ``index`` starts."""
    return next(r.number for r in records if index in r.blocks)


def left_after(tmp_path, blocks) -> float:
    """Height [in] left on the first page after ``blocks``."""
    (page,) = render(tmp_path, blocks)
    return (1 - page.fill) * pdf._TEXT_H


def test_a_heading_goes_to_the_next_page_with_its_introduction_and_figure(tmp_path):
    """The issue's "heading stranded at the foot of page 2": a heading and its
    one-line introduction fit, the figure they introduce does not; all three
    open the next page together."""
    image = figure(tmp_path, "tall.png")  # 5.0 in at the text width, 4.0 in at its smallest
    filler = lines(36)
    assert 1.0 < left_after(tmp_path, [filler]) < 3.5  # room for the heading, not the figure
    blocks = [filler, Heading("Per-method responses"), Paragraph("Figures 3–6 below."), image]
    records = render(tmp_path, blocks)
    assert [r.blocks for r in records] == [[-1, 0], [1, 2, 3]]
    assert records[0].needed > records[0].room  # it was the heading's company that did not fit


def test_a_figure_that_does_not_fit_floats_and_its_sections_text_fills_the_page(tmp_path):
    """A figure too tall for the rest of a page goes to the top of the next;
    the text and table after it in its section fill the space meanwhile, and
    the next section's heading comes after the figure, never before it."""
    image = figure(tmp_path, "tall.png")
    table = Table(pd.DataFrame({"x [m]": [1.0, 2.0]}, index=["a", "b"]), "Small")
    smallest = pdf._Writer(pdf._Pages(None, ""), tmp_path)._image_height(
        image, pdf._MIN_FIGURE_SCALE
    )
    assert 2.0 < left_after(tmp_path, [lines(30)]) < smallest  # room, but not for the figure
    blocks = [lines(30), image, lines(3), table, Heading("Next section"), lines(2)]
    records = render(tmp_path, blocks)
    assert page_of(records, 2) == page_of(records, 3) == 1  # text and table fill page 1
    assert records[1].blocks[0] == 1  # the figure opens page 2 ...
    assert page_of(records, 4) == 2 and records[1].blocks.index(4) > 0  # ... above the heading


def test_a_figure_that_nearly_fits_is_drawn_a_little_smaller_in_place(tmp_path):
    """Rather than leave the rest of the page empty, a figure that fits at
    `_MIN_FIGURE_SCALE` of its size or more is drawn there at that size."""
    image = figure(tmp_path, "tall.png")
    writer_probe = pdf._Writer(pdf._Pages(None, ""), tmp_path)
    full = writer_probe._image_height(image)
    smallest = writer_probe._image_height(image, pdf._MIN_FIGURE_SCALE)
    n = 0
    while left_after(tmp_path, [lines(n + 1)]) > (full + smallest) / 2:
        n += 1
    assert smallest < left_after(tmp_path, [lines(n)]) < full  # fits only smaller
    records = render(tmp_path, [lines(n), image, Heading("After")])
    assert page_of(records, 1) == 1


def test_a_matrix_keeps_its_leading_spaces_so_its_columns_line_up(tmp_path, monkeypatch):
    """The issue's "A's rows are misaligned": the PDF dropped each row's leading
    spaces, so right-aligned columns no longer lined up. Each drawn line is
    now the printed line itself, in a fixed-width font."""
    A = np.array([[-3.9863, 2.21462, 1.76712], [1.31437, -5.35353, 1.06032], [1, 0, 0]])
    text = _matrix("A", A)
    drawn = []
    original = pdf._Pages.text

    def spy(self, x, y, s, font, **kw):
        if font.family == "monospace":
            drawn.append(s)
        return original(self, x, y, s, font, **kw)

    monkeypatch.setattr(pdf._Pages, "text", spy)
    render(tmp_path, [Code(text)])
    assert drawn == text.split("\n")
    rows = drawn[1:]
    assert rows[0].startswith(" ") and len({len(r) for r in rows}) == 1  # right-aligned


@pytest.fixture(scope="module")
def half_car_pages(tmp_path_factory):
    """The README's half car over a bump (2 s of it), its PDF laid out from the
    figures its report drew (shared with tests/test_html_browser.py)."""
    cmp, folder = half_car_report(tmp_path_factory)
    for spec in figure_specs(cmp):  # every figure, drawn at the report's 150 dpi
        with PILImage.open(folder / spec.name) as png:
            assert png.info["dpi"] == pytest.approx((150, 150), abs=0.1), spec.name  # px/m, rounded
    blocks = build_blocks(cmp, "qc-control report --model half --road bump --speed 10")
    out = tmp_path_factory.mktemp("pdf-half") / "report.pdf"
    return blocks, pdf._render("Half car", blocks, folder, out)


#: No page but the last is filled less than this: none is half empty.
MIN_FILL = 0.5


@pytest.mark.slow  # the comparison and its figures: about 8 s
@pytest.mark.xdist_group(HALF_CAR_GROUP)  # the half car's report, written once per suite
def test_the_half_car_report_has_no_half_empty_page_and_no_stranded_heading(half_car_pages):
    """Every page but the last is at least `MIN_FILL` full, and a page ends
    early only because what came next was taller than the room left; each
    heading shares its page with the start of its section (beyond a short
    introduction), never ending a page."""
    blocks, records = half_car_pages
    assert len(records) > 3
    for page in records[:-1]:
        assert page.fill >= MIN_FILL, page
        assert page.needed > page.room, page  # the next piece did not fit
        assert not isinstance(blocks[page.blocks[-1]], Heading), page
    for i, block in enumerate(blocks):
        if not isinstance(block, Heading):
            continue
        section = []
        for later in range(i + 1, len(blocks)):
            if isinstance(blocks[later], Heading):
                break
            section.append(later)
        content = [j for j in section if not _short(blocks[j])] or section
        if content:
            here = page_of(records, i)
            assert any(j in records[here - 1].blocks for j in content), (block.text, here)


def _short(block) -> bool:
    return isinstance(block, Paragraph) and len(block.text) < 400
