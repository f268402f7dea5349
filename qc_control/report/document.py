"""A report as a list of blocks, rendered to Markdown or HTML.

One list of blocks feeds every writer (Markdown, HTML and the PDF in
`qc_control.report.pdf`), so the formats can never say different things.
"""

from __future__ import annotations

import base64
import html
import math
from dataclasses import dataclass
from numbers import Integral, Real
from pathlib import Path

import pandas as pd
from PIL import Image as PILImage  # matplotlib's own dependency

__all__ = [
    "Heading",
    "Paragraph",
    "Table",
    "Image",
    "Code",
    "fmt",
    "sentence",
    "table_cells",
    "caption_text",
    "to_markdown",
    "to_html",
]


@dataclass(frozen=True)
class Heading:
    text: str
    level: int = 2


@dataclass(frozen=True)
class Paragraph:
    text: str


@dataclass(frozen=True)
class Table:
    frame: pd.DataFrame
    caption: str = ""
    label: str = ""  # "Table 2"


@dataclass(frozen=True)
class Image:
    path: str  # relative to the report
    caption: str
    label: str = ""  # "Figure 3"


@dataclass(frozen=True)
class Code:
    """Preformatted text. ``wrap``: a long line may wrap (a command); otherwise
    never (a matrix, whose rows must stay aligned), and its box scrolls."""

    text: str
    wrap: bool = False


#: Integer-valued floats up to this size print in full (30000, not 3e+04).
_WHOLE_LIMIT = 1e15


def sentence(text: str) -> str:
    """``text`` as a sentence of the report: its first letter a capital, a full stop
    after (the verdicts are written to stand inside a sentence)."""
    return f"{text[:1].upper()}{text[1:]}."


def fmt(value) -> str:
    """A value as report text: numbers readable at a glance, text unchanged.

    - integers, and floats with an integer value below 1e15, in full:
      ``30000.0 -> '30000'``, ``29530.0 -> '29530'``;
    - other reals to 4 significant digits, without an exponent from 1e-3 up
      to 1e4 (``0.01982``, ``1503``), rounded to whole numbers from 1e4 up
      to 1e15 (``12346``), with an exponent beyond (``1.917e-07``);
    - complex values as ``a ± bj``, and a complex value with a zero
      imaginary part as the real number it is;
    - NaN as an en dash, infinities as ``∞``; booleans as yes/no.
    """
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, Integral):
        return f"{int(value):d}"
    if isinstance(value, complex):
        if value.imag == 0:
            return fmt(value.real)
        return f"{fmt(value.real)} {'+' if value.imag >= 0 else '−'} {fmt(abs(value.imag))}j"
    if isinstance(value, Real):
        value = float(value)
        if math.isnan(value):
            return "–"
        if math.isinf(value):
            return "∞" if value > 0 else "−∞"
        if value == 0:
            return "0"
        size = abs(value)
        if size < _WHOLE_LIMIT and value == round(value):
            return f"{value:.0f}"
        text = f"{value:.4g}"
        if 1e-3 <= size < _WHOLE_LIMIT and "e" in text:  # 12345.6 or 9999.95
            return f"{value:.0f}"
        return text
    return str(value)


def _is_number(value) -> bool:
    return isinstance(value, (Real, complex)) and not isinstance(value, bool)


def table_cells(frame: pd.DataFrame) -> tuple[list[str], list[list[str]], list[bool]]:
    """(header, body rows, numeric flag per column) of a table, index first.

    Each column is formatted from its own values (``Series.tolist`` keeps
    each column's dtype), never from ``frame.values``, which upcasts a table
    with one complex column to complex throughout. A column is numeric, and
    right-aligned, when most values in it are numbers (a method's column of a
    table with one row per measure holds a "yes" or a mode's name among them).
    """
    columns = [frame.index.tolist()] + [frame.iloc[:, j].tolist() for j in range(frame.shape[1])]
    numeric = [2 * sum(_is_number(v) for v in col) > len(col) for col in columns]
    head = [str(frame.index.name or "")] + [str(c) for c in frame.columns]
    body = [[fmt(col[i]) for col in columns] for i in range(len(frame))]
    return head, body, numeric


def caption_text(block) -> str:
    """'Figure 3: caption', or the caption alone when the block has no label."""
    return f"{block.label}: {block.caption}" if block.label else block.caption


def to_markdown(title: str, blocks) -> str:
    out = [f"# {title}", ""]
    for b in blocks:
        if isinstance(b, Heading):
            out += ["#" * b.level + " " + b.text, ""]
        elif isinstance(b, Paragraph):
            out += [b.text, ""]
        elif isinstance(b, Table):
            head, body, numeric = table_cells(b.frame)
            if b.caption or b.label:
                out += [f"*{caption_text(b)}*", ""]
            out.append("| " + " | ".join(c.replace("|", "\\|") for c in head) + " |")
            out.append("|" + "|".join("---:" if n else ":---" for n in numeric) + "|")
            out += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in body]
            out.append("")
        elif isinstance(b, Image):
            out += [f"![{caption_text(b)}]({b.path})", "", f"*{caption_text(b)}*", ""]
        elif isinstance(b, Code):
            out += ["```", b.text, "```", ""]
    return "\n".join(out)


# The page itself never scrolls sideways. A table too wide for a phone scrolls
# inside its own box, below its caption, which stays in view; a matrix scrolls
# rather than wrap a row. On a narrow screen a figure keeps its design size
# (`_FIGURE_CSS_PX` per inch of the figure), so its text stays readable, and its
# box scrolls; on a wide screen it fits the column.
_CSS = """
body { font-family: system-ui, sans-serif; max-width: 60em; margin: 2em auto; padding: 0 1em;
       line-height: 1.45; color: #222; overflow-wrap: anywhere; }
.table { margin: 0.5em 0 1.5em; }
.scroll { overflow-x: auto; }
table { border-collapse: collapse; font-size: 0.85em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.4em; vertical-align: top; }
th { background: #f3f3f3; overflow-wrap: normal; }
td { white-space: nowrap; }
.num { text-align: right; font-variant-numeric: tabular-nums; }
.text { text-align: left; }
figure { margin: 1em 0 2em; } figure img { max-width: 100%; height: auto; }
figcaption, .caption { font-style: italic; color: #555; text-align: left; }
.caption { margin: 0 0 0.3em; }
pre { background: #f6f6f6; padding: 0.6em; overflow-x: auto; white-space: pre; }
pre.wrap { white-space: pre-wrap; }
@media (max-width: 48em) {
  figure .scroll img { max-width: none; width: var(--design-width); }
  td.long { white-space: normal; overflow-wrap: normal; min-width: 10em; }
  table { font-size: 0.8em; } th, td { padding: 0.2em 0.3em; }
}
@media print { .scroll { overflow: visible; } figure .scroll img { max-width: 100%; } }
"""


def _data_uri(path: Path) -> str:
    kind = {".png": "image/png", ".svg": "image/svg+xml", ".jpg": "image/jpeg"}.get(
        path.suffix.lower(), "application/octet-stream"
    )
    return f"data:{kind};base64," + base64.b64encode(path.read_bytes()).decode("ascii")


def _anchor(label: str) -> str:
    return label.lower().replace(" ", "-")


def _header_cell(text: str) -> str:
    """A column title that may break after '_' (``susp_travel_front``), never mid-word."""
    return html.escape(text).replace("_", "_<wbr>")


#: Characters from which a text cell (a description) may wrap on a narrow screen.
_LONG_TEXT = 24


def _cell_class(kind: str, text: str) -> str:
    """A cell's class: numbers never wrap; a long description may, on a phone."""
    long = kind == "text" and len(text) >= _LONG_TEXT and " " in text
    return f' class="{kind} long"' if long else f' class="{kind}"'


def _html_table(b: Table, caption: str) -> list[str]:
    """A table below its caption, in a box of its own that scrolls when the table
    is wider than the screen: the caption stays in view, outside the scrolling box."""
    head, body, numeric = table_cells(b.frame)
    cls = ["num" if n else "text" for n in numeric]
    esc = html.escape
    ident = _anchor(b.label) if b.label else ""
    out = [f'<div class="table" id="{ident}">' if ident else '<div class="table">']
    label = ""
    if caption and ident:
        out.append(f'<p class="caption" id="{ident}-caption">{caption}</p>')
        label = f' aria-labelledby="{ident}-caption"'
    elif caption:
        out.append(f'<p class="caption">{caption}</p>')
    # tabindex: a keyboard user can scroll the box; role and label name it
    out.append(f'<div class="scroll" role="region" tabindex="0"{label}><table>')
    out.append(
        "<tr>"
        + "".join(f'<th class="{k}">{_header_cell(c)}</th>' for k, c in zip(cls, head))
        + "</tr>"
    )
    for row in body:
        cells = "".join(f"<td{_cell_class(k, c)}>{esc(c)}</td>" for k, c in zip(cls, row))
        out.append(f"<tr>{cells}</tr>")
    out.append("</table></div></div>")
    return out


#: CSS pixels per inch of a figure on a narrow screen: the CSS inch, so a
#: figure shows at the size it was designed at (10 pt text as 13.3 px).
_FIGURE_CSS_PX = 96


def _html_figure(b: Image, path: Path | None, caption: str) -> str:
    """A figure in a box that scrolls on a narrow screen, its caption below, outside it.

    With the file at hand, the image is embedded (data URI) and its size
    stated: the pixel size, and as ``--design-width`` the width it was drawn
    at, from the PNG's resolution (matplotlib writes ``dpi`` into it).
    """
    esc = html.escape
    ident = f' id="{_anchor(b.label)}"' if b.label else ""
    if path is None:
        img = f'<img src="{esc(b.path)}" alt="{esc(caption_text(b))}">'
    else:
        with PILImage.open(path) as png:
            (w, h), dpi = png.size, png.info.get("dpi", (_FIGURE_CSS_PX,))[0]
        design = round(w * _FIGURE_CSS_PX / float(dpi or _FIGURE_CSS_PX))
        img = (
            f'<img src="{esc(_data_uri(path))}" alt="{esc(caption_text(b))}" width="{w}" '
            f'height="{h}" style="--design-width: {design}px">'
        )
    return (
        f'<figure{ident}><div class="scroll">{img}</div><figcaption>{caption}</figcaption></figure>'
    )


def to_html(title: str, blocks, image_dir=None) -> str:
    """The report as one HTML page.

    Parameters
    ----------
    title : str
    blocks : list
    image_dir : path, optional
        Where the images' files are. When given, every image is embedded as
        a data URI, so the page is self-contained (it can be mailed or
        uploaded alone); otherwise images are relative links.
    """
    esc = html.escape
    out = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{esc(title)}</title>",
        f"<style>{_CSS}</style>",
        "</head>",
        "<body>",
        f"<h1>{esc(title)}</h1>",
    ]

    def caption(b) -> str:
        if not b.label:
            return esc(b.caption)
        return f"<b>{esc(b.label)}:</b> {esc(b.caption)}"

    for b in blocks:
        if isinstance(b, Heading):
            out.append(f"<h{b.level}>{esc(b.text)}</h{b.level}>")
        elif isinstance(b, Paragraph):
            out.append(f"<p>{esc(b.text)}</p>")
        elif isinstance(b, Table):
            out += _html_table(b, caption(b) if b.caption or b.label else "")
        elif isinstance(b, Image):
            path = Path(image_dir) / b.path if image_dir is not None else None
            out.append(_html_figure(b, path, caption(b)))
        elif isinstance(b, Code):
            wrap = ' class="wrap"' if b.wrap else ""
            out.append(f"<pre{wrap}><code>{esc(b.text)}</code></pre>")
    out += ["</body>", "</html>", ""]
    return "\n".join(out)
