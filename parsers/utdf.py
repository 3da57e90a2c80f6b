"""Reader and writer of GSFC Universal Tracking Data Format (UTDF, 450-ICD-SN/CUE).

A UTDF file is a sequence of 75-byte big-endian records (byte numbers 1-based):

    1-3 sync 0D 0A 01 · 4-5 router (ASCII) · 6 year · 7-8 SIC · 9-10 VID ·
    11-14 seconds of year · 15-18 microseconds · 19-22 angle 1 (az or X) and
    23-26 angle 2 (el or Y) in 2^-32 of a circle · 27-32 range delay in
    1/256 ns (round trip) · 33-38 Doppler count (cycles of bias + M * Doppler)
    · 39-40 AGC · 41-44 transmit frequency in 10 Hz · 45/47 transmit/receive
    antenna type (high nybble diameter code, low nybble geometry code) ·
    46/48 transmit/receive antenna pad id · 49-50 mode · 51 data validity
    (bit 0 range, 1 Doppler, 2 angles, 3 angles corrected for misalignment,
    4 angles corrected for refraction, 5 range corrected for refraction,
    6 destruct Doppler, 7 side lobe) · 52 frequency band (high nybble) and
    transmission type (low nybble) · 53-54 tracker type (bits 12-15), last
    frame (bit 11), data interval (bits 0-10: seconds, or when bit 10 is set
    the two's complement of samples per second) · 55-72 TDRSS-only fields ·
    73-75 sync 04 0F 0F.

The year byte is the year's last two digits (70-99 -> 19xx, 0-69 -> 20xx);
values of 100 and more are read as years since 1900. The time tag is that
year's 1 January 00:00 UTC + seconds of year + microseconds.

:func:`read` gives one table row per observable a record carries (a set
validity bit or a non-zero field): ``range`` as round-trip delay in s,
Doppler in Hz in the DSN sign convention of every ``doppler_*`` observable
(Moyer: positive when the spacecraft recedes), i.e. minus the UTDF Doppler
shift = (delta count / delta t - 240 MHz bias) / M between consecutive records
of one vehicle and pad (or count / interval for destruct Doppler; NaN for the
first of a series), angles in rad. Extra columns: ``valid`` (the row's
validity bit), ``validity`` (the byte), ``vid``, ``tracker_type``,
``band_code``, ``data_interval_s``, ``doppler_count``, ``factor_m`` and
``doppler_shift_hz`` (the format's own signed shift, positive approaching). The rows of a
record with the same SIC, VID, pads and time tag as an earlier one are kept with the DUPLICATE flag,
a row without a finite value with the INVALID flag (:mod:`parsers.table`); an empty
file is a ParseError in both modes. ``meta["records"]`` holds every field of every
record (AGC, mode, antenna types, router, TDRSS-only bytes, ...; join on
``record``) and :func:`write` turns such a frame back into bytes, bit for bit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.constants import SECONDS_PER_DAY
from parsers import table as tt
from parsers.atomic import write_bytes
from parsers.errors import ParseError, ParseReport, check_mode, handle
from parsers.table import TrackingData

RECORD = 75
FRONT, REAR = b"\x0d\x0a\x01", b"\x04\x0f\x0f"
DOPPLER_BIAS_HZ = 240e6
COUNT_WRAP = 1 << 48
TWO_PI = 2 * np.pi

# one 75-byte record, big-endian, packed
DTYPE = np.dtype([
    ("front", "S3"), ("router", "S2"), ("year", "u1"), ("sic", ">u2"), ("vid", ">u2"),
    ("seconds_of_year", ">u4"), ("microseconds", ">u4"), ("angle1", ">u4"), ("angle2", ">u4"),
    ("range_hi", ">u4"), ("range_lo", ">u2"), ("doppler_hi", ">u4"), ("doppler_lo", ">u2"),
    ("agc", ">u2"), ("transmit_freq_10hz", ">u4"), ("tx_antenna_type", "u1"), ("tx_pad", "u1"),
    ("rx_antenna_type", "u1"), ("rx_pad", "u1"), ("mode", ">u2"), ("validity", "u1"),
    ("band_and_type", "u1"), ("tracker_and_interval", ">u2"), ("tdrss", "S18"), ("rear", "S3"),
])
assert DTYPE.itemsize == RECORD

# the fields of meta["records"] that write() needs (hi/lo words merged into one count)
RECORD_FIELDS = ["front", "router", "year", "sic", "vid", "seconds_of_year", "microseconds",
                 "angle1", "angle2", "range_delay", "doppler_count", "agc", "transmit_freq_10hz",
                 "tx_antenna_type", "tx_pad", "rx_antenna_type", "rx_pad", "mode", "validity",
                 "band_and_type", "tracker_and_interval", "tdrss", "rear"]

# frequency band code -> (uplink band, downlink band)
BANDS = {1: ("VHF", "VHF"), 2: ("UHF", "UHF"), 3: ("S", "S"), 4: ("C", "C"), 5: ("X", "X"),
         6: ("Ku", "Ku"), 7: ("visible", "visible"), 8: ("S", "Ku")}
GEOMETRY = {0: ("angle_az", "angle_el"), 1: ("angle_x", "angle_y"), 2: ("angle_x", "angle_y"),
            3: ("angle_ra", "angle_dec"), 4: ("angle_ha", "angle_dec")}


def sniff(head: bytes) -> bool:
    """True when ``head`` starts with a UTDF record (sync bytes at both ends)."""
    return len(head) >= RECORD and head[:3] == FRONT and head[72:75] == REAR


def read(path, errors: str = "raise") -> TrackingData:
    """Read a UTDF file into a TrackingData; ``meta["records"]`` keeps every field of every record."""
    check_mode(errors)
    path = Path(path)
    buf = path.read_bytes()
    report = ParseReport()
    n = len(buf) // RECORD
    if n == 0:
        raise ParseError(path, f"no UTDF record: {len(buf)} bytes, a record is {RECORD}", offset=0)
    if len(buf) % RECORD:
        handle(ParseError(path, f"trailing partial record of {len(buf) % RECORD} bytes",
                          offset=n * RECORD, record=n), errors, report)
    raw = np.frombuffer(buf, DTYPE, count=n)
    ok = _check(path, raw, errors, report)
    rec = records_frame(raw[ok], np.flatnonzero(ok))
    table = _table(rec, str(path))  # already in time order
    meta = {"records": rec, "sic": sorted(set(rec["sic"].tolist())),
            "vid": sorted(set(rec["vid"].tolist()))}
    return TrackingData(table=table, ramps=tt.empty_ramps(), report=report, meta=meta)


def _check(path, raw, errors, report) -> np.ndarray:
    """Mask of sound records; the others are reported (sync bytes, time fields out of range)."""
    sync = (raw["front"] == FRONT) & (raw["rear"] == REAR)
    times = (raw["microseconds"] < 1_000_000) & (raw["seconds_of_year"] < 366 * SECONDS_PER_DAY)
    ok = sync & times
    for i in np.flatnonzero(~ok):
        why = "sync bytes 0D0A01 ... 040F0F missing" if not sync[i] else "time field out of range"
        handle(ParseError(path, f"corrupt UTDF record: {why}", offset=int(i) * RECORD, record=int(i)),
               errors, report)
    return ok


def records_frame(raw: np.ndarray, index: np.ndarray) -> pd.DataFrame:
    """The records field by field (RECORD_FIELDS), indexed by record number in the file."""
    df = pd.DataFrame({name: raw[name].astype(np.int64) for name in DTYPE.names
                       if name not in ("range_hi", "range_lo", "doppler_hi", "doppler_lo")
                       and DTYPE[name].kind == "u"}, index=pd.Index(index, name="record"))
    df["range_delay"] = (raw["range_hi"].astype(np.int64) << 16) | raw["range_lo"]
    df["doppler_count"] = (raw["doppler_hi"].astype(np.int64) << 16) | raw["doppler_lo"]
    for name in ("front", "tdrss", "rear"):
        df[name] = raw[name].astype(object)
    routers, inverse = np.unique(raw["router"], return_inverse=True)
    df["router"] = np.array([r.decode("latin-1") for r in routers], dtype=object)[inverse.ravel()]
    return df[RECORD_FIELDS]


def encode(records: pd.DataFrame) -> bytes:
    """75-byte records from a frame with RECORD_FIELDS (as read() puts in meta["records"]).

    Raises ValueError when a field does not fit its bytes.
    """
    out = np.zeros(len(records), DTYPE)
    for name in RECORD_FIELDS:
        col = records[name].to_numpy()
        if name in ("range_delay", "doppler_count"):
            col = _fit(name, col, 48)
            out[name.split("_")[0] + "_hi"] = col >> 16
            out[name.split("_")[0] + "_lo"] = col & 0xFFFF
        elif name == "router":
            text = col.astype(str)
            if len(text) and np.char.str_len(text).max() > 2:
                raise ValueError("UTDF field router longer than 2 characters")
            out[name] = np.char.encode(text, "latin-1")
        elif DTYPE[name].kind == "S":
            out[name] = col
        else:
            out[name] = _fit(name, col, 8 * DTYPE[name].itemsize)
    return out.tobytes()


def _fit(name: str, col: np.ndarray, bits: int) -> np.ndarray:
    """``col`` as int64, checked to hold unsigned ``bits``-bit values."""
    col = np.asarray(col).astype(np.int64)
    if len(col) and (col.min() < 0 or col.max() >= 1 << bits):
        raise ValueError(f"UTDF field {name} out of range for {bits} bits")
    return col


def write(path, records: pd.DataFrame) -> None:
    """Write records (RECORD_FIELDS) to ``path`` atomically (:mod:`parsers.atomic`)."""
    write_bytes(path, encode(records))


def epochs(rec: pd.DataFrame) -> np.ndarray:
    """datetime64[ns] UTC time tags of records."""
    yy = rec["year"].to_numpy().astype(np.int64)
    year = np.where(yy >= 70, 1900 + yy, 2000 + yy)  # 70-99 and years since 1900 (>= 100) alike
    jan1 = (year - 1970).astype("datetime64[Y]").astype("datetime64[ns]")
    ns = rec["seconds_of_year"].to_numpy().astype(np.int64) * 1_000_000_000 \
        + rec["microseconds"].to_numpy().astype(np.int64) * 1000
    return jan1 + ns.astype("timedelta64[ns]")


def data_interval(tracker_and_interval: np.ndarray) -> np.ndarray:
    """Data interval (s) from bits 0-10: seconds, or 1/samples-per-second when bit 10 is set."""
    v = np.asarray(tracker_and_interval).astype(np.int64) & 0x7FF
    rate = (~v & 0x7FF) + 1
    return np.where(v & 0x400, 1.0 / rate, v.astype(float))


KINDS = ("range", "doppler", "angle1", "angle2")
UNITS = np.array(["s", "Hz", "rad", "rad"], dtype=object)
TAGS = np.array(["receive", "interval_end", "receive", "receive"], dtype=object)
# observable labels: range, Doppler one-/two-way, then angle 1 and angle 2 by antenna geometry code 0-15
OBSERVABLES = np.array(["range", "doppler_1way", "doppler_2way"]
                       + [GEOMETRY.get(g, ("angle_1", "angle_2"))[a] for a in (0, 1) for g in range(16)], dtype=object)
PADS = np.array([f"PAD-{c}" for c in range(256)] + [""], dtype=object)  # code 256: no station
BAND_UP, BAND_DOWN = (np.array([BANDS.get(b, ("", ""))[i] for b in range(16)] + [""], dtype=object) for i in (0, 1))


def _table(rec: pd.DataFrame, source: str) -> pd.DataFrame:
    """TrackingTable rows (range, Doppler, two angles, in this order per record) from the records."""
    n = len(rec)
    col = {name: rec[name].to_numpy() for name in rec.columns}
    valid = col["validity"].astype(np.int64)
    band = (col["band_and_type"] >> 4).astype(np.int64)
    tx_hz = col["transmit_freq_10hz"].astype(np.int64) * 10.0
    tracker = col["tracker_and_interval"].astype(np.int64)
    interval = data_interval(tracker)
    s_band = (band == 3) | (band == 8) | ((band == 0) & (tx_hz >= 2e9) & (tx_hz < 4e9))
    factor_m = np.where((band == 6) | (band == 8) | (tx_hz >= 12e9), 100.0, 1000.0)
    factor_k = np.where(s_band, 240 / 221, np.where(band == 1, 1.0, np.nan))
    epoch = epochs(rec)
    rng, cnt = col["range_delay"], col["doppler_count"]
    a1, a2 = col["angle1"].astype(float), col["angle2"].astype(float)
    doppler_hz, count_time = _doppler(col, cnt, valid, interval, factor_m, epoch)
    geometry = (col["rx_antenna_type"] & 0x0F).astype(np.int64)
    two_way = tx_hz > 0

    bits = np.stack([valid & 1, (valid >> 1) & 1, (valid >> 2) & 1, (valid >> 2) & 1], axis=1).astype(bool)
    present = bits | np.stack([rng != 0, cnt != 0, a1 != 0, a2 != 0], axis=1)
    value = np.stack([rng / 256e9, -doppler_hz, a1 / 2**32 * TWO_PI,
                      _signed_half_turn(a2 / 2**32 * TWO_PI)], axis=1)
    ctime = np.stack([np.zeros(n), count_time, np.zeros(n), np.zeros(n)], axis=1)
    names = np.stack([np.zeros(n, np.int64), 1 + two_way, 3 + geometry, 19 + geometry], axis=1)  # OBSERVABLES
    flat = np.flatnonzero(present.ravel())
    flat = flat[np.argsort(epoch[flat // len(KINDS)], kind="stable")]  # time order, file order among equals
    r, k = flat // len(KINDS), flat % len(KINDS)
    is_doppler = k == 1
    repeated = rec.duplicated(subset=["sic", "vid", "tx_pad", "rx_pad", "year", "seconds_of_year",
                                      "microseconds"]).to_numpy()  # a second record of the same sample
    sics, sic_code = np.unique(col["sic"], return_inverse=True)
    return tt.build_owned(
        len(r), epoch=epoch[r], tag=tt.coded(k, TAGS), observable=tt.coded(names.ravel()[flat], OBSERVABLES),
        value=value.ravel()[flat], unit=tt.coded(k, UNITS), count_time=ctime.ravel()[flat],
        station_tx=tt.coded(np.where(two_way[r], col["tx_pad"][r], 256), PADS),
        station_rx=tt.coded(col["rx_pad"][r], PADS), spacecraft=tt.coded(sic_code.ravel()[r], sics.astype(str)),
        band_up=tt.coded(np.where(two_way[r], band[r], 16), BAND_UP), band_down=tt.coded(band[r], BAND_DOWN),
        uplink_hz=np.where(two_way[r], tx_hz[r], np.nan),
        transponder_ratio=np.where(two_way[r], factor_k[r], np.nan),
        source=source, record=rec.index.to_numpy()[r].astype(np.int64), flags=np.where(repeated[r], tt.DUPLICATE, 0),
        valid=bits.ravel()[flat], validity=valid[r], vid=col["vid"][r], tracker_type=tracker[r] >> 12,
        band_code=band[r], data_interval_s=interval[r], doppler_count=np.where(is_doppler, cnt[r], -1),
        factor_m=np.where(is_doppler, factor_m[r], np.nan),
        doppler_shift_hz=np.where(is_doppler, doppler_hz[r], np.nan),
    )


MAX_COUNT_GAP = 10  # data intervals


def _doppler(col, cnt, valid, interval, factor_m, epoch):
    """Doppler shift (Hz) and count time (s) per record from the running or destruct count.

    A running count is differenced with the previous record of the same SIC,
    VID and receive pad that carries one, if that record is at most
    ``MAX_COUNT_GAP`` data intervals earlier: a counter is not known to run on
    across a gap between passes, so the first record after one starts a new
    series (NaN), like the first record of a file.
    """
    has = ((valid & 2) != 0) | (cnt != 0)
    destruct = (valid & 64) != 0
    running = has & ~destruct
    key = ((col["sic"].astype(np.int64) * 65536 + col["vid"]) * 256 + col["rx_pad"]) * 2 + running
    order = np.argsort(key, kind="stable")
    same = np.concatenate(([False], key[order][1:] == key[order][:-1]))
    prev = np.full(len(key), -1)
    prev[order] = np.where(same, np.concatenate(([-1], order[:-1])), -1)
    has_prev = (prev >= 0) & running
    p = np.where(has_prev, prev, 0)
    dt = (epoch - epoch[p]).astype(np.int64) / 1e9
    dn = (cnt - cnt[p]) % COUNT_WRAP
    ok = has_prev & (dt > 0) & (dt <= MAX_COUNT_GAP * interval)
    with np.errstate(invalid="ignore", divide="ignore"):
        from_running = (dn / dt - DOPPLER_BIAS_HZ) / factor_m
        from_destruct = (cnt / interval - DOPPLER_BIAS_HZ) / factor_m
    hz = np.where(destruct, from_destruct, np.where(ok, from_running, np.nan))
    count_time = np.where(destruct, interval, np.where(ok, dt, np.nan))
    return hz, count_time


def _signed_half_turn(angle: np.ndarray) -> np.ndarray:
    """Map [0, 2 pi) to [-pi, pi) (elevation and Y angles may be negative)."""
    return np.where(angle >= np.pi, angle - TWO_PI, angle)

