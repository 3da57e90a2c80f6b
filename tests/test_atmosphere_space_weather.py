"""Space-weather files: MSFC's MSAFE table (Orekit's W3B case file), CelesTrak's CSSI file (an excerpt in
Orekit's tests, fixtures/cssi), and the inputs they give NRLMSISE-00."""

import re
from pathlib import Path

import numpy as np
import pytest

from odpipe.environment.atmosphere.space_weather import DailyRecords, MonthlyForecast, open_space_weather
from odpipe.time import utc_to_tdb
from parsers.errors import ParseError
from parsers.spaceweather import read_cssi, read_msafe


@pytest.fixture(scope="module")
def msafe(shared_data):
    return shared_data / "orekit_od" / "W3B" / "Oct2010F10.txt"


def test_rows_and_columns_of_the_real_file(msafe):
    text = msafe.read_text().splitlines()
    rows = [ln for ln in text if re.match(r"\s*\d{4}\.\d{4}\s", ln)]
    table = read_msafe(msafe)
    assert len(table.epoch) == len(rows)
    # the file's rows: " 2010.8337   NOV   109.0      92.6      78.2       7.6       5.6       3.6"
    k = int(np.flatnonzero(table.epoch == np.datetime64("2010-11-01", "ns"))[0])
    assert (table.f107[k], table.ap[k]) == (92.6, 5.6)
    assert str(table.epoch[0])[:10] == "2010-04-01" and str(table.epoch[-1])[:10] == "2030-10-01"
    high = read_msafe(msafe, "95%")
    assert (high.f107[k], high.ap[k]) == (109.0, 7.6)


def test_nrlmsise_inputs_interpolate_between_month_starts(msafe):
    weather = open_space_weather(msafe)
    assert isinstance(weather, MonthlyForecast) and weather.table.level == "50%"
    t = float(utc_to_tdb(np.datetime64("2010-11-16T00:00:00", "ns")))
    f107, f107a, ap = weather.nrlmsise_inputs(t)[0]
    # NOV 92.6 / 5.6 and DEC 95.2 / 5.8 (50 %), 30 days apart: day 15 for the mean, day 14 for the day before
    assert f107a == pytest.approx(92.6 + 2.6 * 15 / 30, abs=1e-6)
    assert f107 == pytest.approx(92.6 + 2.6 * 14 / 30, abs=1e-6)
    assert ap == pytest.approx(5.6 + 0.2 * 15 / 30, abs=1e-6)
    with pytest.raises(ValueError, match="Oct2010F10.txt"):
        weather.nrlmsise_inputs(float(utc_to_tdb(np.datetime64("2031-01-01", "ns"))))


@pytest.mark.parametrize("line, message", [
    (" 2010.8337   NOX    109.0      92.6      78.2       7.6       5.6       3.6", "month"),
    (" 2010.5003   NOV    109.0      92.6      78.2       7.6       5.6       3.6", "not in NOV"),
    (" 2010.8337   NOV    109.0      92.6      78.2       7.6       5.6", "expected 8 fields"),
    (" 2010.8337   NOV    109.0      x92.6     78.2       7.6       5.6       3.6", "F10.7 50%"),
    (" 2010.8337   NOV    109.0      -2.0      78.2       7.6       5.6       3.6", "positive"),
])
def test_bad_rows_name_the_file_and_line(tmp_path, line, message):
    path = tmp_path / "bad.txt"
    path.write_text("  TABLE 3\n\n 2010.7503   OCT   103.7      90.2      77.3       7.1       5.5       3.1\n"
                    + line + "\n")
    with pytest.raises(ParseError, match=rf"bad.txt, line 4: .*{message}"):
        read_msafe(path)


def test_months_out_of_order_and_too_few_rows(tmp_path):
    path = tmp_path / "order.txt"
    path.write_text(" 2010.8337   NOV   109.0  92.6  78.2  7.6  5.6  3.6\n"
                    " 2010.7503   OCT   103.7  90.2  77.3  7.1  5.5  3.1\n")
    with pytest.raises(ParseError, match="order.txt, line 2: OCT 2010 does not follow"):
        read_msafe(path)
    path.write_text("  TABLE 3\n 2010.8337   NOV   109.0  92.6  78.2  7.6  5.6  3.6\n")
    with pytest.raises(ParseError, match="order.txt: expected at least two monthly rows"):
        read_msafe(path)


CSSI = Path(__file__).parent.parent / "fixtures" / "cssi" / "SpaceWeather-All-v1.2_reduced.txt"


def _without_the_repeated_day(tmp_path):
    lines = CSSI.read_text().split("\n")
    assert lines[21] == lines[22]                 # 2020-02-21 twice in Orekit's excerpt
    path = tmp_path / "cssi.txt"
    path.write_text("\n".join(lines[:22] + lines[23:]))
    return path


def test_cssi_repeated_day_names_the_line():
    with pytest.raises(ParseError, match=r"SpaceWeather-All-v1.2_reduced.txt, line 23: 2020-02-21 does not follow"):
        read_cssi(CSSI)


def test_cssi_records_and_nrlmsise_inputs(tmp_path):
    path = _without_the_repeated_day(tmp_path)
    # the file's 2020-02-20 line: 3-hourly Ap 7 15 7 4 7 4 7 18, daily 9, observed F10.7 71.6, Ctr81 72.9
    d = read_cssi(path)
    assert [str(e)[:10] for e in d.epoch] == ["2020-02-19", "2020-02-20", "2020-02-21", "2020-02-22"]
    assert d.ap_3h[1].tolist() == [7, 15, 7, 4, 7, 4, 7, 18] and d.ap[1] == 9
    assert (d.f107[1], d.f107_ctr81[1]) == (71.6, 72.9)
    weather = open_space_weather(path)
    assert isinstance(weather, DailyRecords)
    t = float(utc_to_tdb(np.datetime64("2020-02-21T18:00:00", "ns")))
    assert weather.nrlmsise_inputs(t)[0].tolist() == [71.6, 72.7, 13.0]   # 02-20's flux; 02-21's mean and Ap
    with pytest.raises(ValueError, match="cssi.txt"):
        weather.nrlmsise_inputs(float(utc_to_tdb(np.datetime64("2020-02-19T12:00:00", "ns"))))   # no 02-18


@pytest.mark.parametrize("column, text, message", [
    (slice(112, 118), "  x1.0", "observed F10.7 must be a number"),
    (slice(4, 7), " 13", "no such date"),
    (slice(46, 50), "    ", "eight 3-hourly Ap"),
])
def test_cssi_bad_fields_name_the_file_and_line(tmp_path, column, text, message):
    lines = _without_the_repeated_day(tmp_path).read_text().split("\n")
    row = lines[20]
    lines[20] = row[:column.start] + text + row[column.stop:]
    path = tmp_path / "bad.txt"
    path.write_text("\n".join(lines))
    with pytest.raises(ParseError, match=rf"bad.txt, line 21: .*{message}"):
        read_cssi(path)
