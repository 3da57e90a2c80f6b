"""Wall seconds numba spends compiling (cache loads excluded), for progress reports.

Every ``@njit`` kernel is cached on disk (``cache=True``): a fresh checkout compiles
each one once, later processes load it. ``with compile_timer() as ct:`` sums the
outermost compilations in this process while the block runs (``ct.seconds``, s)
and counts every function compiled, nested ones included (``ct.functions``).
"""

from __future__ import annotations

import time
from contextlib import contextmanager

from numba.core import event


class CompileTimer(event.Listener):
    """Listener of ``numba:compile`` events: outermost wall seconds and functions compiled."""

    def __init__(self):
        self.seconds = 0.0
        self.functions = 0
        self._depth = 0
        self._t0 = 0.0

    def on_start(self, ev):
        if self._depth == 0:
            self._t0 = time.perf_counter()
        self._depth += 1

    def on_end(self, ev):
        self._depth -= 1
        self.functions += 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._t0


@contextmanager
def compile_timer():
    """Context manager yielding a :class:`CompileTimer` that listens while the block runs."""
    timer = CompileTimer()
    with event.install_listener("numba:compile", timer):
        yield timer
