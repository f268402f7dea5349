"""The report as a PDF, drawn with matplotlib alone (no browser, no LaTeX).

Every page is a matplotlib `Figure` of A4 size written through
`matplotlib.backends.backend_pdf.PdfPages`. Text is laid out here: words
are measured with matplotlib's own font metrics (the fonts the PDF embeds)
and wrapped greedily; tables are drawn as ruled grids, split across pages
(header repeated) and, when too wide, across column groups (index
repeated); figures are the report's PNGs, embedded at their own
resolution. The text stays text: it can be searched and copied.
"""

from __future__ import annotations

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


class _Pages:
    """Pages filled from the top down; a new page when a piece does not fit."""

    def __init__(self, pdf: PdfPages, footer: str):
        self.pdf, self.footer = pdf, footer
        self.fig: Figure | None = None
        self.y = 0.0  # the next free height [in] from the bottom of the page
        self.number = 0

    def _finish(self):
        if self.fig is not None:
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

    def new_page(self):
        self._finish()
        self.fig = Figure(figsize=(_PAGE_W, _PAGE_H))
        self.number += 1
        self.y = _PAGE_H - _TOP

    def room(self, height: float, at_top_is_enough: bool = True) -> None:
        """Make sure ``height`` inches fit below the current position."""
        if self.fig is None or self.y - height < _BOTTOM:
            if self.fig is not None and self.y >= _PAGE_H - _TOP - 1e-9 and at_top_is_enough:
                return  # already at the top of a page: taller than a page, draw anyway
            self.new_page()

    def text(self, x: float, y: float, s: str, font: _Font, **kw):
        assert self.fig is not None
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
    def __init__(self, pages: _Pages, image_dir: Path):
        self.pages, self.image_dir, self.m = pages, image_dir, _Measure()

    # text -----------------------------------------------------------------
    def lines(self, text: str, font: _Font, *, before=0.0, after=4.0, keep=2, color="0.1"):
        """Wrapped lines; ``keep`` lines at least stay together with what precedes."""
        lines = self.m.wrap(text, font, _WIDTH / _PT)
        step = 1.35 * font.size * _PT
        self.pages.room(before * _PT + min(keep, len(lines)) * step)
        if self.pages.y < _PAGE_H - _TOP - 1e-9:
            self.pages.y -= before * _PT
        for line in lines:
            self.pages.room(step)
            self.pages.text(_LEFT, self.pages.y, line, font, va="top", color=color)
            self.pages.y -= step
        self.pages.y -= after * _PT

    def heading(self, text: str, level: int, following=None):
        size = {1: 17.0, 2: 13.0}.get(level, 11.0)
        # a heading keeps company with the start of what follows it
        self.pages.room((14 + 1.35 * size + 5) * _PT + self.start_height(following))
        self.lines(text, _Font(size, weight="bold"), before=14, after=5, color="0.05")

    def start_height(self, block) -> float:
        """Height [in] of the part of ``block`` that must not be parted from a heading."""
        if isinstance(block, Image):
            return sum(self._image_size(block)[1:])
        if isinstance(block, Table):
            return 1.3  # caption, header and the first rows
        return 3 * 1.35 * _BODY * _PT  # three lines of text

    def _image_size(self, block: Image) -> tuple[float, float, float]:
        """(width, height, caption height) [in] of a figure as it will be drawn."""
        with PILImage.open(self.image_dir / block.path) as png:
            w_px, h_px = png.size
        cap = self.m.wrap(caption_text(block), _Font(_SMALL, style="italic"), _WIDTH / _PT)
        cap_h = len(cap) * 1.35 * _SMALL * _PT
        width, height = _WIDTH, _WIDTH * h_px / w_px
        most = _PAGE_H - _TOP - _BOTTOM - cap_h - 0.3
        if height > most:
            width, height = width * most / height, most
        return width, height + 0.25, cap_h

    def code(self, text: str):
        font = _Font(_CODE, family="monospace")
        lines = self.m.wrap(text, font, (_WIDTH - 0.2) / _PT)
        step = 1.3 * font.size * _PT
        self.pages.y -= 3 * _PT
        for line in lines:
            self.pages.room(step)
            self.pages.rect(_LEFT, self.pages.y - step, _WIDTH, step, color="0.95", lw=0)
            self.pages.text(_LEFT + 0.1, self.pages.y - 0.1 * step, line, font, va="top")
            self.pages.y -= step
        self.pages.y -= 8 * _PT

    # figures --------------------------------------------------------------
    def image(self, block: Image):
        with PILImage.open(self.image_dir / block.path) as png:
            pixels = np.asarray(png.convert("RGB"))  # 8-bit: embedded as it is
        cap_font = _Font(_SMALL, style="italic")
        caption = self.m.wrap(caption_text(block), cap_font, _WIDTH / _PT)
        width, padded, cap_h = self._image_size(block)
        height = padded - 0.25
        self.pages.room(padded + cap_h)
        y0 = self.pages.y - 0.08 - height
        x0 = _LEFT + (_WIDTH - width) / 2
        assert self.pages.fig is not None  # room() has opened a page
        ax = self.pages.fig.add_axes(
            (x0 / _PAGE_W, y0 / _PAGE_H, width / _PAGE_W, height / _PAGE_H)
        )
        # 'none': vector backends embed the PNG itself, at its own resolution
        ax.imshow(pixels, interpolation="none", aspect="auto")
        ax.set_axis_off()
        self.pages.y = y0 - 0.06
        for line in caption:
            self.pages.text(_LEFT, self.pages.y, line, cap_font, va="top", color="0.3")
            self.pages.y -= 1.35 * _SMALL * _PT
        self.pages.y -= 10 * _PT

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

    def table(self, block: Table):
        head, body, numeric = table_cells(block.frame)
        for size in _TABLE_SIZES:
            font, bold = _Font(size), _Font(size, weight="bold")
            widths, headers = self._layout(head, body, font, bold)
            if sum(widths) * _PT <= _WIDTH:
                break
        # too wide at the smallest size: column groups, each with the index
        groups, group = [], [0]
        for j in range(1, len(head)):
            if sum(widths[k] for k in group + [j]) * _PT > _WIDTH and len(group) > 1:
                groups.append(group)
                group = [0]
            group.append(j)
        groups.append(group)
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
        cap_h = len(cap_lines) * 1.35 * _SMALL * _PT
        p.room(cap_h + head_h + min(3, len(body)) * row_h + 0.1)
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
                p.new_page()
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
    path = Path(path)
    metadata = {"Title": title, "Creator": "qc_control report (matplotlib)"}
    with PdfPages(path, metadata=metadata) as pdf:
        pages = _Pages(pdf, footer=title)
        writer = _Writer(pages, Path(image_dir))
        pages.new_page()
        writer.lines(title, _Font(17.0, weight="bold"), after=10, color="0.05")
        for i, b in enumerate(blocks):
            if isinstance(b, Heading):
                writer.heading(b.text, b.level, blocks[i + 1] if i + 1 < len(blocks) else None)
            elif isinstance(b, Paragraph):
                writer.lines(b.text, _Font(_BODY), after=6)
            elif isinstance(b, Table):
                writer.table(b)
            elif isinstance(b, Image):
                writer.image(b)
            elif isinstance(b, Code):
                writer.code(b.text)
        pages.close()
    return path
