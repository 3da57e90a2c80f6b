"""Logging of the ``odpipe`` command: progress and diagnostics on stderr, products on stdout.

Modules log to ``logging.getLogger(__name__)``; the command sets the level of the ``odpipe``
and ``parsers`` loggers and shows other libraries' records (Dask's) only from WARNING up.
Verbosity: -1 (``-q``) warnings and errors, 0 progress (INFO), 1 (``-v``) detail (DEBUG, with
the logger's name).
"""

from __future__ import annotations

import logging
import sys

PACKAGES = ("odpipe", "parsers")
_installed: list[logging.Handler] = []


class _Format(logging.Formatter):
    """INFO as the bare message; other levels prefixed with theirs (and DEBUG with the logger)."""

    def format(self, record: logging.LogRecord) -> str:
        msg = record.getMessage()
        if record.levelno == logging.DEBUG:
            msg = f"debug: {record.name}: {msg}"
        elif record.levelno != logging.INFO:
            msg = f"{record.levelname.lower()}: {msg}"
        if record.exc_info:
            msg += "\n" + self.formatException(record.exc_info)
        return msg


class _Stderr(logging.StreamHandler):
    """A handler writing to whatever ``sys.stderr`` is when a record comes (a test may have swapped it)."""

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, _):
        pass


def _ours_or_warning(record: logging.LogRecord) -> bool:
    """Progress of odpipe and parsers; of other libraries (Dask, numba), only warnings and errors."""
    return record.name.split(".")[0] in PACKAGES or record.levelno >= logging.WARNING


def level(verbosity: int) -> int:
    """The logging level of a verbosity (-v count minus -q count)."""
    return {1: logging.DEBUG, 0: logging.INFO, -1: logging.WARNING}.get(max(-2, min(1, verbosity)), logging.ERROR)


def configure(verbosity: int = 0, stream=None) -> None:
    """Send the odpipe and parsers loggers' records at ``level(verbosity)`` and above to ``stream``
    (default: ``sys.stderr``). Calling again replaces the previous set-up."""
    root = logging.getLogger()
    while _installed:
        root.removeHandler(_installed.pop())
    handler = logging.StreamHandler(stream) if stream is not None else _Stderr()
    handler.setFormatter(_Format())
    handler.addFilter(_ours_or_warning)
    root.addHandler(handler)
    _installed.append(handler)
    for name in PACKAGES:
        logging.getLogger(name).setLevel(level(verbosity))
