"""The one exception every reader raises for malformed input."""

from __future__ import annotations


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
