"""CCSDS Tracking Data Message (TDM 2.0, 503.0-B-2; 1.0 files read too), KVN and XML.

``read(path)`` returns :class:`parsers.TrackingData` (rows and units in
:mod:`parsers.tdm.observations`); ``meta`` holds the version, header, comments and each
segment's metadata, which ``write`` uses to turn a TrackingData back into a TDM in either
syntax. Malformed files raise :class:`parsers.ParseError` naming file, line and keyword;
with ``errors="report"`` bad data lines are reported and skipped (metadata faults always
raise). Values that are not finite (NaN, inf) are kept with the INVALID flag. XML
DOCTYPE/ENTITY declarations are refused; KVN must be UTF-8.
"""

from __future__ import annotations

import gc
from pathlib import Path

from parsers.atomic import write_text
from parsers.errors import ParseReport, check_mode, decode
from parsers.table import TrackingData
from parsers.tdm import keywords, kvn, times, xml
from parsers.tdm.message import Message, Segment
from parsers.tdm.observations import message, tracking

__all__ = ["read", "sniff", "write", "Message", "Segment", "keywords", "times"]


def sniff(head: bytes) -> bool:
    """True for a KVN TDM (starts with CCSDS_TDM_VERS) or an XML one (a <tdm> root)."""
    text = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    return text.startswith(b"CCSDS_TDM_VERS") or (text.startswith(b"<?xml") and b"<tdm" in head)


def read(path, errors: str = "raise") -> TrackingData:
    """Read a KVN or XML TDM."""
    check_mode(errors)
    path = Path(path)
    raw = path.read_bytes()
    report = ParseReport()
    is_xml = raw.lstrip(b"\xef\xbb\xbf \t\r\n").startswith(b"<")
    collecting = gc.isenabled()
    gc.disable()  # millions of small objects, no cycles: the cyclic collector only costs time here
    try:
        msg = xml.parse(raw, path, errors, report) if is_xml else kvn.parse(decode(raw, path), path, errors, report)
    finally:
        if collecting:
            gc.enable()
    table, ramps = tracking(msg, path.name, path, errors, report)
    templates = [Segment(meta=s.meta, meta_comments=s.meta_comments, data_comments=s.data_comments)
                 for s in msg.segments]
    meta = {"format": "TDM", "syntax": "xml" if is_xml else "kvn", "version": msg.version, "header": msg.header,
            "comments": msg.comments, "segments": templates}
    return TrackingData(table, ramps, report, meta)


def write(path, data: TrackingData, syntax: str = "kvn") -> None:
    """Write ``data`` (as read by :func:`read`) as a TDM in ``syntax`` "kvn" or "xml", atomically."""
    msg: Message = message(data.table, data.meta)
    text = {"kvn": kvn.render, "xml": xml.render}[syntax](msg)
    write_text(path, text)
