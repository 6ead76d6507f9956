"""A self-contained HTML page: every image inlined as a data URI, so that the one file can be
mailed, archived or opened offline."""

from __future__ import annotations

import base64
import html
from collections.abc import Sequence
from pathlib import Path

STYLE = """
body { font-family: system-ui, sans-serif; color: #222;
       margin: 2em auto; padding: 0 1em; max-width: 1300px; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; }
th { background: #f0f0f0; }
td.text { text-align: left; }
.caption { color: #555; font-size: 0.9em; }
.episode { border-top: 2px solid #ddd; margin-top: 2em; padding-top: 0.5em; }
.graphs img { width: 48%; margin-right: 1%; }
img { max-width: 100%; }
.warn { color: #a40; }
"""

MIME = {".png": "image/png", ".gif": "image/gif"}


def image(path: Path, alt: str) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f'<img alt="{html.escape(alt)}" src="data:{MIME[path.suffix]};base64,{data}">'


def table(header: Sequence[str], rows: Sequence[Sequence[str]], text_columns=()) -> str:
    """An HTML table; the columns named in `text_columns` are left-aligned."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = []
    for row in rows:
        cells = "".join(
            f'<td class="text">{html.escape(c)}</td>'
            if header[k] in text_columns
            else f"<td>{html.escape(c)}</td>"
            for k, c in enumerate(row)
        )
        body.append(f"<tr>{cells}</tr>")
    return f"<table><tr>{head}</tr>{''.join(body)}</table>"


def heading(level: int, text: str) -> str:
    return f"<h{level}>{html.escape(text)}</h{level}>"


def paragraph(text: str, cls: str = "") -> str:
    attr = f' class="{cls}"' if cls else ""
    return f"<p{attr}>{html.escape(text)}</p>"


def page(title: str, parts: Sequence[str]) -> str:
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>{html.escape(title)}</title><style>{STYLE}</style></head>"
        f"<body>{heading(1, title)}{''.join(parts)}</body></html>\n"
    )
