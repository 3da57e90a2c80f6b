"""Fuzzing every reader: a few hundred seeded hostile variants of real files (or of the project's own
writers' output) give a result or ParseError, nothing else, each within a time limit (tests/fuzzing.py).
The long run is benchmarks/bench_fuzz.py."""

from __future__ import annotations

import pytest

from tests.fuzzing import READERS, run

# inputs per reader, sized by its CPU cost per input (1 ms OEM .. 23 ms TRK-2-34) and by where its line coverage
# stops growing: the lines of parsers/ that the inputs reach (traced, 2026-11-26) were all reached within the first
# 37 inputs for UTDF, 62 for ODF and 75 for TRK-2-34, so those three run 75, 125 and 75 (were 150, 250, 150: about
# 2.5 s); the others still reached new lines in the second half of their inputs (IONEX at 261 and 269 of 300,
# the maneuver plan at 379 of 400) and keep theirs
INPUTS = {"odf": 125, "utdf": 75, "trk234": 75, "tdm_kvn": 200, "tdm_xml": 250, "trk223": 400, "ionex": 300,
          "maneuver_log": 250, "maneuver_plan": 400, "oem": 400}


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(READERS))
def test_only_parse_errors_and_no_hang(name, shared_data, tmp_path):
    tally = run(name, shared_data, INPUTS[name], seed=1, limit_s=5.0, folder=tmp_path)
    assert tally.inputs == INPUTS[name]
    # the mutations reach past the first check: some inputs are read whole, some refused
    assert 0 < tally.parse_errors < tally.inputs


def test_the_harness_catches_other_exceptions_and_hangs(monkeypatch, tmp_path):
    import time

    from tests import fuzzing

    def reader(fail):
        def read(path, errors):
            if b"\n" in path.read_bytes():
                fail()
            raise fuzzing.ParseError(path, "refused")
        return fuzzing.Reader(read, lambda data: [b"a\nb" * 50], ".txt")

    monkeypatch.setitem(fuzzing.READERS, "raises", reader(lambda: int("x")))
    monkeypatch.setitem(fuzzing.READERS, "hangs", reader(lambda: time.sleep(5)))
    with pytest.raises(fuzzing.Crash, match="ValueError"):
        run("raises", tmp_path, 50)
    with pytest.raises(fuzzing.Crash, match="no answer within 0.2 s"):
        run("hangs", tmp_path, 50, limit_s=0.2)
