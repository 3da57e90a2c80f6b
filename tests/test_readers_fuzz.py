"""Fuzzing every reader: a few hundred seeded hostile variants of real files (or of the project's own
writers' output) give a result or ParseError, nothing else, each within a time limit (tests/fuzzing.py).
The long run is benchmarks/bench_fuzz.py."""

from __future__ import annotations

import pytest

from tests.fuzzing import READERS, run

# inputs per reader: about 1.5 s each on one core, 15 s for the ten readers
INPUTS = {"odf": 250, "utdf": 300, "trk234": 300, "tdm_kvn": 250, "tdm_xml": 250, "trk223": 300, "ionex": 150,
          "maneuver_log": 200, "maneuver_plan": 300, "oem": 300}


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(READERS))
def test_only_parse_errors_and_no_hang(name, shared_data, tmp_path):
    tally = run(name, shared_data, INPUTS[name], seed=1, limit_s=5.0, folder=tmp_path)
    assert tally.inputs == INPUTS[name]
    # the mutations must reach past the first check: some inputs are refused, some are read
    assert 0 < tally.parse_errors < tally.inputs
