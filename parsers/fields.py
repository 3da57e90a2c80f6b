"""Typed fields of one text line, with ParseErrors that name the file, the line and the field.

Shared by the whitespace-separated text readers (ILRS CRD and CPF, Orekit ``.aer``)
and the fixed-column SINEX reader.
"""

from __future__ import annotations

import math
import re

import numpy as np

from parsers.errors import ParseError

MISSING = ("na", "NA")  # CRD/CPF v2 writes "na" for a value not available
_DECIMAL = re.compile(r"\d+(\.\d*)?|\.\d+")


def numbered_lines(path):
    """(1-based line number, text without its line end) of a text file, lines ended by LF or CR LF only.

    Read as latin-1, so every byte is one character and no character (such as
    U+0085 from a UTF-8 byte) starts a line the way ``str.splitlines`` would.
    """
    text = open(path, encoding="latin-1", newline="").read()
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    return [(k, ln[:-1] if ln.endswith("\r") else ln) for k, ln in enumerate(lines, start=1)]


class Fields:
    """The fields of line ``number`` (1-based) of ``path``: ``text.split()`` unless ``fields`` are given.

    ``fixed``: the fields were cut from columns and their names say which (messages then omit "field i").
    """

    def __init__(self, path, number: int, text: str, record: str = "", fields: list[str] | None = None,
                 fixed: bool = False):
        self.path, self.number, self.text, self.record, self.fixed = path, number, text, record, fixed
        self.fields = text.split() if fields is None else fields

    def _label(self, i: int, name: str) -> str:
        return name if self.fixed else f"field {i + 1} ({name})"

    def __len__(self) -> int:
        return len(self.fields)

    def error(self, reason: str) -> ParseError:
        return ParseError(self.path, reason, line=self.number, record=self.record or None)

    def need(self, n: int, what: str) -> None:
        """Refuse a line of fewer than ``n`` fields; ``what`` lists them for the message."""
        if len(self.fields) < n:
            raise self.error(f"expected {n} fields ({what}), found {len(self.fields)}: {self.text.strip()!r}")

    def str(self, i: int, default: str = "") -> str:
        return self.fields[i] if i < len(self.fields) else default

    def int(self, i: int, name: str, default: int | None = None) -> int:
        """Field ``i`` as an integer ('na' -> -1); ``default`` when the line ends before it (None: required)."""
        text = self._get(i, name, default)
        if not isinstance(text, str):
            return text
        if text in MISSING:
            return -1
        try:
            return int(text)
        except ValueError:
            raise self.error(f"{self._label(i, name)} must be an integer, not {text!r}") from None

    def float(self, i: int, name: str, default: float | None = None) -> float:
        """Field ``i`` as a float ('na' -> NaN; Fortran D exponents allowed); ``default`` when absent."""
        text = self._get(i, name, default)
        if not isinstance(text, str):
            return text
        if text in MISSING:
            return math.nan
        try:
            value = float(text.replace("D", "E").replace("d", "e"))
        except ValueError:
            raise self.error(f"{self._label(i, name)} must be a number, not {text!r}") from None
        if math.isnan(value) or math.isinf(value):
            raise self.error(f"{self._label(i, name)} must be a finite number, not {text!r}")
        return value

    def seconds_ns(self, i: int, name: str) -> int:
        """Field ``i``, a non-negative decimal number of seconds, as exact integer nanoseconds."""
        text = self._get(i, name, None)
        if not _DECIMAL.fullmatch(text):
            raise self.error(f"{self._label(i, name)} must be non-negative decimal seconds, not {text!r}")
        whole, _, frac = text.partition(".")
        digits = (frac + "0" * 10)[:10]  # one digit beyond ns, to round
        return int(whole or 0) * 1_000_000_000 + (int(digits) + 5) // 10

    def _get(self, i, name, default):
        if i < len(self.fields):
            return self.fields[i]
        if default is None:
            raise self.error(f"{self._label(i, name)} is missing: {self.text.strip()!r}")
        return default


def date_ns(fields: Fields, i: int, what: str) -> np.datetime64:
    """UTC datetime64[ns] from fields i..i+5 = year, month, day, hour, minute, second (integers)."""
    y, mo, d, h, mi, s = (fields.int(i + k, f"{what} {n}") for k, n in
                          enumerate(("year", "month", "day", "hour", "minute", "second")))
    try:
        day = np.datetime64(f"{y:04d}-{mo:02d}-{d:02d}", "ns")
    except ValueError:
        raise fields.error(f"{what} date {y}-{mo}-{d} is not a calendar date") from None
    if not (0 <= h < 24 and 0 <= mi < 60 and 0 <= s <= 60):
        raise fields.error(f"{what} time {h}:{mi}:{s} out of range")
    return day + np.timedelta64((h * 60 + mi) * 60 + s, "s").astype("timedelta64[ns]")
