"""A single-page HTML report: headline figures, tables and plots, with the images embedded.

The page stands alone (images are PNG data URIs), so it can be mailed or
archived with the run. Build it from sections; each section holds text,
tables (pandas DataFrames) and figures (PNG files) in order.

What a reader sees follows fixed rules: times as ISO UTC calendar strings
(:func:`utc_iso`; datetime columns are written so), a unit in round brackets
on every column header that has one, each column at the precision its
quantity carries (the caller's ``formats``), an undefined value as an en dash,
never ``nan``, and wide tables scrolling inside the page.
"""

from __future__ import annotations

import base64
import html
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from parsers.atomic import write_text
from odpipe.time import tdb_to_utc

_STYLE = """
body{font-family:system-ui,sans-serif;margin:1.5em auto;max-width:1200px;padding:0 1em;color:#222}
h1{border-bottom:2px solid #335;padding-bottom:.2em;font-size:1.6em} h2{color:#335;margin-top:1.4em;font-size:1.25em}
h3{color:#335;font-size:1em;margin:1em 0 .3em}
.scroll{overflow-x:auto;max-width:100%}
table{border-collapse:collapse;font-size:.78em;margin:.4em 0;font-variant-numeric:tabular-nums}
td,th{border:1px solid #bbb;padding:.15em .45em;text-align:right;white-space:nowrap}
th{background:#eef;white-space:normal;vertical-align:bottom} td.text,th.text{text-align:left}
.headline td:first-child{text-align:left} .headline td{white-space:pre-line} img{max-width:100%;border:1px solid #ddd;margin:.4em 0}
.note{color:#555;font-size:.9em}
"""

MISSING = "\u2013"  # en dash: a value that is undefined or absent
NEGATIVE_ZERO = re.compile(r"-0(\.0*)?")   # a negative value that its format rounds to zero


def utc_iso(t_tdb, decimals: int = 0):
    """ISO UTC calendar string(s) ``YYYY-MM-DDTHH:MM:SS[.fff]`` of TDB seconds past J2000, rounded to
    ``decimals`` digits of the second (0..6); a scalar gives a str, an array a list."""
    unit = {0: "s", 3: "ms", 6: "us"}[decimals]
    utc = np.atleast_1d(np.asarray(tdb_to_utc(np.atleast_1d(np.asarray(t_tdb, float))), "datetime64[ns]"))
    out = [np.datetime_as_string(t, unit=unit) for t in _round(utc, unit)]
    return out[0] if np.ndim(t_tdb) == 0 else out


def _round(t: np.ndarray, unit: str) -> np.ndarray:
    step = np.timedelta64(1, unit).astype("timedelta64[ns]").astype(np.int64)
    ns = t.astype(np.int64)
    return (((ns + step // 2) // step) * step).astype("datetime64[ns]")


def _cell(value, fmt) -> str:
    if value is None or (np.ndim(value) == 0 and not isinstance(value, str) and pd.isna(value)):
        return MISSING
    if isinstance(value, (float, np.floating)) and not np.isfinite(value):
        return MISSING
    if isinstance(value, (np.datetime64, pd.Timestamp)):
        return np.datetime_as_string(_round(np.array([np.datetime64(value, "ns")]), "s")[0], unit="s")
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (float, np.floating, int, np.integer)):
        text = fmt(value) if callable(fmt) else \
            (fmt or ("{:d}" if isinstance(value, (int, np.integer)) else "{:.6g}")).format(value)
        return text.lstrip("-") if NEGATIVE_ZERO.fullmatch(text) else text   # -0.04 at 0.1: "0.0", not "-0.0"
    return str(value)


def _row_format(fmt, i: int):
    """Row ``i``'s format of a column: ``fmt`` itself, or its i-th entry when it lists one per row."""
    return fmt[i] if isinstance(fmt, (list, tuple)) else fmt


def html_table(df: pd.DataFrame, formats: dict | None = None) -> str:
    """A DataFrame as an HTML table (no index): ``formats`` maps a column to a format string
    (e.g. ``"{:.3f}"``), a callable, or a list of those, one per row; other floats get 6 significant
    figures, NaN an en dash, datetimes ISO seconds; text columns are left aligned."""
    formats = formats or {}
    text = [not (pd.api.types.is_numeric_dtype(df[c]) or pd.api.types.is_datetime64_any_dtype(df[c]))
            or pd.api.types.is_bool_dtype(df[c]) for c in df.columns]
    cls = [" class='text'" if t else "" for t in text]
    head = "".join(f"<th{k}>{html.escape(str(c))}</th>" for c, k in zip(df.columns, cls))
    rows = []
    for i, row in enumerate(df.itertuples(index=False)):
        cells = "".join(f"<td{k}>{html.escape(_cell(v, _row_format(formats.get(c), i)))}</td>"
                        for c, v, k in zip(df.columns, row, cls))
        rows.append(f"<tr>{cells}</tr>")
    return f"<div class='scroll'><table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table></div>"


@dataclass
class Section:
    title: str
    items: list = field(default_factory=list)

    def text(self, s: str) -> "Section":
        self.items.append(("text", s))
        return self

    def table(self, df: pd.DataFrame, formats: dict | None = None, caption: str = "") -> "Section":
        """A table (see :func:`html_table`), under an optional small heading ``caption``."""
        if caption:
            self.items.append(("caption", caption))
        self.items.append(("table", html_table(df, formats)))
        return self

    def tables(self, tables) -> "Section":
        """Several (caption, DataFrame, formats) tables, each under its caption."""
        for caption, df, formats in tables:
            self.table(df, formats, caption)
        return self

    def figure(self, png: Path, caption: str = "") -> "Section":
        self.items.append(("figure", (Path(png), caption)))
        return self


def render(title: str, headline: dict, sections: list[Section]) -> str:
    """The report's HTML text."""
    out = [f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>",
           f"<style>{_STYLE}</style></head><body><h1>{html.escape(title)}</h1>"]
    if headline:
        rows = "".join(f"<tr><td>{html.escape(str(k))}</td><td>{html.escape(_cell(v, None))}</td></tr>"
                       for k, v in headline.items())
        out.append(f"<table class='headline'>{rows}</table>")
    for sec in sections:
        out.append(f"<h2>{html.escape(sec.title)}</h2>")
        for kind, item in sec.items:
            if kind == "text":
                out.append(f"<p>{html.escape(item)}</p>")
            elif kind == "caption":
                out.append(f"<h3>{html.escape(item)}</h3>")
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
