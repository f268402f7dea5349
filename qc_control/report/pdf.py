"""The report as a PDF, drawn with matplotlib alone (no browser, no LaTeX).

Every page is a matplotlib `Figure` of A4 size written through
`matplotlib.backends.backend_pdf.PdfPages`. Text is laid out here: words
are measured with matplotlib's own font metrics (the fonts the PDF embeds)
and wrapped greedily; tables are drawn as ruled grids, split across pages
(header repeated) and, when too wide, across column groups (index
repeated); figures are the report's PNGs, embedded at their own
resolution. The text stays text: it can be searched and copied.

Pages are filled as a typesetter would: a heading stays with the start of
its section; a figure that does not fit the rest of a page is drawn a little
smaller there, or floats to the top of the next page while the text and
tables of its section fill the space (never past the section's end); a short
table or matrix is not split. `_render` records each page's decisions
(`PageRecord`) for the tests.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import RendererAgg
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.patches import Rectangle
from PIL import Image as PILImage  # matplotlib's own dependency

from .document import Code, Heading, Image, Paragraph, Table, caption_text, table_cells

__all__ = ["to_pdf"]

_PAGE_W, _PAGE_H = 8.27, 11.69  # A4 [in]
_LEFT, _RIGHT, _TOP, _BOTTOM = 0.8, 0.8, 0.8, 0.85  # margins [in]
_WIDTH = _PAGE_W - _LEFT - _RIGHT
_PT = 1 / 72  # inch per point

_BODY, _SMALL, _CODE = 9.5, 8.5, 7.5  # font sizes [pt]
_TABLE_SIZES = (8.0, 7.5, 7.0)  # tried in turn; a table wider still splits into column groups,
# never below 7 pt, the smallest size legible on a printed page
_CELL_PAD = 3.0  # [pt] either side of a cell's text
_HEADING_SIZES = {1: 17.0, 2: 13.0}  # [pt]; 11 pt below
#: A figure that does not fit the rest of a page is drawn smaller to fit there,
#: down to this fraction of its full size (its smallest text, 8.3 pt on the
#: 8-inch figure, is 6.9 pt at the text width and 5.5 pt at 0.8 of it); smaller
#: than that it goes to the next page.
_MIN_FIGURE_SCALE = 0.8
_FIGURE_PAD = 0.08 + 0.06 + 10 * _PT  # [in] above the image, above and below its caption
_SHORT_INTRO = 4  # lines: a paragraph this short introduces what follows it
_KEEP_CODE = 30  # lines: a matrix this long is never split across pages
_KEEP_ROWS = 12  # a table this long is never split across pages


@dataclass(frozen=True)
class _Font:
    size: float
    family: str = "sans-serif"
    weight: str = "normal"
    style: str = "normal"

    @property
    def prop(self) -> FontProperties:
        style: Any = self.style  # 'normal' or 'italic': FontProperties wants the literal
        return FontProperties(family=self.family, size=self.size, weight=self.weight, style=style)


class _Measure:
    """Text widths [pt] from the Agg renderer, whose font metrics the PDF uses too."""

    def __init__(self):
        self._renderer = RendererAgg(100, 100, 72)  # 72 dpi: pixels are points
        self._cache: dict = {}

    def width(self, text: str, font: _Font) -> float:
        key = (text, font)
        if key not in self._cache:
            w, _, _ = self._renderer.get_text_width_height_descent(text, font.prop, ismath=False)
            self._cache[key] = float(w)
        return self._cache[key]

    def wrap(self, text: str, font: _Font, width_pt: float) -> list[str]:
        """Greedy word wrap; a word wider than the line is cut where it must be.

        A line's width is taken as the sum of its words' and spaces' widths
        (each measured once), which ignores kerning across a space: the
        line is kept 2 % short of ``width_pt`` to make up for it.
        """
        limit = 0.98 * width_pt
        space = self.width(" ", font)
        lines: list[str] = []
        for para in text.split("\n"):
            line, used = "", 0.0
            for word in para.split(" "):
                w = self.width(word, font)
                if line and used + space + w <= limit:
                    line, used = f"{line} {word}", used + space + w
                    continue
                if line:
                    lines.append(line)
                while w > limit and len(word) > 1:
                    cut = len(word) - 1
                    while cut > 1 and self.width(word[:cut], font) > limit:
                        cut -= 1
                    lines.append(word[:cut])
                    word = word[cut:]
                    w = self.width(word, font)
                line, used = word, w
            lines.append(line)
        return lines


@dataclass
class PageRecord:
    """How one page was filled: the layout decisions, for checking them.

    ``fill`` is the fraction of the text area's height used; ``blocks`` the
    indices of the blocks drawn on the page, in order (-1: the title);
    ``needed`` and ``room`` [in] what the piece that opened the next page
    asked for and what was left, when a piece did not fit (else 0 and 0).
    """

    number: int
    blocks: list[int]
    fill: float = 0.0
    needed: float = 0.0
    room: float = 0.0


#: Height [in] of the text area of a page.
_TEXT_H = _PAGE_H - _TOP - _BOTTOM


class _Pages:
    """Pages filled from the top down; a new page when a piece does not fit."""

    def __init__(self, pdf: PdfPages, footer: str):
        self.pdf, self.footer = pdf, footer
        self.fig: Figure | None = None
        self.y = 0.0  # the next free height [in] from the bottom of the page
        self.number = 0
        self.block = -1  # the index of the block being drawn
        self.records: list[PageRecord] = []
        self.on_new_page: Callable[[], None] | None = None  # the writer's deferred figures

    def drawing(self) -> None:
        """Note that the current block puts ink on this page."""
        blocks = self.records[-1].blocks
        if not blocks or blocks[-1] != self.block:
            blocks.append(self.block)

    def _finish(self):
        if self.fig is not None:
            self.records[-1].fill = (_PAGE_H - _TOP - self.y) / _TEXT_H
            self.fig.text(
                0.5,
                0.45 / _PAGE_H,
                f"{self.footer} — page {self.number}",
                ha="center",
                va="bottom",
                fontsize=7.5,
                color="0.4",
                parse_math=False,
            )
            self.pdf.savefig(self.fig)
        self.fig = None

    def new_page(self, needed: float = 0.0):
        if self.records:
            self.records[-1].needed, self.records[-1].room = needed, self.y - _BOTTOM
        self._finish()
        self.fig = Figure(figsize=(_PAGE_W, _PAGE_H))
        self.number += 1
        self.records.append(PageRecord(self.number, []))
        self.y = _PAGE_H - _TOP
        if self.on_new_page is not None:
            self.on_new_page()

    @property
    def at_top(self) -> bool:
        return self.y >= _PAGE_H - _TOP - 1e-9

    def left(self) -> float:
        """Height [in] left on this page."""
        return self.y - _BOTTOM

    def room(self, height: float) -> None:
        """Make sure ``height`` inches fit below the current position."""
        if self.fig is None or self.y - height < _BOTTOM:
            if self.fig is not None and self.at_top:
                return  # already at the top of a page: taller than a page, draw anyway
            self.new_page(height)

    def text(self, x: float, y: float, s: str, font: _Font, **kw):
        assert self.fig is not None
        self.drawing()
        self.fig.text(
            x / _PAGE_W,
            y / _PAGE_H,
            s,
            fontsize=font.size,
            family=font.family,
            weight=font.weight,
            style=font.style,
            parse_math=False,
            **kw,
        )

    def rect(self, x: float, y: float, w: float, h: float, **kw):
        assert self.fig is not None
        self.drawing()
        self.fig.add_artist(
            Rectangle(
                (x / _PAGE_W, y / _PAGE_H),
                w / _PAGE_W,
                h / _PAGE_H,
                transform=self.fig.transFigure,
                **kw,
            )
        )

    def close(self):
        self._finish()


class _Writer:
    """Draws the blocks in order, but for a figure that does not fit the rest of its
    page: that one floats to the top of the next page, and the text and tables of
    its section that follow fill the space meanwhile (never past its section's end:
    a figure is never printed under the next heading)."""

    def __init__(self, pages: _Pages, image_dir: Path):
        self.pages, self.image_dir, self.m = pages, image_dir, _Measure()
        self.deferred: list[tuple[int, Image]] = []  # (block index, figure), in order
        self._flushing = False
        pages.on_new_page = self.flush

    def flush(self) -> None:
        """Draw the deferred figures, in order, from the top of the page just opened."""
        if self._flushing or not self.deferred:
            return
        self._flushing, current = True, self.pages.block
        while self.deferred:
            self.pages.block, block = self.deferred.pop(0)
            self._draw_image(block, 1.0)
        self._flushing, self.pages.block = False, current

    def finish(self) -> None:
        """The figures still deferred at the end, on a page of their own."""
        if self.deferred:
            self.pages.new_page(self._image_height(self.deferred[0][1]))

    # text -----------------------------------------------------------------
    def lines(self, text: str, font: _Font, *, before=0.0, after=4.0, keep=2, color="0.1"):
        """Wrapped lines; ``keep`` lines at least stay together with what precedes."""
        lines = self.m.wrap(text, font, _WIDTH / _PT)
        step = 1.35 * font.size * _PT
        self.pages.room(before * _PT + min(keep, len(lines)) * step)
        if not self.pages.at_top:
            self.pages.y -= before * _PT
        for line in lines:
            self.pages.room(step)
            self.pages.text(_LEFT, self.pages.y, line, font, va="top", color=color)
            self.pages.y -= step
        self.pages.y -= after * _PT

    def heading(self, text: str, level: int, following=()):
        """A heading, kept on one page with what opens its section (`keep_height`)."""
        size = _HEADING_SIZES.get(level, 11.0)
        if self.deferred:  # the previous section's floating figures come first
            self.pages.new_page(self._image_height(self.deferred[0][1]))
        self.pages.room(self._heading_height(text, level) + self.keep_height(following))
        self.lines(text, _Font(size, weight="bold"), before=14, after=5, color="0.05")

    def _heading_height(self, text: str, level: int) -> float:
        font = _Font(_HEADING_SIZES.get(level, 11.0), weight="bold")
        return (19 + 1.35 * font.size * len(self.m.wrap(text, font, _WIDTH / _PT))) * _PT

    def keep_height(self, following) -> float:
        """Height [in] of what must not be parted from a heading: the start of what
        follows (three lines of text; a figure whole, at its smallest; a table's
        caption, header and three rows), and when that is a short introduction
        (`_SHORT_INTRO` lines or fewer) to a figure or table, the start of that
        too; a sub-heading and its own start likewise.
        Without this a heading and its one-line introduction end a page whose
        section starts on the next: stranded."""
        height = 0.0
        for k, block in enumerate(following):
            if isinstance(block, Heading):
                height += self._heading_height(block.text, block.level)
                continue
            if isinstance(block, Paragraph):
                n = len(self.m.wrap(block.text, _Font(_BODY), _WIDTH / _PT))
                height += min(n, 3) * 1.35 * _BODY * _PT + 6 * _PT
                after = following[k + 1 : k + 2]
                # a short paragraph before a figure or table introduces it: keep both
                if n <= _SHORT_INTRO and after and isinstance(after[0], (Image, Table, Code)):
                    continue
            elif isinstance(block, Image):
                figure = self._image_height(block, _MIN_FIGURE_SCALE)
                after = following[k + 1 : k + 2]
                # a figure that may float lets the heading keep company with what follows it
                height += min(figure, self._start(after[0])) if _floats(after) else figure
            else:
                height += self._start(block)
            break
        return height

    def _start(self, block) -> float:
        """Height [in] of the start of a table, code or paragraph (three lines)."""
        if isinstance(block, Table):
            return self._table_start_height(block)
        if isinstance(block, Code):
            return 3 * 1.3 * _CODE * _PT
        return 3 * 1.35 * _BODY * _PT + 6 * _PT

    # figures --------------------------------------------------------------
    def _image_size(self, block: Image, scale: float = 1.0) -> tuple[float, float, float]:
        """(width, height, caption height) [in] of a figure as it will be drawn,
        ``scale`` times its full size (the text width, or a page's height)."""
        with PILImage.open(self.image_dir / block.path) as png:
            w_px, h_px = png.size
        cap = self.m.wrap(caption_text(block), _Font(_SMALL, style="italic"), _WIDTH / _PT)
        cap_h = len(cap) * 1.35 * _SMALL * _PT
        width, height = _WIDTH, _WIDTH * h_px / w_px
        most = _TEXT_H - cap_h - 0.3
        if height > most:
            width, height = width * most / height, most
        return scale * width, scale * height, cap_h

    def _image_height(self, block: Image, scale: float = 1.0) -> float:
        """Everything a figure takes [in]: the image, its caption, the space around."""
        _, height, cap_h = self._image_size(block, scale)
        return height + _FIGURE_PAD + cap_h

    def image(self, block: Image, index: int, following=()):
        """A figure at the text width. When it does not fit the rest of the page: as
        large as fits there if that is `_MIN_FIGURE_SCALE` of its size or more;
        else, when text or a table of its section follows, it floats to the top of
        the next page while they fill the space; else it opens the next page."""
        p = self.pages
        if self.deferred:  # figures keep their order
            self.deferred.append((index, block))
            return
        scale = 1.0
        if p.fig is not None and not p.at_top and self._image_height(block) > p.left():
            _, full, cap_h = self._image_size(block)
            fits = (p.left() - _FIGURE_PAD - cap_h - 1e-6) / full  # 1e-6 in: rounding
            if fits >= _MIN_FIGURE_SCALE:
                scale = fits
            elif _floats(following):
                self.deferred.append((index, block))
                return
        self._draw_image(block, scale)

    def _draw_image(self, block: Image, scale: float):
        p = self.pages
        width, height, cap_h = self._image_size(block, scale)
        p.room(height + _FIGURE_PAD + cap_h)
        with PILImage.open(self.image_dir / block.path) as png:
            pixels = np.asarray(png.convert("RGB"))  # 8-bit: embedded as it is
        y0 = p.y - 0.08 - height
        x0 = _LEFT + (_WIDTH - width) / 2
        assert p.fig is not None  # room() has opened a page
        p.drawing()
        ax = p.fig.add_axes((x0 / _PAGE_W, y0 / _PAGE_H, width / _PAGE_W, height / _PAGE_H))
        # 'none': vector backends embed the PNG itself, at its own resolution
        ax.imshow(pixels, interpolation="none", aspect="auto")
        ax.set_axis_off()
        p.y = y0 - 0.06
        cap_font = _Font(_SMALL, style="italic")
        for line in self.m.wrap(caption_text(block), cap_font, _WIDTH / _PT):
            p.text(_LEFT, p.y, line, cap_font, va="top", color="0.3")
            p.y -= 1.35 * _SMALL * _PT
        p.y -= 10 * _PT

    def code(self, text: str):
        """Preformatted lines as they are, leading spaces included (a matrix's columns
        stay aligned); only a line wider than the page is wrapped (a command). A
        block of up to `_KEEP_CODE` lines is kept on one page."""
        font = _Font(_CODE, family="monospace")
        limit = (_WIDTH - 0.2) / _PT
        lines: list[str] = []
        for raw in text.split("\n"):
            fits = self.m.width(raw, font) <= limit
            lines += [raw] if fits else self.m.wrap(raw, font, limit)
        step = 1.3 * font.size * _PT
        if len(lines) <= _KEEP_CODE:
            self.pages.room((3 + 8) * _PT + len(lines) * step)
        self.pages.y -= 3 * _PT
        for line in lines:
            self.pages.room(step)
            self.pages.rect(_LEFT, self.pages.y - step, _WIDTH, step, color="0.95", lw=0)
            self.pages.text(_LEFT + 0.1, self.pages.y - 0.1 * step, line, font, va="top")
            self.pages.y -= step
        self.pages.y -= 8 * _PT

    # tables ---------------------------------------------------------------
    def _layout(self, head, body, font: _Font, bold: _Font):
        """Column widths [pt] and wrapped header lines, for one font size."""
        widths, headers = [], []
        for j, title in enumerate(head):
            data = max((self.m.width(row[j], font) for row in body), default=0.0)
            word = max((self.m.width(w, bold) for w in title.split()), default=0.0)
            inner = max(data, word, 1.0)
            # wrap() keeps 2 % in hand: give it that back, so no word is ever cut
            lines = self.m.wrap(title, bold, inner / 0.98 + 0.5) if title else [""]
            inner = max([inner] + [self.m.width(t, bold) for t in lines])
            widths.append(inner + 2 * _CELL_PAD)
            headers.append(lines)
        return widths, headers

    def _plan(self, block: Table):
        """(font, bold, widths, headers, column groups): the largest of `_TABLE_SIZES`
        at which the table fits the width; too wide at the smallest, column
        groups, each with the index."""
        head, body, _ = table_cells(block.frame)
        for size in _TABLE_SIZES:
            font, bold = _Font(size), _Font(size, weight="bold")
            widths, headers = self._layout(head, body, font, bold)
            if sum(widths) * _PT <= _WIDTH:
                break
        groups, group = [], [0]
        for j in range(1, len(head)):
            if sum(widths[k] for k in group + [j]) * _PT > _WIDTH and len(group) > 1:
                groups.append(group)
                group = [0]
            group.append(j)
        groups.append(group)
        return font, bold, widths, headers, groups

    def _start_height(self, caption: str, headers, cols, rows: int, font, bold) -> float:
        """Height [in] of a table part's caption, header and first three rows."""
        cap_font = _Font(_SMALL, style="italic")
        cap_lines = self.m.wrap(caption, cap_font, _WIDTH / _PT) if caption else []
        n_head = max(len(headers[j]) for j in cols)
        head_h = (n_head * 1.25 * bold.size + 2 * _CELL_PAD) * _PT
        row_h = 1.45 * font.size * _PT
        return len(cap_lines) * 1.35 * _SMALL * _PT + 2 * _PT + head_h + min(3, rows) * row_h

    def _table_start_height(self, block: Table) -> float:
        font, bold, _, headers, groups = self._plan(block)
        return self._start_height(
            caption_text(block), headers, groups[0], len(block.frame), font, bold
        )

    def table(self, block: Table):
        head, body, numeric = table_cells(block.frame)
        font, bold, widths, headers, groups = self._plan(block)
        for i, cols in enumerate(groups):
            caption = caption_text(block)
            if len(groups) > 1:
                caption += f" (columns {i + 1} of {len(groups)})"
            self._table_part(caption, cols, head, body, numeric, widths, headers, font, bold)

    def _table_part(self, caption, cols, head, body, numeric, widths, headers, font, bold):
        p = self.pages
        row_h = 1.45 * font.size * _PT
        n_head = max(len(headers[j]) for j in cols)
        head_h = (n_head * 1.25 * bold.size + 2 * _CELL_PAD) * _PT
        cap_font = _Font(_SMALL, style="italic")
        cap_lines = self.m.wrap(caption, cap_font, _WIDTH / _PT) if caption else []
        # the caption never ends a page without its table's header and first rows;
        # a short table is never split (a last row alone under a repeated header)
        start = self._start_height(caption, headers, cols, len(body), font, bold)
        whole = start + max(0, len(body) - 3) * row_h
        p.room(whole if len(body) <= _KEEP_ROWS and whole < _TEXT_H else start)
        for line in cap_lines:
            p.text(_LEFT, p.y, line, cap_font, va="top", color="0.3")
            p.y -= 1.35 * _SMALL * _PT
        p.y -= 2 * _PT
        x = [_LEFT]
        for j in cols:
            x.append(x[-1] + widths[j] * _PT)
        total = x[-1] - _LEFT

        def header():
            p.rect(_LEFT, p.y - head_h, total, head_h, color="0.93", lw=0)
            for k, j in enumerate(cols):
                for n, line in enumerate(headers[j]):
                    y = p.y - (_CELL_PAD + n * 1.25 * bold.size) * _PT
                    if numeric[j]:
                        p.text(x[k + 1] - _CELL_PAD * _PT, y, line, bold, va="top", ha="right")
                    else:
                        p.text(x[k] + _CELL_PAD * _PT, y, line, bold, va="top")
            p.rect(_LEFT, p.y, total, 0.8 * _PT, color="0.3", lw=0)
            p.y -= head_h
            p.rect(_LEFT, p.y, total, 0.5 * _PT, color="0.5", lw=0)

        header()
        for r, row in enumerate(body):
            if p.y - row_h < _BOTTOM:
                p.rect(_LEFT, p.y, total, 0.8 * _PT, color="0.3", lw=0)
                p.new_page(row_h)
                header()
            if r % 2:
                p.rect(_LEFT, p.y - row_h, total, row_h, color="0.975", lw=0)
            y = p.y - 0.22 * font.size * _PT
            for k, j in enumerate(cols):
                if numeric[j]:
                    p.text(x[k + 1] - _CELL_PAD * _PT, y, row[j], font, va="top", ha="right")
                else:
                    p.text(x[k] + _CELL_PAD * _PT, y, row[j], font, va="top")
            p.y -= row_h
        p.rect(_LEFT, p.y, total, 0.8 * _PT, color="0.3", lw=0)
        p.y -= 12 * _PT


def _floats(following) -> bool:
    """Whether a figure followed by ``following`` may float: text, a table or code
    of its own section comes next, to fill the space it leaves."""
    return bool(following) and isinstance(following[0], (Paragraph, Table, Code))


def to_pdf(title: str, blocks, image_dir, path) -> Path:
    """Write the report's blocks to ``path`` as an A4 PDF.

    Parameters
    ----------
    title : str
    blocks : list
        The blocks of `qc_control.report.build_blocks`.
    image_dir : path
        Where the images' PNG files are.
    path : path
        The PDF to write.

    Returns
    -------
    Path
    """
    _render(title, blocks, image_dir, path)
    return Path(path)


def _render(title: str, blocks, image_dir, path) -> list[PageRecord]:
    """Write the PDF (see `to_pdf`); how each page was filled, for checking."""
    metadata = {"Title": title, "Creator": "qc_control report (matplotlib)"}
    with PdfPages(Path(path), metadata=metadata) as pdf:
        pages = _Pages(pdf, footer=title)
        writer = _Writer(pages, Path(image_dir))
        pages.new_page()
        writer.lines(title, _Font(17.0, weight="bold"), after=10, color="0.05")
        for i, b in enumerate(blocks):
            pages.block = i
            if isinstance(b, Heading):
                writer.heading(b.text, b.level, blocks[i + 1 :])
            elif isinstance(b, Paragraph):
                writer.lines(b.text, _Font(_BODY), after=6)
            elif isinstance(b, Table):
                writer.table(b)
            elif isinstance(b, Image):
                writer.image(b, i, blocks[i + 1 :])
            elif isinstance(b, Code):
                writer.code(b.text)
        writer.finish()
        pages.close()
    return pages.records
