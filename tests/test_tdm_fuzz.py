"""Fuzzing the TDM readers: mangled KVN and XML give ParseError (or a table), nothing else."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from parsers import ParseError, tdm

pytestmark = pytest.mark.realdata
_SEEDS = ["kvn/TDMExample8.txt", "xml/TDMExample8.xml", "kvn/TDMExampleAllKeywordsSingleDiff.txt"]
_FUZZ = settings(max_examples=70, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


def _only_parse_error(tmp_path: Path, blob: bytes) -> None:
    path = tmp_path / "fuzz.tdm"
    path.write_bytes(blob)
    for errors in ("raise", "report"):
        try:
            tdm.read(path, errors=errors)
        except ParseError:
            pass


def _seed(shared_data: Path, i: int) -> bytes:
    return (shared_data / "tdm" / _SEEDS[i]).read_bytes()


@_FUZZ
@given(st.integers(0, 2), st.floats(0, 1))
def test_truncated(tmp_path, shared_data, i, frac):
    raw = _seed(shared_data, i)
    _only_parse_error(tmp_path, raw[:int(len(raw) * frac)])


@_FUZZ
@given(st.integers(0, 2), st.lists(st.tuples(st.floats(0, 1), st.sampled_from(list(b"=<>/ \n\t-.:TZ0123456789AEx&"))),
                                   min_size=1, max_size=6))
def test_mangled(tmp_path, shared_data, i, edits):
    raw = bytearray(_seed(shared_data, i))
    for where, byte in edits:
        raw[min(int(where * len(raw)), len(raw) - 1)] = byte
    _only_parse_error(tmp_path, bytes(raw))


@_FUZZ
@given(st.binary(max_size=512), st.booleans())
def test_random(tmp_path, shared_data, blob, as_xml):
    _only_parse_error(tmp_path, (b"<?xml version='1.0'?><tdm>" if as_xml else b"CCSDS_TDM_VERS = 2.0\n") + blob)
