"""The TDM message as read from KVN or XML: header, segments of metadata and data lines.

Both syntaxes fill the same :class:`Message`; values stay text here, each with its line
number, and every keyword is checked as it is met so a :class:`parsers.ParseError` names
the file, line and keyword of the first fault (as Orekit's parser does).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from parsers.errors import ParseError, finite
from parsers.tdm import keywords as kw
from parsers.tdm import times

_PATH = re.compile(r"^[1-5](,[1-5])+$")
_EPOCH = re.compile(times.EPOCH[:-1] + "Z?$")


@dataclass
class Segment:
    """One metadata block and its data lines (keyword, epoch text, value text, line)."""

    meta: dict[str, str] = field(default_factory=dict)
    meta_comments: list[str] = field(default_factory=list)
    data_comments: list[str] = field(default_factory=list)
    keyword: list[str] = field(default_factory=list)
    epoch: list[str] = field(default_factory=list)
    value: list[str] = field(default_factory=list)
    line: list[int] = field(default_factory=list)


@dataclass
class Message:
    """A whole TDM: version, header keywords and comments, segments."""

    version: str = "2.0"
    header: dict[str, str] = field(default_factory=dict)
    comments: list[str] = field(default_factory=list)
    segments: list[Segment] = field(default_factory=list)


def check_header(path, key: str, value: str, line: int) -> None:
    if key not in kw.HEADER:
        raise ParseError(path, f"unexpected header keyword {key}", line=line, record=key)
    if key == "CREATION_DATE" and not _EPOCH.match(value):
        raise ParseError(path, f"CREATION_DATE {value!r} is not a CCSDS epoch", line=line, record=key)


def check_meta(path, key: str, value: str, line: int) -> None:
    """Raise ParseError unless ``key = value`` is a valid TDM metadata line."""
    if key not in kw.METADATA:
        raise ParseError(path, f"unexpected metadata keyword {key}", line=line, record=key)
    if key in kw.NUMBER:
        finite(value, path, key, line=line, record=key)
    elif key in kw.TIME and not _EPOCH.match(value):
        raise ParseError(path, f"{key} = {value!r} is not a CCSDS epoch", line=line, record=key)
    elif key in kw.PATH and not _PATH.match(value):
        raise ParseError(path, f"{key} = {value!r} is not a list of participant numbers like 1,2,1",
                         line=line, record=key)
    elif key in kw.CHOICE and value not in kw.CHOICE[key]:
        raise ParseError(path, f"{key} = {value!r} is not one of {sorted(kw.CHOICE[key])}", line=line, record=key)


def close_meta(path, seg: Segment, line: int) -> None:
    """Check what a finished metadata block must hold."""
    for key in ("TIME_SYSTEM", "PARTICIPANT_1"):
        if key not in seg.meta:
            raise ParseError(path, f"metadata block has no {key}", line=line, record=key)


def check_data_keyword(path, key: str, line: int) -> None:
    if key not in kw.DATA:
        raise ParseError(path, f"unexpected data keyword {key}", line=line, record=key)
