"""TDM in keyword = value notation (KVN): text <-> :class:`Message`."""

from __future__ import annotations

from parsers.errors import ParseError, ParseReport, handle
from parsers.tdm.message import (Message, Segment, check_data_keyword, check_header, check_meta,
                                 close_meta)

_BLOCKS = {"META_START": "meta", "DATA_START": "data"}


def parse(text: str, path, errors: str = "raise", report: ParseReport | None = None) -> Message:
    """The :class:`Message` in KVN ``text``; ParseError on the first malformed line.

    With ``errors="report"`` a malformed data line is reported and skipped; other faults raise.
    """
    msg = Message()
    state, seg, line_no = "version", None, 0
    for line_no, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        key, eq, rest = line.partition("=")
        key, rest = key.strip(), rest.strip()
        if state == "version":
            if key != "CCSDS_TDM_VERS" or not eq:
                raise ParseError(path, "first line must be CCSDS_TDM_VERS = <version>", line=line_no, record=key)
            msg.version, state = rest, "header"
            continue
        if line.startswith("COMMENT"):
            note = line[7:].strip()
            target = {"header": msg.comments, "meta": seg.meta_comments if seg else None,
                      "data": seg.data_comments if seg else None}.get(state)
            if target is None:
                raise ParseError(path, "COMMENT outside header, metadata or data", line=line_no, record="COMMENT")
            target.append(note)
            continue
        if line in ("META_START", "DATA_START"):
            expected = "meta" if line == "META_START" else "data"
            if (expected == "meta" and state not in ("header", "between")) or \
                    (expected == "data" and state != "after_meta"):
                raise ParseError(path, f"{line} out of place", line=line_no, record=line)
            if expected == "meta":
                seg = Segment()
                msg.segments.append(seg)
            state = expected
            continue
        if line == "META_STOP" and state == "meta":
            close_meta(path, seg, line_no)
            state = "after_meta"
            continue
        if line == "DATA_STOP" and state == "data":
            state = "between"
            continue
        if state == "data":
            try:
                _data_line(path, seg, key, eq, rest, line_no)
            except ParseError as err:
                handle(err, errors, report)
            continue
        if not eq:
            raise ParseError(path, f"expected KEYWORD = value, got {line[:60]!r}", line=line_no, record=key[:40])
        if state == "header":
            check_header(path, key, rest, line_no)
            msg.header[key] = rest
        elif state == "meta":
            check_meta(path, key, rest, line_no)
            seg.meta[key] = rest
        else:
            raise ParseError(path, f"{key} outside any block", line=line_no, record=key)
    if state not in ("between",) or not msg.segments:
        raise ParseError(path, f"file ends inside {state} (no complete META/DATA segment)", line=line_no)
    return msg


def _data_line(path, seg: Segment, key: str, eq: str, rest: str, line_no: int) -> None:
    if not eq:
        raise ParseError(path, f"expected KEYWORD = epoch value, got {key[:60]!r}", line=line_no, record=key[:40])
    check_data_keyword(path, key, line_no)
    fields = rest.split()
    if len(fields) != 2:
        raise ParseError(path, f"{key} needs an epoch and one value, got {rest[:60]!r}", line=line_no, record=key)
    seg.keyword.append(key)
    seg.epoch.append(fields[0])
    seg.value.append(fields[1])
    seg.line.append(line_no)


def render(msg: Message) -> str:
    """KVN text of ``msg``."""
    out = [f"CCSDS_TDM_VERS = {msg.version}"]
    out += [f"COMMENT {c}" for c in msg.comments]
    out += [f"{k} = {v}" for k, v in msg.header.items()]
    for seg in msg.segments:
        out.append("META_START")
        out += [f"COMMENT {c}" for c in seg.meta_comments]
        out += [f"{k} = {v}" for k, v in seg.meta.items()]
        out += ["META_STOP", "DATA_START"]
        out += [f"COMMENT {c}" for c in seg.data_comments]
        out += [f"{k} = {e} {v}" for k, e, v in zip(seg.keyword, seg.epoch, seg.value)]
        out.append("DATA_STOP")
    return "\n".join(out) + "\n"
