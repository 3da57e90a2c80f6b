"""Whether calibration files cover the data in time.

A TRK-2-23 file spans its cards (earliest start to latest end), an IONEX set
its maps (first to last epoch). The data's span (receive times, UTC) must lie
inside the union of the spans of the files given for one kind; otherwise the
corrections there would silently fall back to models (seasonal troposphere,
no ionosphere). Rows a file's span covers but no card of their station does
are the per-row fallbacks that :func:`odpipe.media.apply.fallbacks` reports.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

Span = tuple[np.datetime64, np.datetime64]


def trk223_spans(calibrations, paths) -> dict[str, Span | None]:
    """{file: (first card start, last card end) UTC, or None when it holds no card}."""
    out = {}
    for p in paths:
        cards = [c for c in calibrations.cards if c.source == Path(p).name]   # cards name their file
        out[str(p)] = (min(c.start for c in cards), max(c.end for c in cards)) if cards else None
    return out


def ionex_span(maps) -> Span:
    """(first, last) map epoch UTC of combined IONEX maps."""
    return maps.epochs[0], maps.epochs[-1]


def covered(spans, start, end) -> bool:
    """Whether [start, end] lies inside the union of ``spans`` (None entries ignored)."""
    t = np.datetime64(start, "ns")
    end = np.datetime64(end, "ns")
    for lo, hi in sorted((np.datetime64(a, "ns"), np.datetime64(b, "ns")) for a, b in filter(None, spans)):
        if lo > t:
            return False
        t = max(t, hi)
        if t >= end:
            return True
    return t >= end


def uncovered_message(kind: str, spans: dict[str, Span | None], start, end) -> str | None:
    """None when files ``spans`` ({file: span}) of ``kind`` cover [start, end]; else why, naming each file."""
    if not spans or covered(spans.values(), start, end):
        return None
    files = "; ".join(f"{f} {_fmt(s)}" if s else f"{f} (no cards)" for f, s in spans.items())
    return (f"{kind} calibration does not cover the data: {files}; the data {_fmt((start, end))}")


def _fmt(span: Span) -> str:
    lo, hi = (str(np.datetime64(t, "s")) for t in span)
    return f"{lo} .. {hi} UTC"
