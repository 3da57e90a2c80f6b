"""OEM reader on the project's own writer's output: hostile bytes and numbers are ParseErrors naming the line."""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.products.segments import EphemerisSegment
from odpipe.products.oem import format_oem
from parsers import ParseError, ParseReport, oem


@pytest.fixture
def oem_text():
    t = np.arange(5) * 60.0 + 3.9e8
    states = np.column_stack([7e6 + t * 0, t - 3.9e8, t * 0, t * 0, t * 0 + 7.5e3, t * 0 + 1.0])
    return format_oem([EphemerisSegment(t, states, "earth")], "SAT", "2099-001A", creation_date="2026-01-01T00:00:00")


def _data_lines(text):
    return [i for i, ln in enumerate(text.splitlines()) if ln[:4].isdigit()]


def test_written_states_read_back(oem_text, tmp_path):
    p = tmp_path / "x.oem"
    p.write_text(oem_text)
    seg, = oem.read(p)
    assert seg.states.shape == (5, 6) and seg.states[3, 1] == pytest.approx(180.0) and seg.meta["OBJECT_ID"] == "2099-001A"


@pytest.mark.parametrize("bad, words", [("1e400", "finite"), ("nan", "finite"), ("x", "not a number")])
def test_bad_state_number_is_refused_or_reported(oem_text, tmp_path, bad, words):
    lines = oem_text.splitlines()
    k = _data_lines(oem_text)[2]
    fields = lines[k].split()
    lines[k] = " ".join(fields[:3] + [bad] + fields[4:])
    p = tmp_path / "x.oem"
    p.write_text("\n".join(lines))
    with pytest.raises(ParseError, match=words) as err:
        oem.read(p)
    assert err.value.line == k + 1
    report = ParseReport()
    seg, = oem.read(p, errors="report", report=report)
    assert len(seg.epochs) == 4 and [e.line for e in report] == [k + 1]


def test_bad_byte_and_absurd_epoch(oem_text, tmp_path):
    raw = oem_text.encode()
    at = raw.index(b"OBJECT_NAME")
    p = tmp_path / "x.oem"
    p.write_bytes(raw[:at] + b"\xe9" + raw[at:])  # one latin-1 byte in a UTF-8 file
    with pytest.raises(ParseError, match="utf-8") as err:
        oem.read(p)
    assert err.value.offset == at
    lines = oem_text.splitlines()
    k = _data_lines(oem_text)[0]
    lines[k] = "0000" + lines[k][4:]  # year 0: datetime64[ns] would wrap it to 1753
    p.write_text("\n".join(lines))
    with pytest.raises(ParseError, match="outside") as err:
        oem.read(p)
    assert err.value.line == k + 1
    p.write_bytes(b"")
    with pytest.raises(ParseError, match="empty"):
        oem.read(p, errors="report")
