"""TDM in XML: text <-> :class:`Message`.

Parsed with expat, which here never loads anything from outside the file: a DOCTYPE or
ENTITY declaration is refused with ParseError before any of it is acted on.
"""

from __future__ import annotations

from xml.parsers import expat
from xml.sax.saxutils import escape, quoteattr

from parsers.errors import ParseError, ParseReport, handle
from parsers.tdm.message import (Message, Segment, check_data_keyword, check_header, check_meta,
                                 close_meta)


class _Node:
    __slots__ = ("tag", "attrs", "text", "line", "children")

    def __init__(self, tag, attrs, line):
        self.tag, self.attrs, self.line, self.text, self.children = tag, attrs, line, [], []


def _tree(data: bytes, path) -> _Node:
    p = expat.ParserCreate()
    p.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    stack: list[_Node] = []
    root: list[_Node] = []

    def refuse(what):
        def handler(*_):
            raise ParseError(path, f"{what} declarations are not allowed in a TDM", line=p.CurrentLineNumber,
                             record=what)
        return handler

    def start(tag, attrs):
        node = _Node(tag, attrs, p.CurrentLineNumber)
        (stack[-1].children if stack else root).append(node)
        stack.append(node)

    def end(_tag):
        stack.pop()

    def text(s):
        if stack:
            stack[-1].text.append(s)

    p.StartDoctypeDeclHandler = refuse("DOCTYPE")
    p.EntityDeclHandler = refuse("ENTITY")
    p.ExternalEntityRefHandler = refuse("external entity")
    p.StartElementHandler, p.EndElementHandler, p.CharacterDataHandler = start, end, text
    try:
        p.Parse(data, True)
    except expat.ExpatError as err:
        raise ParseError(path, f"malformed XML: {expat.errors.messages[err.code]}", line=err.lineno) from None
    except LookupError as err:  # an XML declaration naming an unknown encoding
        raise ParseError(path, f"malformed XML: {err}", line=1) from None
    return root[0]


def _value(node: _Node) -> str:
    return "".join(node.text).strip()


def parse(data: bytes, path, errors: str = "raise", report: ParseReport | None = None) -> Message:
    """The :class:`Message` in XML ``data``; ParseError on the first malformed element.

    With ``errors="report"`` a malformed ``<observation>`` is reported and skipped; other faults raise.
    """
    root = _tree(data, path)
    if root.tag != "tdm":
        raise ParseError(path, f"root element is <{root.tag}>, not <tdm>", line=root.line, record=root.tag)
    msg = Message(version=root.attrs.get("version", ""))
    for part in root.children:
        if part.tag == "header":
            for n in part.children:
                if n.tag == "COMMENT":
                    msg.comments.append(_value(n))
                else:
                    check_header(path, n.tag, _value(n), n.line)
                    msg.header[n.tag] = _value(n)
        elif part.tag == "body":
            for s in part.children:
                if s.tag != "segment":
                    raise ParseError(path, f"unexpected <{s.tag}> in body", line=s.line, record=s.tag)
                msg.segments.append(_segment(s, path, errors, report))
        else:
            raise ParseError(path, f"unexpected <{part.tag}> in tdm", line=part.line, record=part.tag)
    if not msg.segments:
        raise ParseError(path, "no segment", line=root.line, record="segment")
    return msg


def _segment(node: _Node, path, errors, report) -> Segment:
    seg = Segment()
    for block in node.children:
        if block.tag == "metadata":
            for n in block.children:
                if n.tag == "COMMENT":
                    seg.meta_comments.append(_value(n))
                    continue
                check_meta(path, n.tag, _value(n), n.line)
                seg.meta[n.tag] = _value(n)
            close_meta(path, seg, block.line)
        elif block.tag == "data":
            for obs in block.children:
                if obs.tag == "COMMENT":
                    seg.data_comments.append(_value(obs))
                    continue
                try:
                    _observation(obs, seg, path)
                except ParseError as err:
                    handle(err, errors, report)
        else:
            raise ParseError(path, f"unexpected <{block.tag}> in segment", line=block.line, record=block.tag)
    return seg


def _observation(obs: _Node, seg: Segment, path) -> None:
    if obs.tag != "observation":
        raise ParseError(path, f"unexpected <{obs.tag}> in data", line=obs.line, record=obs.tag)
    epoch = [n for n in obs.children if n.tag == "EPOCH"]
    values = [n for n in obs.children if n.tag != "EPOCH"]
    for n in values:
        check_data_keyword(path, n.tag, n.line)
    if len(epoch) != 1 or len(values) != 1:
        at = values[0] if values else obs
        raise ParseError(path, "an observation needs one EPOCH and one value", line=at.line, record=at.tag)
    seg.keyword.append(values[0].tag)
    seg.epoch.append(_value(epoch[0]))
    seg.value.append(_value(values[0]))
    seg.line.append(values[0].line)


def render(msg: Message) -> str:
    """XML text of ``msg``."""
    def el(tag, value, pad):
        return f"{pad}<{tag}>{escape(value)}</{tag}>"

    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f'<tdm id="CCSDS_TDM_VERS" version={quoteattr(msg.version)}>', "  <header>"]
    out += [el("COMMENT", c, "    ") for c in msg.comments]
    out += [el(k, v, "    ") for k, v in msg.header.items()]
    out += ["  </header>", "  <body>"]
    for seg in msg.segments:
        out += ["    <segment>", "      <metadata>"]
        out += [el("COMMENT", c, "        ") for c in seg.meta_comments]
        out += [el(k, v, "        ") for k, v in seg.meta.items()]
        out += ["      </metadata>", "      <data>"]
        out += [el("COMMENT", c, "        ") for c in seg.data_comments]
        out += [f"        <observation><EPOCH>{e}</EPOCH><{k}>{v}</{k}></observation>"
                for k, e, v in zip(seg.keyword, seg.epoch, seg.value)]
        out += ["      </data>", "    </segment>"]
    out += ["  </body>", "</tdm>"]
    return "\n".join(out) + "\n"
