"""Reader of DSN Orbit Data Files (ODF, JPL 820-013 TRK-2-18).

An ODF is a sequence of 36-byte big-endian records in groups, each group
opened by a header record (primary key, secondary key, logical record length,
group start packet number, then 20 zero bytes):

    101 file label · 107 identifier · 109 orbit data · 2030 ramps (secondary
    key = station) · 2040 clock offsets · 105 data summary · -1 end of file

followed by zero padding. Records are decoded all at once with numpy bit
fields. Times are UTC seconds past 1950-01-01 00:00 (no leap seconds counted,
as numpy's datetime64), fractional part in ms for data and ns for ramps and
clock offsets.

Observables keep the file's values: Doppler in Hz as the ODF gives it (the
counted frequency minus the Doppler bias, i.e. bias already removed), total
count phase and narrowband VLBI in cycles, sequential/PRA range in range
units (ambiguous modulo ``range_modulus_ru`` = 2^(lowest component + 6)),
tone (RE) range and wideband VLBI converted from ns to s, angles converted
from degrees to rad. The reference frequency (``reference_hz``) is, per the
spec, the spacecraft transponder frequency for one-way data, the receiver
frequency for ramped two/three-way data and the transmitter frequency
otherwise; ``uplink_hz`` repeats it except for ramped rows (NaN there): rows
whose transmitting station has ramp records in the file. The one-way
reference is given at S-band scale: the downlink is reference * 240/240 (S),
* 880/240 (X) or * 3344/240 (Ka) (GRAIL: 2280.6 MHz S, 2305.036363636 MHz
-> 8451.8 MHz X; MESSENGER: 2299.812417 MHz -> 8432.645529 MHz X).

Extra columns after the contract: ``odf_data_type``, ``validity`` (0 good,
1 bad), ``network_id``, ``band_exciter``, ``reference_hz``,
``rx_exciter_independent``, ``downlink_delay_s``, ``uplink_delay_s``,
``range_modulus_ru``, ``observable_int`` and ``observable_frac`` (the two
stored parts; value = int + frac * 1e-9 in the file unit) and the raw
type-dependent items ``item15``, ``item20``, ``item21`` (TRK-2-18 table 3-3b,
items 15/20/21; e.g. item21 = count time in 0.01 s for Doppler, highest
component * 100000 + coder offset for range).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from parsers import table as tt
from parsers.errors import ParseError, ParseReport, check_mode, handle
from parsers.table import TrackingData

RECORD = 36
EPOCH_1950 = np.datetime64("1950-01-01T00:00:00", "ns")
LABEL, IDENTIFIER, ORBIT_DATA, RAMPS, CLOCK_OFFSETS, SUMMARY, END = 101, 107, 109, 2030, 2040, 105, -1
GROUP_KEYS = (LABEL, IDENTIFIER, ORBIT_DATA, RAMPS, CLOCK_OFFSETS, SUMMARY, END)

# data type id -> (observable, factor from the file unit to the table unit, table unit, time tag)
DATA_TYPES = {
    1: ("vlbi_nb_sc_doppler", 1.0, "cycles", "receive"),
    2: ("vlbi_nb_sc_phase", 1.0, "cycles", "receive"),
    3: ("vlbi_nb_quasar_doppler", 1.0, "cycles", "receive"),
    4: ("vlbi_nb_quasar_phase", 1.0, "cycles", "receive"),
    5: ("vlbi_wb_sc", 1e-9, "s", "receive"),
    6: ("vlbi_wb_quasar", 1e-9, "s", "receive"),
    11: ("doppler_1way", 1.0, "Hz", "interval_mid"),
    12: ("doppler_2way", 1.0, "Hz", "interval_mid"),
    13: ("doppler_3way", 1.0, "Hz", "interval_mid"),
    21: ("phase_1way", 1.0, "cycles", "receive"),
    22: ("phase_2way", 1.0, "cycles", "receive"),
    23: ("phase_3way", 1.0, "cycles", "receive"),
    36: ("range", 1.0, "RU", "receive"),
    37: ("range", 1.0, "RU", "receive"),
    41: ("range", 1e-9, "s", "receive"),
    51: ("angle_az", np.pi / 180, "rad", "receive"),
    52: ("angle_el", np.pi / 180, "rad", "receive"),
    53: ("angle_ha", np.pi / 180, "rad", "receive"),
    54: ("angle_dec", np.pi / 180, "rad", "receive"),
    55: ("angle_x", np.pi / 180, "rad", "receive"),
    56: ("angle_y", np.pi / 180, "rad", "receive"),
    57: ("angle_x", np.pi / 180, "rad", "receive"),
    58: ("angle_y", np.pi / 180, "rad", "receive"),
}
DOPPLER_OR_PHASE = (11, 12, 13, 21, 22, 23)
RANGE_SRA = (36, 37)
ANGLES = tuple(range(51, 59))
BANDS = np.array(["Ku", "S", "X", "Ka"], dtype=object)
# the same, as lookup arrays indexed by data type id (6 bits)
_OBSERVABLE, _FACTOR, _UNIT, _TAG = (np.array([DATA_TYPES.get(k, ("", 0.0, "", ""))[c] for k in range(64)],
                                              dtype=float if c == 1 else object) for c in range(4))

# (uplink band, downlink band) -> transponder turnaround ratio (DSN 810-005, module 201)
TURNAROUND = {("S", "S"): 240 / 221, ("S", "X"): 880 / 221, ("X", "S"): 240 / 749,
              ("X", "X"): 880 / 749, ("X", "Ka"): 3344 / 749, ("Ka", "Ka"): 3360 / 3599}


def sniff(head: bytes) -> bool:
    """True when ``head`` starts with an ODF file label header record (key 101)."""
    if len(head) < RECORD:
        return False
    w = np.frombuffer(head[:RECORD], ">i4")
    return bool(w[0] == LABEL and w[1] == 0 and w[2] == 1 and w[3] == 0 and not w[4:].any())


def code_labels(codes: np.ndarray, label) -> np.ndarray:
    """Object array of ``label(code)`` for integer codes, computed once per distinct code."""
    uniq, inverse = np.unique(np.asarray(codes, dtype=np.int64), return_inverse=True)
    return np.array([label(int(c)) for c in uniq], dtype=object)[inverse.ravel()]


def station_names(ids: np.ndarray, network: np.ndarray | int = 0) -> np.ndarray:
    """'DSS-nn' for DSN ids (network 0), 'NETk-nn' for other networks, '' for id 0."""
    ids = np.asarray(ids, dtype=np.int64)
    net = np.broadcast_to(np.asarray(network, dtype=np.int64), ids.shape)
    return code_labels(net * 128 + ids, lambda c: "" if c % 128 == 0 else
                       f"DSS-{c % 128:02d}" if c < 128 else f"NET{c // 128}-{c % 128:02d}")


def time_ordered(tbl: pd.DataFrame) -> pd.DataFrame:
    """The table sorted by epoch (stable: file order among equal tags), unchanged when already sorted."""
    if tbl["epoch"].is_monotonic_increasing:
        return tbl
    return tbl.sort_values("epoch", kind="stable").reset_index(drop=True)


def transponder_ratio(band_up: np.ndarray, band_down: np.ndarray) -> np.ndarray:
    """Turnaround ratio for each (uplink, downlink) band pair; NaN when unknown or one-way."""
    out = np.full(len(band_up), np.nan)
    for (up, down), ratio in TURNAROUND.items():
        out[(band_up == up) & (band_down == down)] = ratio
    return out


def read(path, errors: str = "raise") -> TrackingData:
    """Read an ODF into a TrackingData (orbit data table, ramp table, report, header facts)."""
    check_mode(errors)
    path = Path(path)
    buf = path.read_bytes()
    report = ParseReport()
    n = len(buf) // RECORD
    words = np.frombuffer(buf, ">u4", count=n * 9).reshape(n, 9)
    keys = words[:, 0].view(">i4")
    is_header = ~words[:, 4:].any(axis=1) & np.isin(keys, GROUP_KEYS)

    meta = _label_and_identifier(path, buf, keys, words, is_header)
    end = np.flatnonzero(is_header & (keys == END))
    stop = int(end[0]) if len(end) else n
    if len(end):
        pad = np.frombuffer(buf, np.uint8)[(stop + 1) * RECORD:]
        meta["padding_nonzero_bytes"] = int(np.count_nonzero(pad))
    else:
        handle(ParseError(path, "no end-of-file group (key -1); file truncated?",
                          offset=n * RECORD, record=n), errors, report)
        if len(buf) % RECORD:
            handle(ParseError(path, f"trailing partial record of {len(buf) % RECORD} bytes",
                              offset=n * RECORD, record=n), errors, report)

    index = np.arange(stop)
    hdr = np.flatnonzero(is_header[:stop])
    _check_headers(path, keys, words, hdr, errors, report)
    meta["groups"] = [(int(keys[i]), int(words[i, 1]), int(i)) for i in np.append(hdr, end[:1])]
    owner = np.maximum.accumulate(np.where(is_header[:stop], index, 0))
    group = keys[owner]
    body = ~is_header[:stop] & (index > 4)
    stray = body & ~np.isin(group, (ORBIT_DATA, RAMPS, CLOCK_OFFSETS, SUMMARY))
    for i in np.flatnonzero(stray):
        handle(ParseError(path, f"record in group {int(group[i])}, which carries no data records",
                          offset=int(i) * RECORD, record=int(i)), errors, report)

    data_idx = np.flatnonzero(body & (group == ORBIT_DATA))
    tbl = _orbit_data(path, words, data_idx, errors, report)
    ramps = _ramps(path, words, np.flatnonzero(body & (group == RAMPS)),
                   words[owner, 1], errors, report)
    meta["clock_offsets"] = _clock_offsets(path, words, np.flatnonzero(body & (group == CLOCK_OFFSETS)))
    summary = np.flatnonzero(body & (group == SUMMARY))
    meta["summary_records"] = [buf[i * RECORD:(i + 1) * RECORD] for i in summary]
    _mark_ramped(tbl, ramps)
    return TrackingData(table=time_ordered(tbl), ramps=ramps, report=report, meta=meta)


def _label_and_identifier(path, buf, keys, words, is_header) -> dict:
    """File label (records 0-1) and identifier (2-3) groups, and the orbit data header (4)."""
    expect = ((0, LABEL), (2, IDENTIFIER), (4, ORBIT_DATA))
    for i, key in expect:
        if len(words) <= i or not is_header[i] or keys[i] != key \
                or words[i, 3] != i:
            raise ParseError(path, f"expected the group header {key} at packet {i}: not an ODF file "
                             "or a corrupt label", offset=i * RECORD, record=i)
    lab = buf[RECORD:2 * RECORD]
    ident = buf[3 * RECORD:4 * RECORD]
    scid, cdate, ctime, rdate, rtime = np.frombuffer(lab[16:36], ">u4").tolist()
    return {
        "system_id": _ascii(lab[0:8]), "program_id": _ascii(lab[8:16]), "spacecraft_id": scid,
        "creation_date": cdate, "creation_time": ctime,
        "reference_date": rdate, "reference_time": rtime,
        "identifiers": (_ascii(ident[0:8]), _ascii(ident[8:16]), _ascii(ident[16:36])),
    }


def _ascii(b: bytes) -> str:
    return b.decode("ascii", errors="replace").strip(" \x00")


def _check_headers(path, keys, words, hdr, errors, report) -> None:
    """Every group header states its own packet number; ramp headers a station, length 1."""
    bad = words[hdr, 3] != hdr
    bad |= (keys[hdr] == RAMPS) & ((words[hdr, 1] > 127) | (words[hdr, 2] != 1))
    for i in hdr[bad]:
        handle(ParseError(path, f"inconsistent group header (key {int(keys[i])}, "
                          f"secondary {int(words[i, 1])}, length {int(words[i, 2])}, "
                          f"packet {int(words[i, 3])})", offset=int(i) * RECORD, record=int(i)),
               errors, report)


def _orbit_data(path, words, idx, errors, report) -> pd.DataFrame:
    """Decode the orbit data records ``idx`` into a TrackingTable."""
    w = words[idx]
    w4 = w[:, 4]
    fmt = w4 >> 29
    dtype_id = ((w4 >> 7) & 63).astype(np.int64)
    frac_ms = w[:, 1] >> 22
    obs_frac = w[:, 3].view(">i4").astype(np.int64)
    ok = (fmt == 2) & np.isin(dtype_id, list(DATA_TYPES)) & (frac_ms < 1000) \
        & (np.abs(obs_frac) < 1_000_000_000)
    for j in np.flatnonzero(~ok):
        i = int(idx[j])
        why = (f"format id {int(fmt[j])} (only 2 is defined)" if fmt[j] != 2 else
               f"unknown data type {int(dtype_id[j])}" if dtype_id[j] not in DATA_TYPES else
               "fraction field out of range")
        handle(ParseError(path, f"corrupt orbit data record: {why}", offset=i * RECORD, record=i),
               errors, report)
    idx, w, w4, dtype_id, frac_ms, obs_frac = idx[ok], w[ok], w4[ok], dtype_id[ok], frac_ms[ok], obs_frac[ok]

    a = (w[:, 5].astype(np.uint64) << np.uint64(32)) | w[:, 6]
    b = (w[:, 7].astype(np.uint64) << np.uint64(32)) | w[:, 8]
    item15 = (a >> np.uint64(57)).astype(np.int64)
    scid = ((a >> np.uint64(47)) & np.uint64(0x3FF)).astype(np.int64)
    independent = ((a >> np.uint64(46)) & np.uint64(1)).astype(np.int64)
    ref_mhz = ((a >> np.uint64(24)) & np.uint64(0x3FFFFF)) * np.uint64(1 << 24) + (a & np.uint64(0xFFFFFF))
    item20 = ((b >> np.uint64(44)) & np.uint64(0xFFFFF)).astype(np.int64)
    item20 = np.where(item20 >= 1 << 19, item20 - (1 << 20), item20)
    item21 = ((b >> np.uint64(22)) & np.uint64(0x3FFFFF)).astype(np.int64)
    item22 = (b & np.uint64(0x3FFFFF)).astype(np.int64)

    rx = (w4 >> 22) & 127
    tx = (w4 >> 15) & 127
    net = ((w4 >> 13) & 3).astype(np.int64)
    down, up, exc = (w4 >> 5) & 3, (w4 >> 3) & 3, (w4 >> 1) & 3
    angles = np.isin(dtype_id, ANGLES)
    one_way = tx == 0
    band_down = np.where(angles, "", BANDS[down])
    band_up = np.where(angles | one_way, "", BANDS[up])
    band_exc = np.where(angles, "", BANDS[exc])

    obs_int = w[:, 2].view(">i4").astype(np.int64)
    raw = obs_int + obs_frac * 1e-9
    counted = np.isin(dtype_id, DOPPLER_OR_PHASE)
    delay_up = np.isin(dtype_id, DOPPLER_OR_PHASE + RANGE_SRA + (41,))
    sra = np.isin(dtype_id, RANGE_SRA)
    ref_hz = np.where(angles, np.nan, ref_mhz.astype(np.float64) / 1000.0)
    ratio = np.where(one_way, np.nan, transponder_ratio(band_up, band_down))
    nanos = w[:, 0].astype(np.int64) * 1_000_000_000 + frac_ms.astype(np.int64) * 1_000_000
    return tt.build(
        len(idx),
        epoch=EPOCH_1950 + nanos.astype("timedelta64[ns]"),
        tag=_TAG[dtype_id], observable=_OBSERVABLE[dtype_id], value=raw * _FACTOR[dtype_id],
        unit=_UNIT[dtype_id],
        count_time=np.where(counted, item21 * 0.01, 0.0),
        station_tx=station_names(tx), station_rx=station_names(rx, net),
        spacecraft=code_labels(scid, str), band_up=band_up, band_down=band_down,
        uplink_hz=ref_hz, transponder_ratio=ratio, source=str(path), record=idx.astype(np.int64),
        flags=0,
        odf_data_type=dtype_id, validity=(w4 & 1).astype(np.int64), network_id=net,
        band_exciter=band_exc, reference_hz=ref_hz, rx_exciter_independent=independent,
        downlink_delay_s=(w[:, 1] & 0x3FFFFF).astype(np.int64) * 1e-9,
        uplink_delay_s=np.where(delay_up, item22 * 1e-9, np.nan),
        range_modulus_ru=np.where(sra, np.exp2(item15 + 6.0), np.nan),
        observable_int=obs_int, observable_frac=obs_frac,
        item15=item15, item20=item20, item21=item21,
    )


def _ramps(path, words, idx, header_station, errors, report) -> pd.DataFrame:
    """Decode ramp records ``idx`` into a ramp table (RAMP_COLUMNS)."""
    w = words[idx]
    station = (w[:, 4] & 0x3FF).astype(np.int64)
    frac_ok = (w[:, 1] < 1_000_000_000) & (w[:, 8] < 1_000_000_000) & (w[:, 6] < 1_000_000_000) \
        & (w[:, 5] < 1_000_000_000) \
        & (np.abs(w[:, 3].view(">i4").astype(np.int64)) < 1_000_000_000) \
        & (station == header_station[idx])
    for j in np.flatnonzero(~frac_ok):
        i = int(idx[j])
        handle(ParseError(path, "corrupt ramp record (fraction out of range or station differs "
                          "from its group header)", offset=i * RECORD, record=i), errors, report)
    idx, w, station = idx[frac_ok], w[frac_ok], station[frac_ok]
    start = w[:, 0].astype(np.int64) * 1_000_000_000 + w[:, 1].astype(np.int64)
    stop = w[:, 7].astype(np.int64) * 1_000_000_000 + w[:, 8].astype(np.int64)
    rate = w[:, 2].view(">i4").astype(np.int64) + w[:, 3].view(">i4").astype(np.int64) * 1e-9
    freq = (w[:, 4] >> 10).astype(np.int64) * 1e9 + w[:, 5].astype(np.int64) + w[:, 6] * 1e-9
    return pd.DataFrame({
        "station": station_names(station),
        "start": EPOCH_1950 + start.astype("timedelta64[ns]"),
        "end": EPOCH_1950 + stop.astype("timedelta64[ns]"),
        "freq_hz": freq, "rate_hz_s": rate, "band": band_of_frequency(freq),
        "source": np.full(len(idx), str(path), dtype=object), "record": idx.astype(np.int64),
    })


def band_of_frequency(freq_hz: np.ndarray) -> np.ndarray:
    """Uplink band letter from a sky frequency (Hz): S < 4 GHz < X < 12 GHz < Ku < 26 GHz < Ka."""
    edges = np.array([4e9, 12e9, 26e9])
    return np.array(["S", "X", "Ku", "Ka"], dtype=object)[np.searchsorted(edges, freq_hz)]


def _clock_offsets(path, words, idx) -> pd.DataFrame:
    """Clock offset group: offset (s) of the secondary station's clock over a time span."""
    w = words[idx]
    t0 = w[:, 0].astype(np.int64) * 1_000_000_000 + w[:, 1].astype(np.int64)
    t1 = w[:, 7].astype(np.int64) * 1_000_000_000 + w[:, 8].astype(np.int64)
    return pd.DataFrame({
        "start": EPOCH_1950 + t0.astype("timedelta64[ns]"),
        "end": EPOCH_1950 + t1.astype("timedelta64[ns]"),
        "offset_s": w[:, 2].view(">i4") + w[:, 3].view(">i4") * 1e-9,
        "station_primary": station_names(w[:, 4]), "station_secondary": station_names(w[:, 5]),
        "record": idx.astype(np.int64),
    })


def _mark_ramped(tbl: pd.DataFrame, ramps: pd.DataFrame) -> None:
    """Uplink rows whose transmitter has ramp records in the file: ramped, uplink_hz NaN.

    Coverage is not tested at the receive tag: the uplink left one light time
    earlier, which the ramp store evaluates (see :mod:`parsers.ramps`).
    """
    ramped = tbl["station_tx"].isin(set(ramps["station"])).to_numpy() & (tbl["station_tx"] != "").to_numpy()
    tbl["ramped"] = ramped
    tbl.loc[ramped, "uplink_hz"] = np.nan
