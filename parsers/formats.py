"""Which format is this file? Ask each reader module's ``sniff``, in a fixed order.

Reader modules are imported lazily by name; one that does not exist (yet) or
has no ``sniff`` is skipped.
"""

from __future__ import annotations

import importlib
from pathlib import Path

from parsers.errors import ParseError

READERS = ("parsers.odf", "parsers.utdf", "parsers.trk234", "parsers.tdm", "parsers.trk223", "parsers.ionex",
           "parsers.maneuvers", "parsers.crd", "parsers.cpf", "parsers.sinex", "parsers.aer")
HEAD_BYTES = 65536


def _module(name: str):
    try:
        mod = importlib.import_module(name)
    except ModuleNotFoundError as exc:
        if exc.name == name:
            return None
        raise
    return mod if hasattr(mod, "sniff") and hasattr(mod, "read") else None


def available() -> list[str]:
    """Names of the reader modules present with ``sniff`` and ``read``."""
    return [n for n in READERS if _module(n) is not None]


def detect(path) -> str | None:
    """Name of the first reader module whose ``sniff`` accepts the file's first bytes, else None."""
    with open(path, "rb") as f:
        head = f.read(HEAD_BYTES)
    for name in READERS:
        mod = _module(name)
        if mod is not None and mod.sniff(head):
            return name
    return None


def unrecognised(path) -> ParseError:
    """The error for a file no reader recognises: an empty one said so (a truncated copy, a failed download)."""
    if Path(path).stat().st_size == 0:
        return ParseError(Path(path), "empty file (0 bytes)")
    return ParseError(Path(path), f"format not recognised (readers available: {', '.join(available())})")


def read_any(path, errors: str = "raise"):
    """Read ``path`` with the reader that recognises it; ParseError when none does."""
    name = detect(path)
    if name is None:
        raise unrecognised(path)
    return importlib.import_module(name).read(path, errors=errors)
