"""The nightly batch under SIGKILL: the short version of ``benchmarks/bench_faults.py`` (2 kills).

Three simulated 6-h arcs (two rounds of the cluster's two workers, so a kill can land between an arc
finishing and the next starting) run as ``odpipe batch`` on a local Dask cluster; the whole process group is
killed at random moments after the run's first arc has started, and the batch rerun. ``fault_loop`` asserts,
after every kill, that no finished arc was lost or redone and every ``current`` verifies; for every night that
ends, that each arc was fitted exactly once, every product parses, the night's report is complete and no
temporary file is left.
"""

import pytest

from benchmarks.bench_faults import fault_loop

ARCS = 3


@pytest.mark.slow
def test_a_batch_killed_at_random_moments_loses_nothing_and_fits_each_arc_once(tmp_path):
    # kills 0.5-3 s after the first arc of the run has started (seed 1: 1.8 and 2.9 s), so both land among the fits
    # whatever the load makes of the batch's start-up. Measured 2026-11-26 18:32 at a load of 3.8: the first arcs
    # started 4-5 s after the batch and took 9-11 s (their workers' imports and kernel loads), both kills landed
    # while the first two arcs were being fitted (5 processes killed, 2 abandoned attempts cleaned each, 0 arcs
    # done), 36 s in all. Counted from the batch's start (2-8 s, before), the first kill landed in the start-up at
    # that load, and on the idle machine the second run (7.7 s) outlived the 7-s night, costing a night more. A kill
    # between arcs, finished arcs kept: tests/test_runs.py's killed batch. (A CI run with 5-100 s delays from the
    # start completed 49 nights before its third kill landed, in 12.6 min.)
    s = fault_loop(tmp_path, kills=2, arcs=ARCS, min_delay=0.5, max_delay=3.0, seed=1, say=lambda line: None,
                   from_fit=True)
    assert s["kills"] == 2 and s["processes_killed"] >= 2   # at least the client each time
    assert s["nights"] >= 1 and s["products_parsed"] >= s["nights"] * ARCS * 15
