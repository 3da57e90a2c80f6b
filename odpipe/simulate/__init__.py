"""Simulated tracking: truth, schedules, observables with errors, and their files; the project's one simulator.

:func:`run_case` loads a case file (:mod:`.case`), propagates the truth (:mod:`.truth`),
schedules passes (:mod:`.schedule`), simulates observables (:mod:`.observe`) with the
TRK-2-23 troposphere and ionosphere (:mod:`.calibrations`) and writes everything (:mod:`.files`).
:func:`.observe.simulate_tracking` simulates a :class:`.schedule.TrackingPlan` (every station while
the spacecraft is above the mask) of a given trajectory, for fits against the truth. Both make their
values with :func:`.observe.simulate_values`.
"""

from odpipe.simulate.run import run_case

__all__ = ["run_case"]
