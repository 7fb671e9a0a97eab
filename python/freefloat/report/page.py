"""One self-contained HTML page: sections of text, tables and Plotly figures, with plotly.js inlined once (the page
needs no network access to be viewed), and a little CSS. No hand-written JavaScript: Plotly draws the plots."""

from __future__ import annotations

import html
import json
import time
from dataclasses import dataclass, field

CSS = """
body { font-family: system-ui, -apple-system, 'Segoe UI', sans-serif; margin: 0 auto; max-width: 1280px;
       padding: 1em 2em; color: #222; background: #fff; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; } h2 { margin-top: 1.6em; border-bottom: 1px solid #ddd; }
p.sub { color: #555; margin-top: 0; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.88em; }
th, td { border: 1px solid #ddd; padding: 3px 8px; text-align: right; }
th { background: #f3f3f3; } td.l, th.l { text-align: left; }
tr.bad td { background: #fdecea; }
pre { background: #f7f7f7; padding: 0.8em; overflow-x: auto; font-size: 0.82em; max-height: 30em; }
details { margin: 0.6em 0; } .plot { margin: 0.5em 0 1.2em 0; }
nav a { margin-right: 1em; }
"""


def esc(x) -> str:
    return html.escape(str(x))


def fmt(x, digits: int = 4) -> str:
    """A number as a table shows it (None as an en dash)."""
    if x is None:
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        if x != x:
            return "NaN"
        return f"{x:.{digits}g}"
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(fmt(v, digits) for v in x) + "]"
    return str(x)


def table(header: list, rows: list[list], left: int = 1, bad_rows: set | None = None) -> str:
    """An HTML table; the first `left` columns left-aligned; rows whose index is in `bad_rows` highlighted."""
    h = "".join(f"<th class='l'>{esc(c)}</th>" if i < left else f"<th>{esc(c)}</th>" for i, c in enumerate(header))
    body = []
    for k, r in enumerate(rows):
        cells = "".join(
            f"<td class='l'>{esc(fmt(c))}</td>" if i < left else f"<td>{esc(fmt(c))}</td>" for i, c in enumerate(r)
        )
        cls = " class='bad'" if bad_rows and k in bad_rows else ""
        body.append(f"<tr{cls}>{cells}</tr>")
    return f"<table><thead><tr>{h}</tr></thead><tbody>{''.join(body)}</tbody></table>"


@dataclass
class Page:
    title: str
    subtitle: str = ""
    parts: list = field(default_factory=list)  # (section title or None, html)
    n_figures: int = 0

    def section(self, title: str) -> None:
        self.parts.append(("section", title))

    def text(self, s: str) -> None:
        self.parts.append(("html", f"<p>{esc(s)}</p>"))

    def raw(self, s: str) -> None:
        self.parts.append(("html", s))

    def table(self, header, rows, **kw) -> None:
        self.parts.append(("html", table(header, rows, **kw)))

    def settings(self, title: str, obj) -> None:
        """A collapsed block with a mapping as indented JSON (the run's or campaign's settings)."""
        text = obj if isinstance(obj, str) else json.dumps(obj, indent=1, default=str)
        self.parts.append(("html", f"<details><summary>{esc(title)}</summary><pre>{esc(text)}</pre></details>"))

    def figure(self, fig, height: int | None = None) -> None:
        """A Plotly figure (drawn by the plotly.js inlined once in the page)."""
        if height:
            fig.update_layout(height=height)
        fig.update_layout(template="plotly_white", margin=dict(l=60, r=30, t=60, b=50))
        div = fig.to_html(
            full_html=False,
            include_plotlyjs=False,
            div_id=f"fig{self.n_figures}",
            config={"displaylogo": False, "responsive": True},
        )
        self.n_figures += 1
        self.parts.append(("html", f"<div class='plot'>{div}</div>"))

    def render(self) -> str:
        from plotly.offline import get_plotlyjs

        body, toc = [], []
        for what, content in self.parts:
            if what == "section":
                anchor = f"s{len(toc)}"
                toc.append(f"<a href='#{anchor}'>{esc(content)}</a>")
                body.append(f"<h2 id='{anchor}'>{esc(content)}</h2>")
            else:
                body.append(content)
        stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
        return (
            "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
            f"<title>{esc(self.title)}</title><style>{CSS}</style>"
            f"<script type='text/javascript'>{get_plotlyjs()}</script></head><body>"
            f"<h1>{esc(self.title)}</h1><p class='sub'>{esc(self.subtitle)} · written by freefloat report, {stamp}</p>"
            f"<nav>{''.join(toc)}</nav>" + "\n".join(body) + "</body></html>\n"
        )
