"""Shared test set-up: where the real data are, and the ``realdata`` marker's rule.

Real data live in ``../shared/data`` beside the project (``ODPIPE_SHARED_DATA``
overrides). Outside CI, tests marked ``realdata`` skip with a message when the
folder is absent; under ``CI=true`` its absence is a failure.

The files of ``LONGEST_FIRST`` run first, in its order (longest first: a long file started last
would leave one worker running it alone), then the other files holding a test marked ``slow``,
then the rest, each file whole and its tests in their own order, so that ``make test``'s workers
(pytest-xdist, whole files per worker) start the long ones early and finish together.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED_DATA = Path(os.environ.get("ODPIPE_SHARED_DATA", ROOT.parent / "shared" / "data"))
# the longest files, longest first, whether marked slow or not (wall seconds summed over each file's tests in a whole
# make test on the idle machine, 2026-11-26 20:40 UTC: the fault test 17.2, the ground/crosslink study 16.6, the twin
# 11.0, MESSENGER 7.8, the batches 6.7, the libration arc 6.6, the GRAIL arc 6.4, the fuzzing 5.8, then 4.1 to 2.8);
# a scheduling hint only: a file missing here runs after these, with the other slow files or the rest
LONGEST_FIRST = ("test_batch_faults.py", "test_study_ground_and_crosslink.py", "test_demo_twin.py", "test_messenger.py",
                 "test_runs.py", "test_od_long_arc.py", "test_grail_arc.py", "test_readers_fuzz.py",
                 "test_study_dro_leo_dowr.py", "test_nightly_cluster.py", "test_estimation_covariance_realism.py",
                 "test_study_halo_geo_doppler.py", "test_grail_apriori.py", "test_orekit_cases.py", "test_crlb.py",
                 "test_estimation_montecarlo.py")


def _in_ci() -> bool:
    return os.environ.get("CI", "").lower() in ("1", "true", "yes")


def pytest_collection_modifyitems(config, items):
    # Every realdata test goes through the shared_data fixture, which holds the rule.
    for item in items:
        if "realdata" in item.keywords:
            item.add_marker(pytest.mark.usefixtures("shared_data"))
    slow_files = {item.path for item in items if "slow" in item.keywords}
    rank = {name: k for k, name in enumerate(LONGEST_FIRST)}
    # stable: each file stays in one piece
    items.sort(key=lambda item: (rank.get(item.path.name, len(rank)), item.path not in slow_files))


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path of ../shared/data; fails under CI when absent, skips otherwise."""
    if not SHARED_DATA.is_dir():
        if _in_ci():
            pytest.fail(f"CI=true but the real data folder {SHARED_DATA} is absent")
        pytest.skip(f"real data folder {SHARED_DATA} is absent")
    return SHARED_DATA
