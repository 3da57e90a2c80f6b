"""A process's exit without the interpreter's last garbage collections.

At exit Python collects garbage over every object still alive, then again while it tears the modules down:
0.3-0.5 s for a process that imported a run, about 1 s after an arc or a night's report. Objects alive at
exit are frozen instead (:func:`gc.freeze`), so those collections pass them over (0.05-0.1 s); they are still
freed by reference counting, and every other ``atexit`` handler still runs (flushing logs and files). The
``odpipe`` command asks for it; a batch's workers, forked from a server process, end without any of it.
"""

from __future__ import annotations

import atexit
import gc

_registered: list[bool] = []


def skip_final_collection() -> None:
    """From now on, this process exits without collecting the objects alive at its exit (registered once)."""
    if not _registered:
        atexit.register(gc.freeze)
        _registered.append(True)
