"""IONEX reader on the real AIUB file and Orekit's split and corrupted variants."""

import numpy as np
import pytest

from parsers.errors import ParseError
from parsers.ionex import read_ionex

pytestmark = pytest.mark.realdata


def test_header_and_grid(shared_data):
    m = read_ionex(shared_data / "ionex" / "gpsg0150.19i")
    # header of gpsg0150.19i: 25 hourly maps 2019-01-15 00:00 .. 01-16 00:00, 350 km shell, R 6371 km
    assert m.tec.shape == (25, 1, 71, 73)
    assert m.epochs[0] == np.datetime64("2019-01-15T00:00") and m.epochs[-1] == np.datetime64("2019-01-16T00:00")
    assert m.interval_s == 3600.0 and m.height_m[0] == 350e3 and m.base_radius_m == 6371e3
    assert m.lat_deg[0] == 87.5 and m.lat_deg[-1] == -87.5 and m.lon_deg[0] == -180 and m.lon_deg[-1] == 180
    assert m.mapping_function == "NONE" and m.rms is None


def test_grid_values_match_orekit_documented_cells(shared_data):
    # Orekit GlobalIonosphereMapModelTest.testTimeInterpolation reads these raw cells (0.1 TECU)
    # at 55N: 14:00 lon 15E -> 103; 14:00 lon 20E/25E -> 104/105; 15:00 lon 10E/5E -> 101/100.
    m = read_ionex(shared_data / "ionex" / "gpsg0150.19i")
    k14 = np.flatnonzero(m.epochs == np.datetime64("2019-01-15T14:00"))[0]
    ilat = np.flatnonzero(m.lat_deg == 55.0)[0]
    col = {lon: np.flatnonzero(m.lon_deg == lon)[0] for lon in (5, 10, 15, 20, 25)}
    assert m.tec[k14, 0, ilat, col[15]] == pytest.approx(10.3)
    assert m.tec[k14, 0, ilat, [col[20], col[25]]] == pytest.approx([10.4, 10.5])
    assert m.tec[k14 + 1, 0, ilat, [col[10], col[5]]] == pytest.approx([10.1, 10.0])


def test_split_files_combine_to_the_whole(shared_data):
    d = shared_data / "ionex"
    whole = read_ionex(d / "gpsg0150.19i")
    split = read_ionex(d / "split-3.19i", d / "split-1.19i", d / "split-2.19i")
    assert split.epochs.size == 7          # 00:00..06:00, shared boundary maps merged once
    np.testing.assert_array_equal(split.epochs, whole.epochs[:7])
    np.testing.assert_array_equal(split.tec, whole.tec[:7])


def test_jammed_fields_read_as_fixed_width_with_exponent(shared_data):
    m = read_ionex(shared_data / "ionex" / "jammed-fields.14i")
    # line "1015710167 9847 ..." at 22.5N with EXPONENT -2
    assert m.tec[0, 0, 1, :3] == pytest.approx([101.57, 101.67, 98.47])
    assert m.base_radius_m == 6378.1e3 and m.height_m[0] == 400e3


@pytest.mark.parametrize("name, line, words", [
    ("corrupted-bad-data-gpsg0150.19i", 22, "bad value"),
    ("missing-epoch-header-gpsg0150.19i", 16, "EPOCH OF FIRST MAP"),
    ("missing-lat-lon-header-gpsg0150.19i", 16, "LAT1 / LAT2 / DLAT"),
])
def test_corrupted_files_name_file_and_line(shared_data, name, line, words):
    with pytest.raises(ParseError) as info:
        read_ionex(shared_data / "ionex" / name)
    assert info.value.line == line and words in str(info.value) and name in info.value.path


def test_exponent_change_inside_a_map(tmp_path, shared_data):
    lines = (shared_data / "ionex" / "jammed-fields.14i").read_text().splitlines()
    k = next(i for i, s in enumerate(lines) if "LAT/LON1/LON2/DLON/H" in s)
    lines.insert(k, f"{-1:6d}" + " " * 54 + "EXPONENT")
    p = tmp_path / "exp.14i"
    p.write_text("\n".join(lines) + "\n")
    m = read_ionex(p)
    assert m.tec[0, 0, 0, 0] == pytest.approx(891.7)      # 8917 x 10^-1 instead of 10^-2
    assert m.tec[1, 0, 0, 0] == pytest.approx(read_ionex(shared_data / "ionex" / "jammed-fields.14i").tec[1, 0, 0, 0])


def test_rms_maps_read_beside_tec(tmp_path, shared_data):
    # jammed-fields.14i carries TEC maps only; its TEC blocks relabelled as RMS maps must come back as rms
    lines = (shared_data / "ionex" / "jammed-fields.14i").read_text().splitlines()
    k = next(i for i, s in enumerate(lines) if "END OF HEADER" in s) + 1
    header, body = lines[:k], [s for s in lines[k:] if "END OF FILE" not in s]
    rms = [s.replace("START OF TEC MAP", "START OF RMS MAP").replace("END OF TEC MAP", "END OF RMS MAP")
           for s in body]
    p = tmp_path / "rms.14i"
    p.write_text("\n".join(header + body + rms + [" " * 60 + "END OF FILE"]) + "\n")
    m = read_ionex(p)
    assert m.rms is not None and m.rms.shape == m.tec.shape
    np.testing.assert_array_equal(m.rms, m.tec)


def _jammed(shared_data):
    return (shared_data / "ionex" / "jammed-fields.14i").read_text().splitlines()


def _write(tmp_path, lines):
    p = tmp_path / "x.14i"
    p.write_text("\n".join(lines) + "\n")
    return p


def _replace(lines, label, data):
    return [data.ljust(60) + ln[60:] if ln[60:].strip() == label else ln for ln in lines]


@pytest.mark.parametrize("label, data, words", [
    ("LAT1 / LAT2 / DLAT", "    25.0  20.0   nan", "finite"),
    ("LON1 / LON2 / DLON", "  -180.0 180.0  1e-9", "not regular"),
    ("EPOCH OF FIRST MAP", "  1e400     2    13     2     0     0", "integer"),
    ("EPOCH OF FIRST MAP", "     0     2    13     2     0     0", "outside"),
    ("# OF MAPS IN FILE", "9" * 59, "integer"),
])
def test_absurd_header_numbers_are_parse_errors(tmp_path, shared_data, label, data, words):
    with pytest.raises(ParseError, match=words) as info:
        read_ionex(_write(tmp_path, _replace(_jammed(shared_data), label, data)))
    assert info.value.line is not None


def test_map_with_a_missing_latitude_band_is_refused_or_reported(tmp_path, shared_data):
    from parsers.errors import ParseReport
    lines = _jammed(shared_data)
    band, end = [i for i, ln in enumerate(lines) if ln[60:].strip() == "LAT/LON1/LON2/DLON/H"][:2]
    holey = lines[:band] + lines[end:]  # first map loses its first latitude band: a hole of NaN
    with pytest.raises(ParseError, match="no values at"):
        read_ionex(_write(tmp_path, holey))
    report = ParseReport()
    maps = read_ionex(_write(tmp_path, holey), errors="report", report=report)
    whole = read_ionex(shared_data / "ionex" / "jammed-fields.14i")
    # the holey map is left out and reported (and the header's map count with it); the other map is kept
    assert len(maps.epochs) == len(whole.epochs) - 1 and len(report) == 2
    np.testing.assert_array_equal(maps.tec[0], whole.tec[1])
