"""Exit statuses of the ``odpipe`` command and the one-line description of an error.

An expected error (bad input, a wrong configuration, a fit that failed) is told in
one line that names the file, key or record; anything else is a bug, said so.
"""

from __future__ import annotations

import sys
from enum import IntEnum


class Exit(IntEnum):
    """Exit statuses of ``odpipe``; the meaning of each is its docstring line in :data:`MEANING`."""

    OK = 0
    INTERNAL = 1
    INPUT = 2
    FIT = 3
    PARTIAL = 4
    INTERRUPTED = 130


MEANING = {
    Exit.OK: "success",
    Exit.INTERNAL: "internal error (a bug: rerun with --debug for the traceback) or a system error",
    Exit.INPUT: "bad input: usage, configuration, a missing, unreadable or malformed file, a bad value",
    Exit.FIT: "the fit failed (diverged, did not converge, or nothing was left to fit)",
    Exit.PARTIAL: "some arcs of a batch, or some studies, failed (the others ran; see the summary and the report)",
    Exit.INTERRUPTED: "interrupted (Ctrl-C)",
}

_INPUT_OS_ERRORS = (FileNotFoundError, PermissionError, IsADirectoryError, NotADirectoryError)


DEBUG_HINT = "rerun with --debug for the traceback"


def describe(exc: BaseException, hint: str = DEBUG_HINT) -> tuple[Exit, str]:
    """The exit status an error gives and its one-line message (``hint``: where a bug's traceback is)."""
    fit = sys.modules.get("odpipe.estimation.fit")  # not imported: no fit ran (and importing it takes seconds)
    text = " ".join(str(exc).split())
    if fit is not None and isinstance(exc, fit.FitDiverged):
        return Exit.FIT, f"fit failed: {text}"
    if isinstance(exc, OSError) and exc.strerror:
        where = f"{exc.filename}: " if exc.filename is not None else ""
        return (Exit.INPUT if isinstance(exc, _INPUT_OS_ERRORS) else Exit.INTERNAL), f"{where}{exc.strerror}"
    if isinstance(exc, ValueError) and text:  # ParseError and ConfigError are ValueErrors that name the place
        return Exit.INPUT, text
    return Exit.INTERNAL, f"internal error ({type(exc).__name__}: {text or repr(exc)}); this is a bug: {hint}"
