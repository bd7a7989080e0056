"""The report's small HTML builders. Every text that reaches the page goes through :func:`text`: project and axis
names, descriptions and the saved result files are user input, and the report is opened from a file."""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Sequence
from html import escape

#: what a table cell shows for a value the file does not hold
NOTHING = "—"


def text(value: object) -> str:
    return escape(str(value), quote=True)


def shown(value: object, unit: str = "") -> str:
    """A value as a cell shows it, escaped: numbers to 6 significant digits, nested values as compact JSON."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return NOTHING
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return text(f"{value:.6g}" + (f" {unit}" if unit else ""))
    if isinstance(value, (dict, list)):
        return text(json.dumps(value, ensure_ascii=False))
    return text(f"{value}" + (f" {unit}" if unit else ""))


def table(headers: Sequence[str], rows: Iterable[Sequence[str]], css: str = "") -> str:
    """A table of cells that are HTML already (built with :func:`shown` or :func:`text`)."""
    head = "".join(f"<th>{text(header)}</th>" for header in headers)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    klass = f' class="{text(css)}"' if css else ""
    return f"<table{klass}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def facts(pairs: Iterable[tuple[str, str]]) -> str:
    """A two-column table of label → value (values HTML already)."""
    rows = "".join(f"<tr><th>{text(label)}</th><td>{value}</td></tr>" for label, value in pairs)
    return f'<table class="facts"><tbody>{rows}</tbody></table>'


def absent(message: str) -> str:
    """A section without data says so plainly."""
    return f'<p class="absent">{text(message)}</p>'


def note(message: str) -> str:
    return f'<p class="note">{text(message)}</p>'


def section(anchor: str, title: str, body: str) -> str:
    return f'<section id="{text(anchor)}"><h3>{text(title)}</h3>{body}</section>'
