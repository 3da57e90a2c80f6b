"""The one exception every reader raises for malformed input, and the checks every reader shares."""

from __future__ import annotations

import math
import re
from pathlib import Path

_INTEGER = re.compile(r"[-+]?\d{1,18}", re.ASCII)


class ParseError(ValueError):
    """Malformed input, located in the file.

    Attributes: ``path`` (file name), ``offset`` (byte offset, binary formats),
    ``line`` (1-based line number, text formats), ``record`` (record index or
    keyword) and ``reason`` (what was wrong).
    """

    def __init__(self, path, reason, *, offset=None, line=None, record=None):
        self.path = str(path)
        self.reason = reason
        self.offset = offset
        self.line = line
        self.record = record
        where = [self.path]
        if line is not None:
            where.append(f"line {line}")
        if offset is not None:
            where.append(f"byte {offset}")
        if record is not None:
            where.append(f"record {record}")
        super().__init__(f"{', '.join(where)}: {reason}")

    def __reduce__(self):
        # Rebuilt from its fields, so it survives pickling (Dask workers, copies of DataFrame.attrs).
        return _rebuild, (self.path, self.reason, self.offset, self.line, self.record)


def _rebuild(path, reason, offset, line, record) -> ParseError:
    return ParseError(path, reason, offset=offset, line=line, record=record)


class ParseReport:
    """What a reader in ``errors="report"`` mode skipped: a list of ParseError."""

    def __init__(self):
        self.errors: list[ParseError] = []

    def add(self, err: ParseError) -> None:
        self.errors.append(err)

    def __len__(self) -> int:
        return len(self.errors)

    def __iter__(self):
        return iter(self.errors)


def check_mode(errors: str) -> None:
    """Refuse an ``errors`` argument other than "raise" or "report" before any reading starts."""
    if errors not in ("raise", "report"):
        raise ValueError(f"errors must be 'raise' or 'report', not {errors!r}")


def handle(err: ParseError, errors: str, report: ParseReport | None) -> None:
    """Raise ``err`` (errors="raise") or record it in ``report`` (errors="report")."""
    check_mode(errors)
    if errors == "raise":
        raise err
    if report is not None:
        report.add(err)


def read_text(path, encoding: str = "utf-8") -> str:
    """The text of file ``path``: ParseError when it is empty (or blank) or not ``encoding`` (byte offset)."""
    return decode(Path(path).read_bytes(), path, encoding)


def decode(raw: bytes, path, encoding: str = "utf-8") -> str:
    """``raw`` decoded strictly; ParseError naming the first bad byte, or an empty (blank) file."""
    try:
        text = raw.decode(encoding)
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise ParseError(path, f"byte {raw[exc.start:exc.start + 1]!r} is not {encoding} text",
                         offset=exc.start, line=line) from None
    if not text.strip():
        raise ParseError(path, "empty file", offset=0)
    return text


def finite(text: str, path, what: str, **where) -> float:
    """``text`` as a finite float; ParseError (naming ``what`` and ``where``) for anything else (1e400, nan)."""
    try:
        value = float(text)
    except (ValueError, TypeError):
        raise ParseError(path, f"{what}: {str(text)[:40]!r} is not a number", **where) from None
    if not math.isfinite(value):
        raise ParseError(path, f"{what}: {str(text)[:40]!r} is not a finite number", **where)
    return value


def integer(text: str, path, what: str, lo: int, hi: int, **where) -> int:
    """``text`` as an integer in [lo, hi]; ParseError otherwise (also for 5000-digit numbers)."""
    s = str(text).strip()
    if not _INTEGER.fullmatch(s):
        raise ParseError(path, f"{what}: {s[:40]!r} is not an integer", **where)
    value = int(s)
    if not lo <= value <= hi:
        raise ParseError(path, f"{what}: {value} is outside [{lo}, {hi}]", **where)
    return value
