"""Simulated tracking cases (issue 10): truth, schedules, observables with errors, and their files.

:func:`run_case` loads a case file (:mod:`.case`), propagates the truth (:mod:`.truth`),
schedules passes (:mod:`.schedule`), simulates observables (:mod:`.observe`) with the
TRK-2-23 troposphere and ionosphere (:mod:`.calibrations`) and writes everything (:mod:`.files`).
"""

from odpipe.simulate.run import run_case

__all__ = ["run_case"]
