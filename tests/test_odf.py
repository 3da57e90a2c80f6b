"""ODF reader against real files and the independent ASCII listing of odf07155.odf.

External references: messenger/odf07155.txt (tudat's test oracle, every record
of odf07155.odf printed by another program), the data README/PROVENANCE facts
(spacecraft ids, stations, bands, dates, Cassini range wrapping modulo 2^25 RU),
and the GRAIL file names, whose time is the first data time.
"""

from __future__ import annotations

import struct
from decimal import Decimal

import numpy as np
import pandas as pd
import pytest

from parsers import ParseError, odf

MESSENGER = "messenger/odf07155.odf"
CASSINI = "cassini/S18TIGM2006_058_0005X25MV1.ODF"
BAND_CODE = {"": 0, "Ku": 0, "S": 1, "X": 2, "Ka": 3}
NS_1950 = np.datetime64("1950-01-01", "ns")


def parse_listing(text: str):
    """Headers, label, data rows and ramp rows of the tudat ODF listing."""
    headers, data, ramps, label = [], [], [], None
    lines = text.splitlines()
    section = None
    for k, line in enumerate(lines):
        if line.strip().startswith("Prime_Key"):
            headers.append([int(x) for x in lines[k + 1].split()])
        elif line.startswith("---") and "Group" in line:
            section = line
        elif line.strip().startswith("SystemID"):
            label = lines[k + 1].split()
        elif line.split()[:1] and line.split()[0].lstrip("-").replace(".", "").isdigit() \
                and not lines[k - 1].strip().startswith("Prime_Key"):
            fields = line.split()
            if "Orbit Data" in section and len(fields) == 19:
                data.append(fields)
            elif "Ramp" in section and len(fields) == 5:
                ramps.append(fields)
    return headers, label, data, ramps


@pytest.fixture(scope="module")
def messenger(shared_data):
    return odf.read(shared_data / MESSENGER), (shared_data / MESSENGER.replace(".odf", ".txt")).read_text()


@pytest.mark.realdata
def test_messenger_every_data_record_matches_listing(messenger):
    d, text = messenger
    _, _, rows, _ = parse_listing(text)
    t = d.table
    assert len(rows) == len(t) == 2228
    f = np.array(rows, dtype=object).T
    ns = (t["epoch"].to_numpy() - NS_1950).astype(np.int64)
    ms = np.array([int(Decimal(x) * 1000) for x in f[0]])
    np.testing.assert_array_equal(ns // 1_000_000, ms)
    np.testing.assert_array_equal(ns % 1_000_000, 0)
    np.testing.assert_array_equal(t["downlink_delay_s"] * 1e9, f[1].astype(float))
    listed = f[2].astype(float)
    np.testing.assert_allclose(t["value"], listed, rtol=4e-16, atol=6e-10)
    exact = np.array([Decimal(x) for x in f[2]])
    stored = np.array([Decimal(int(i)) + Decimal(int(j)) / 10**9
                       for i, j in zip(t["observable_int"], t["observable_frac"])])
    assert max(abs(exact - stored)) <= Decimal("6e-10") + max(abs(exact)) * Decimal("3e-16")
    ints = f[3:12].astype(int)
    assert (ints[0] == 2).all()
    np.testing.assert_array_equal(t["station_rx"], [f"DSS-{x:02d}" for x in ints[1]])
    np.testing.assert_array_equal(t["station_tx"], ["" if x == 0 else f"DSS-{x:02d}" for x in ints[2]])
    np.testing.assert_array_equal(t["network_id"], ints[3])
    np.testing.assert_array_equal(t["odf_data_type"], ints[4])
    np.testing.assert_array_equal(t["band_down"].map(BAND_CODE), ints[5])
    np.testing.assert_array_equal(t["band_up"].map(BAND_CODE), ints[6])
    np.testing.assert_array_equal(t["band_exciter"].map(BAND_CODE), ints[7])
    np.testing.assert_array_equal(t["validity"], ints[8])
    np.testing.assert_array_equal(t["item15"], f[12].astype(int))
    np.testing.assert_array_equal(t["spacecraft"], f[13])
    np.testing.assert_array_equal(t["rx_exciter_independent"], f[14].astype(int))
    np.testing.assert_array_equal(np.round(t["reference_hz"] * 1000), [int(Decimal(x) * 1000) for x in f[15]])
    np.testing.assert_array_equal(t["item20"], f[16].astype(int))
    np.testing.assert_array_equal(t["item21"], f[17].astype(int))
    np.testing.assert_array_equal(np.round(t["uplink_delay_s"] * 1e9), f[18].astype(int))
    doppler = t["observable"].str.startswith("doppler").to_numpy()
    np.testing.assert_allclose(t["count_time"][doppler], f[17][doppler].astype(int) / 100)
    # record index: data records follow the orbit data header at packet 4
    np.testing.assert_array_equal(t["record"], np.arange(5, 5 + len(t)))


@pytest.mark.realdata
def test_messenger_every_ramp_and_header_matches_listing(messenger):
    d, text = messenger
    headers, label, _, rows = parse_listing(text)
    assert [(h[0], h[1], h[3]) for h in headers] == d.meta["groups"]
    assert label[:3] == [d.meta["system_id"], d.meta["program_id"], str(d.meta["spacecraft_id"])]
    assert [int(x) for x in label[3:]] == [d.meta["creation_date"], d.meta["creation_time"],
                                           d.meta["reference_date"], d.meta["reference_time"]]
    r = d.ramps
    assert len(rows) == len(r) == 169
    f = np.array(rows, dtype=object).T
    np.testing.assert_array_equal(r["station"], [f"DSS-{int(x):02d}" for x in f[0]])
    for col, k in (("start", 1), ("end", 4)):
        ns = (r[col].to_numpy() - NS_1950).astype(np.int64)
        np.testing.assert_array_equal(ns, [int(Decimal(x) * 10**9) for x in f[k]])
    np.testing.assert_allclose(r["rate_hz_s"], f[2].astype(float), rtol=1e-15, atol=1e-9)
    np.testing.assert_allclose(r["freq_hz"], f[3].astype(float), rtol=3e-16, atol=0)
    assert set(r["band"]) == {"X"}
    # ramp rows are numbered after their group header's packet
    starts = {h[1]: h[3] for h in headers if h[0] == 2030}
    first = r.groupby("station", sort=False)["record"].min()
    assert {int(s[4:]): v - 1 for s, v in first.items()} == starts


@pytest.mark.realdata
def test_messenger_facts_from_provenance(messenger):
    d, _ = messenger
    t = d.table
    assert set(t["spacecraft"]) == {"236"}
    assert set(t["station_rx"]) == {"DSS-14", "DSS-43", "DSS-63"}
    assert set(t["observable"]) == {"doppler_1way", "doppler_2way", "doppler_3way", "range"}
    assert t["epoch"].min().date().isoformat() == "2007-06-04"
    assert t["epoch"].max().date().isoformat() == "2007-06-05"
    # the file's last padding byte is the stray 0x0A the data README mentions
    assert d.meta["padding_nonzero_bytes"] == 1 and len(d.report) == 0


@pytest.mark.realdata
def test_cassini_bands_ratios_and_range_wrap(shared_data):
    d = odf.read(shared_data / CASSINI)
    t = d.table
    assert set(t["spacecraft"]) == {"82"}
    assert set(t["station_rx"]) | set(t["station_tx"]) == {"DSS-25", "DSS-34"}
    pairs = set(zip(t["band_up"], t["band_down"]))
    assert pairs == {("X", "X"), ("X", "Ka")}
    xx = (t["band_up"] == "X") & (t["band_down"] == "X")
    np.testing.assert_array_equal(t.loc[xx, "transponder_ratio"], 880 / 749)
    np.testing.assert_array_equal(t.loc[~xx, "transponder_ratio"], 3344 / 749)
    rng = t[t["observable"] == "range"]
    assert len(rng) == 64 and (rng["unit"] == "RU").all()
    # file name "X25": sequential range ambiguous modulo 2^25 RU
    np.testing.assert_array_equal(rng["range_modulus_ru"], 2.0**25)
    assert (rng["value"] >= 0).all() and (rng["value"] < rng["range_modulus_ru"]).all()
    assert rng["value"].max() > 0.99 * 2**25  # it really comes close to wrapping
    assert set(t["observable"]) == {"doppler_2way", "doppler_3way", "range"}
    assert (t.loc[t["observable"] != "range", "count_time"] == 1.0).all()
    assert set(d.ramps["station"]) == {"DSS-25"} and t["ramped"].all()


@pytest.mark.realdata
@pytest.mark.parametrize("name", ["grblugf2012_099_0620smmmv1.odf", "grblugf2012_102_0055smmmv1.odf"])
def test_grail_first_time_matches_file_name_and_outliers_kept(shared_data, name):
    d = odf.read(shared_data / "grail" / name)
    t = d.table
    year, doy, hhmm = name[7:11], int(name[12:15]), name[16:20]
    first = t["epoch"].min()
    assert (first.year, first.day_of_year, f"{first.hour:02d}{first.minute:02d}") == (int(year), doy, hhmm)
    assert set(t["spacecraft"]) == {"181"} and (t["count_time"] == 1.0).all()
    assert set(t["observable"]) == {"doppler_1way", "doppler_2way"}
    two = t[t["observable"] == "doppler_2way"]
    assert set(zip(two["band_up"], two["band_down"])) == {("S", "S")}
    np.testing.assert_array_equal(two["transponder_ratio"], 240 / 221)
    assert set(two["station_tx"]) <= set(d.ramps["station"]) and two["ramped"].all()
    assert set(d.ramps["band"]) == {"S"}
    one = t[t["observable"] == "doppler_1way"]
    assert one["uplink_hz"].notna().all() and (one["station_tx"] == "").all()
    assert (t["validity"] == 0).all() and (t["flags"] == 0).all()
    assert t["value"].abs().max() > 1e7  # gross outliers flagged valid are kept
    # one-way references are S-band scaled: scaled to the downlink band they land on round
    # channel frequencies (2280.6 MHz S, 8451.8 MHz X), which they do not at S-band scale for X
    scale = one["band_down"].map({"S": 1.0, "X": 880 / 240})
    assert set(np.round(one["reference_hz"] * scale / 1e5) / 10) == {2280.6, 8451.8}


def _header(key: int, secondary: int, length: int, packet: int) -> bytes:
    """An ODF group header record."""
    return struct.pack(">iIII", key, secondary, length, packet) + bytes(20)


def _messenger_bytes(shared_data) -> bytes:
    return (shared_data / MESSENGER).read_bytes()


@pytest.mark.realdata
def test_truncated_file_raises_with_offset_or_reports(shared_data, tmp_path):
    buf = _messenger_bytes(shared_data)
    p = tmp_path / "cut.odf"
    p.write_bytes(buf[: 36 * 1000 + 7])
    with pytest.raises(ParseError) as e:
        odf.read(p)
    assert e.value.offset == 36 * 1000 and str(p) in str(e.value)
    d = odf.read(p, errors="report")
    assert len(d.table) == 1000 - 5 and len(d.report) == 2


@pytest.mark.realdata
def test_corrupt_record_reported_and_skipped(shared_data, tmp_path):
    buf = bytearray(_messenger_bytes(shared_data))
    buf[36 * 10 + 16] = 0xE0 | (buf[36 * 10 + 16] & 0x1F)  # format id 7 in record 10
    p = tmp_path / "bad.odf"
    p.write_bytes(bytes(buf))
    with pytest.raises(ParseError, match="format id 7") as e:
        odf.read(p)
    assert (e.value.offset, e.value.record) == (360, 10)
    d = odf.read(p, errors="report")
    assert len(d.table) == 2227 and 10 not in set(d.table["record"])
    assert [err.record for err in d.report] == [10]


def test_not_an_odf_raises_parse_error(tmp_path):
    p = tmp_path / "x.odf"
    p.write_bytes(b"hello world" * 10)
    assert not odf.sniff(p.read_bytes())
    with pytest.raises(ParseError, match="not an ODF"):
        odf.read(p)


@pytest.mark.realdata
def test_sniff(shared_data):
    assert odf.sniff(_messenger_bytes(shared_data)[:64])
    assert not odf.sniff((shared_data / "utdf" / "data.utd").read_bytes())


@pytest.mark.realdata
def test_clock_offset_group_and_parquet(shared_data, tmp_path):
    """A clock offset group (TRK-2-18 table 3-6, as laid out in tudat's OdfClockOffsetBlock) spliced
    before the EOF group: start/end s + ns, signed offset s + ns, primary and secondary station."""
    buf = _messenger_bytes(shared_data)
    n_data = 300
    head = buf[: 36 * n_data]
    clock = struct.pack(">IIiiIIIII", 1812103200, 250_000_000, -1, -500_000_000, 14, 63, 0, 1812189600, 0)
    p = tmp_path / "clock.odf"
    p.write_bytes(head + _header(2040, 0, 1, n_data) + clock + _header(-1, 0, 0, n_data + 2))
    d = odf.read(p)
    assert len(d.table) == n_data - 5 and len(d.report) == 0
    c = d.meta["clock_offsets"].iloc[0]
    assert c["offset_s"] == -1.5 and (c["station_primary"], c["station_secondary"]) == ("DSS-14", "DSS-63")
    assert c["start"] == NS_1950 + np.timedelta64(1812103200_250_000_000, "ns")
    assert str(c["end"]) == "2007-06-05 10:00:00"
    d.table.to_parquet(tmp_path / "t.parquet")
    back = pd.read_parquet(tmp_path / "t.parquet")
    assert back["epoch"].equals(d.table["epoch"]) and back["value"].equals(d.table["value"])


@pytest.mark.realdata
def test_rows_come_out_time_ordered(shared_data, tmp_path):
    buf = _messenger_bytes(shared_data)
    swapped = buf[:36 * 5] + buf[36 * 6:36 * 7] + buf[36 * 5:36 * 6] + buf[36 * 7:]  # records 5 and 6
    p = tmp_path / "swapped.odf"
    p.write_bytes(bytes(swapped))
    t = odf.read(p).table
    # the earlier sample now sits at file record 6: it comes first, still traced to its bytes
    assert t["epoch"].is_monotonic_increasing and list(t["record"][:3]) == [6, 5, 7]
