"""Fuzzing every reader: a few hundred seeded hostile variants of real files (or of the project's own
writers' output) give a result or ParseError, nothing else, each within a time limit (tests/fuzzing.py).
The long run is benchmarks/bench_fuzz.py."""

from __future__ import annotations

import pytest

from tests.fuzzing import READERS, run

# inputs per reader, sized by its CPU cost per input (1 ms OEM .. 23 ms TRK-2-34): about 16 s for all ten
INPUTS = {"odf": 250, "utdf": 150, "trk234": 150, "tdm_kvn": 200, "tdm_xml": 250, "trk223": 400, "ionex": 300,
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
