"""A single-page HTML report: headline figures, tables and plots, with the images embedded.

The page stands alone (images are PNG data URIs), so it can be mailed or
archived with the run. Build it from sections; each section holds text,
tables (pandas DataFrames) and figures (PNG files) in order.
"""

from __future__ import annotations

import base64
import html
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from odpipe.products.atomic import write_text

_STYLE = """
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1100px;color:#222}
h1{border-bottom:2px solid #335;padding-bottom:.2em} h2{color:#335;margin-top:1.6em}
table{border-collapse:collapse;font-size:.85em;margin:.5em 0} td,th{border:1px solid #bbb;padding:.2em .5em;text-align:right}
th{background:#eef} .headline td:first-child{text-align:left} img{max-width:100%;border:1px solid #ddd;margin:.4em 0}
.note{color:#555;font-size:.9em}
"""


@dataclass
class Section:
    title: str
    items: list = field(default_factory=list)

    def text(self, s: str) -> "Section":
        self.items.append(("text", s))
        return self

    def table(self, df: pd.DataFrame, floatfmt: str = "{:.6g}") -> "Section":
        self.items.append(("table", df.to_html(index=False, float_format=floatfmt.format, border=0)))
        return self

    def figure(self, png: Path, caption: str = "") -> "Section":
        self.items.append(("figure", (Path(png), caption)))
        return self


def render(title: str, headline: dict, sections: list[Section]) -> str:
    """The report's HTML text."""
    out = [f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>",
           f"<style>{_STYLE}</style></head><body><h1>{html.escape(title)}</h1>"]
    if headline:
        rows = "".join(f"<tr><td>{html.escape(str(k))}</td><td>{html.escape(str(v))}</td></tr>"
                       for k, v in headline.items())
        out.append(f"<table class='headline'>{rows}</table>")
    for sec in sections:
        out.append(f"<h2>{html.escape(sec.title)}</h2>")
        for kind, item in sec.items:
            if kind == "text":
                out.append(f"<p>{html.escape(item)}</p>")
            elif kind == "table":
                out.append(item)
            else:
                png, caption = item
                data = base64.b64encode(png.read_bytes()).decode()
                out.append(f"<figure><img alt='{html.escape(caption)}' src='data:image/png;base64,{data}'>"
                           f"<figcaption class='note'>{html.escape(caption)}</figcaption></figure>")
    out.append("</body></html>")
    return "\n".join(out)


def write_report(path, title: str, headline: dict, sections: list[Section]) -> Path:
    """Write the report atomically; returns its path."""
    return write_text(path, render(title, headline, sections))
