"""A report as a list of blocks, rendered to Markdown or HTML.

One list of blocks feeds both writers, so the two formats can never say
different things.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass
from numbers import Integral, Real

import pandas as pd

__all__ = ["Heading", "Paragraph", "Table", "Image", "Code", "fmt", "to_markdown", "to_html"]


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


@dataclass(frozen=True)
class Image:
    path: str  # relative to the report
    caption: str


@dataclass(frozen=True)
class Code:
    text: str


def fmt(value) -> str:
    """A number to 4 significant digits; integers and text unchanged."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, Integral):
        return f"{value:d}"
    if isinstance(value, complex):
        return f"{value.real:.4g} {'+' if value.imag >= 0 else '−'} {abs(value.imag):.4g}j"
    if isinstance(value, Real):
        if math.isnan(value):
            return "–"
        if math.isinf(value):
            return "∞" if value > 0 else "−∞"
        return f"{value:.4g}"
    return str(value)


def _cells(frame: pd.DataFrame) -> tuple[list[str], list[list[str]]]:
    head = [frame.index.name or ""] + [str(c) for c in frame.columns]
    body = [[fmt(idx)] + [fmt(v) for v in row] for idx, row in zip(frame.index, frame.values)]
    return head, body


def to_markdown(title: str, blocks) -> str:
    out = [f"# {title}", ""]
    for b in blocks:
        if isinstance(b, Heading):
            out += ["#" * b.level + " " + b.text, ""]
        elif isinstance(b, Paragraph):
            out += [b.text, ""]
        elif isinstance(b, Table):
            head, body = _cells(b.frame)
            if b.caption:
                out += [f"*{b.caption}*", ""]
            out.append("| " + " | ".join(c.replace("|", "\\|") for c in head) + " |")
            out.append("|" + "|".join("---" for _ in head) + "|")
            out += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in body]
            out.append("")
        elif isinstance(b, Image):
            out += [f"![{b.caption}]({b.path})", "", f"*{b.caption}*", ""]
        elif isinstance(b, Code):
            out += ["```", b.text, "```", ""]
    return "\n".join(out)


_CSS = """
body { font-family: system-ui, sans-serif; max-width: 60em; margin: 2em auto; padding: 0 1em;
       line-height: 1.45; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.6em; text-align: right; }
th:first-child, td:first-child { text-align: left; }
th { background: #f3f3f3; }
figure { margin: 1em 0 2em; } figure img { max-width: 100%; }
figcaption, caption { font-style: italic; color: #555; }
pre { background: #f6f6f6; padding: 0.6em; overflow-x: auto; }
"""


def to_html(title: str, blocks) -> str:
    esc = html.escape
    out = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        f"<title>{esc(title)}</title>",
        f"<style>{_CSS}</style>",
        "</head>",
        "<body>",
        f"<h1>{esc(title)}</h1>",
    ]
    for b in blocks:
        if isinstance(b, Heading):
            out.append(f"<h{b.level}>{esc(b.text)}</h{b.level}>")
        elif isinstance(b, Paragraph):
            out.append(f"<p>{esc(b.text)}</p>")
        elif isinstance(b, Table):
            head, body = _cells(b.frame)
            out.append("<table>")
            if b.caption:
                out.append(f"<caption>{esc(b.caption)}</caption>")
            out.append("<tr>" + "".join(f"<th>{esc(c)}</th>" for c in head) + "</tr>")
            out += ["<tr>" + "".join(f"<td>{esc(c)}</td>" for c in row) + "</tr>" for row in body]
            out.append("</table>")
        elif isinstance(b, Image):
            out.append(
                f'<figure><img src="{esc(b.path)}" alt="{esc(b.caption)}">'
                f"<figcaption>{esc(b.caption)}</figcaption></figure>"
            )
        elif isinstance(b, Code):
            out.append(f"<pre><code>{esc(b.text)}</code></pre>")
    out += ["</body>", "</html>", ""]
    return "\n".join(out)
