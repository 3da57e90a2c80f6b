"""Reader of ILRS Consolidated Laser Ranging Data (CRD) files, v1 and v2 (normal points ``.npt``, full rate ``.frd``).

A CRD file is a sequence of text records, the record type first (upper or lower
case; fields separated by blanks; v2 writes ``na`` for a value not available):

- headers ``H1`` format (``CRD``, version, production date), ``H2`` station
  (name, CDP pad id, system number, occupancy, epoch time scale; v2 network),
  ``H3`` target (name, ILRS id, SIC, NORAD id, spacecraft time scale, target
  type), ``H4`` session (data type 0 full rate / 1 normal point / 2 sampled
  engineering, start and end date-times, data release, then the "applied"
  indicators of troposphere, centre of mass, receive amplitude, station system
  delay and spacecraft system delay, the range type 0 none / 1 one-way / 2
  two-way / 3 receive only / 4 mixed, and the data quality alert), ``H5``
  (v2) prediction used, ``H8`` end of session, ``H9`` end of file;
- configuration ``C0`` system (wavelength nm, system id, component ids),
  ``C1`` laser, ``C2`` detector, ``C3`` timing, ``C4`` transponder, ``C5``-``C7``
  (v2) software, meteorological instruments, calibration target;
- data ``10`` full-rate range and ``11`` normal point (seconds of day, time of
  flight s, system id, epoch event, ...), ``12`` range supplement, ``20``
  meteorology (pressure mbar, temperature K, humidity %), ``21`` meteorological
  supplement, ``30`` pointing angles (deg), ``40``/``41`` calibration, ``50``
  session statistics, ``60`` compatibility, ``00`` comments and ``9x`` user records.

A data record's epoch is the H4 start date plus its seconds of day (exact to the
ns), one day later when that lands more than 12 h before the session start (the
pass crossed 00:00). All ILRS epoch time scales (H2) are realizations of UTC;
the epochs are taken as UTC.

The epoch event says which instant the epoch is (0 ground receive, 1 spacecraft
bounce, 2 ground transmit, all two-way; 3 spacecraft receive, 4 spacecraft
transmit, 5 ground transmit and spacecraft receive, 6 spacecraft transmit and
ground receive, all one-way). Rows of ``10``/``11`` records with events 0-2 are
two-way ``range`` in the TrackingTable: value = c/2 * time of flight (m), tagged
at ground reception t_r = t (event 0), t + tof (event 2) or t + tof/2 (event 1;
the unequal up and down legs, |range rate| * tof / (2c), under 0.2 us for
LAGEOS, are not solved here), station_tx = station_rx = the CDP pad id (e.g.
'7090', as SINEX and ILRS name sites). One-way events become ``range_1way``
(c * tof, m) tagged 'transmit' (events 4, 5) or 'receive' (3, 6) at the epoch as
given; no measurement model reads them yet. The time of flight is as the
station gave it: corrected for station system delay when H4 says so
(``station_delay_applied``), never for troposphere unless ``tropo_applied``.

Extra table columns: ``tof_s`` (time of flight as written), ``epoch_event``,
``epoch_file`` (the epoch as written, UTC), ``system_id``, ``wavelength_nm``
(C0 of that system), ``station_code`` (H2 name, e.g. 'YARL'), ``session``
(row of ``meta["sessions"]``), ``line`` (1-based), ``window_s``, ``n_raw``,
``bin_rms_ps`` (normal points; NaN/-1 for full rate), ``validity`` (1 when a
full-rate record's filter flag says noise) and the station meteorology at
reception, linearly interpolated between the session's ``20`` records (end
values held outside them; NaN without any): ``pressure_mbar``,
``temperature_k``, ``humidity_pct``. ``sigma`` stays NaN (a normal point's
precision is about c/2 * bin_rms / sqrt(n_raw), a weighting choice left to
the run). ``record`` is the 0-based line index.

``meta``: ``sessions`` (one row per H4 with its H1-H5 fields), ``configuration``
(C records), ``supplements`` (12), ``meteo`` (20), ``meteo_supplements``
(21), ``angles`` (30, rad), ``calibrations`` (40/41), ``statistics`` (50),
``compatibility`` (60), ``comments`` (00), each with ``session`` and ``line``.
Field definitions: ILRS CRD v1.01 (Ricklefs and Moore, 2009) and v2.01 (2019).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.constants import C_LIGHT, NS_PER_DAY
from parsers import table as tt
from parsers.errors import ParseError, ParseReport, check_mode, handle
from parsers.fields import Fields, numbered_lines, date_ns
from parsers.table import TrackingData

ROLLOVER_NS = 12 * 3600 * 10**9
TWO_WAY_EVENTS = (0, 1, 2)
ONE_WAY_TAG = {3: "receive", 4: "transmit", 5: "transmit", 6: "receive"}

# record type -> (number of required fields, field names with kinds: i int, f float, s text, t seconds of day)
SPEC = {
    "H1": (6, "literal:s version:i year:i month:i day:i hour:i"),
    "H2": (5, "station_code:s pad_id:i system_number:i occupancy:i timescale:i network:s"),
    "H3": (6, "target:s ilrs_id:i sic:i norad:i sc_timescale:i target_type:i"),
    "H4": (21, "data_type:i start:d6 end:d6 data_release:i tropo_applied:i com_applied:i amplitude_applied:i "
               "station_delay_applied:i sc_delay_applied:i range_type:i data_quality:i"),
    "H5": (5, "prediction_type:i year_of_century:i prediction_datetime:s provider:s sequence:i"),
    "C0": (3, "detail_type:i wavelength_nm:f system_id:s"),
    "C1": (9, "detail_type:i config_id:s laser_type:s wavelength_nm:f fire_rate_hz:f pulse_energy_mj:f "
              "pulse_width_ps:f divergence_arcsec:f pulses_in_train:i"),
    "C2": (13, "detail_type:i config_id:s detector_type:s wavelength_nm:f quantum_efficiency_pct:f voltage_v:f "
               "dark_count_khz:f output_pulse_type:s output_pulse_width_ps:f filter_nm:f filter_transmission_pct:f "
               "spatial_filter_arcsec:f signal_processing:s amplifier_gain:f amplifier_bandwidth_khz:f "
               "amplifier_in_use:s"),
    "C3": (7, "detail_type:i config_id:s time_source:s frequency_source:s timer:s timer_serial:s epoch_delay_us:f"),
    "C4": (10, "detail_type:i config_id:s station_utc_offset_ns:f station_drift:f transponder_utc_offset_ns:f "
               "transponder_drift:f transponder_ref_time_s:f station_offset_applied:i sc_offset_applied:i "
               "sc_time_simplified:i"),
    "C5": (2, "detail_type:i config_id:s"),
    "C6": (2, "detail_type:i config_id:s"),
    "C7": (2, "detail_type:i config_id:s"),
    "10": (4, "sod:t tof_s:f system_id:s epoch_event:i filter_flag:i detector_channel:i stop_number:i "
              "receive_amplitude:i transmit_amplitude:i"),
    "11": (4, "sod:t tof_s:f system_id:s epoch_event:i window_s:f n_raw:i bin_rms_ps:f bin_skew:f bin_kurtosis:f "
              "bin_peak_minus_mean_ps:f return_rate_pct:f detector_channel:i snr:f"),
    "12": (6, "sod:t system_id:s tropo_correction_ps:f com_correction_m:f nd_value:f time_bias_s:f range_rate_mps:f"),
    "20": (4, "sod:t pressure_mbar:f temperature_k:f humidity_pct:f origin:i"),
    "21": (6, "sod:t wind_speed_mps:f wind_direction_deg:f weather:s visibility_km:f sky_clarity:f seeing:i "
              "cloud_cover:i sky_temperature_k:f"),
    "30": (3, "sod:t azimuth_deg:f elevation_deg:f direction:i origin:i refraction_corrected:i "
              "azimuth_rate_degps:f elevation_rate_degps:f"),
    "40": (9, "sod:t data_type:i system_id:s n_recorded:i n_used:i target_distance_m:f delay_ps:f delay_shift_ps:f "
              "rms_ps:f skew:f kurtosis:f peak_minus_mean_ps:f calibration_type:i shift_type:i detector_channel:i "
              "span:i return_rate_pct:f"),
    "50": (5, "system_id:s rms_ps:f skew:f kurtosis:f peak_minus_mean_ps:f data_quality:i"),
    "60": (3, "system_id:s system_change:i system_config:i"),
}
SPEC["41"] = SPEC["40"]  # v2 calibration detail: the fields of 40
META_OF = {"12": "supplements", "20": "meteo", "21": "meteo_supplements", "30": "angles", "40": "calibrations",
           "41": "calibrations", "50": "statistics", "60": "compatibility", "00": "comments"}
_FIELDS = {rt: [tuple(f.split(":")) for f in names.split()] for rt, (_, names) in SPEC.items()}


def sniff(head: bytes) -> bool:
    """True when the first non-blank line is an H1 record of format CRD."""
    first = next((ln for ln in head.decode("latin-1").splitlines() if ln.strip()), "")
    return first[:2].upper() == "H1" and [w.upper() for w in first[2:].split()[:1]] == ["CRD"]


def decode(f: Fields, kind: str) -> dict:
    """The fields of one record of type ``kind`` (a SPEC key) by name; absent trailing fields get NaN/-1/''."""
    required, _ = SPEC[kind]
    out, i = {}, 1
    for k, (name, typ) in enumerate(_FIELDS[kind]):
        need = k < required
        if typ == "t":
            out[name] = f.seconds_ns(i, name)
        elif typ == "d6":
            out[name] = date_ns(f, i, name)
            i += 5
        elif typ == "i":
            out[name] = f.int(i, name, None if need else -1)
        elif typ == "f":
            out[name] = f.float(i, name, None if need else np.nan)
        else:
            if need and i >= len(f):
                f.need(i + 1, " ".join(n for n, _ in _FIELDS[kind]))
            out[name] = f.str(i)
        i += 1
    return out


class _Reader:
    """State of one pass over the file: current headers, the open session, the records gathered."""

    def __init__(self, path: Path):
        self.path = path
        self.h1 = self.h2 = self.h3 = None
        self.session = None          # dict of the open session (H4 .. H8)
        self.sessions, self.configuration, self.ranges = [], [], []
        self.meta = {name: [] for name in set(META_OF.values())}
        self.ended = False

    def line(self, number: int, text: str) -> None:
        kind = text[:2].upper()
        f = Fields(self.path, number, text, record=kind)
        if self.ended:
            raise f.error("record after the H9 end-of-file record")
        if kind in ("H1", "H2", "H3"):
            setattr(self, kind.lower(), decode(f, kind))
            if kind == "H1" and self.h1["literal"].upper() != "CRD":
                raise f.error(f"H1 must name the format CRD, not {self.h1['literal']!r}")
        elif kind == "H4":
            self._open(f)
        elif kind == "H5":
            self._need_session(f).update(decode(f, "H5"))
        elif kind == "H8":
            self._need_session(f)
            self.session = None
        elif kind == "H9":
            self.ended = True
        elif kind[0] == "C" and kind in SPEC:
            rec = decode(f, kind)
            if kind == "C0":
                rec["components"] = " ".join(f.fields[4:])
            self.configuration.append({"session": self._need_session(f)["session"], "line": number, "record": kind,
                                       **rec, "fields": " ".join(f.fields[1:])})
        elif kind in ("10", "11"):
            self.ranges.append(self._dated(f, kind))
        elif kind in META_OF and kind != "00":
            self.meta[META_OF[kind]].append(self._dated(f, kind) if SPEC[kind][1].startswith("sod") else
                                            {"session": self._need_session(f)["session"], "line": number,
                                             **decode(f, kind)})
        elif kind == "00":
            self.meta["comments"].append({"session": self.session["session"] if self.session else -1,
                                          "line": number, "text": text[2:].strip()})
        elif not (kind[0] == "9" and kind[1].isdigit()):  # 90-99: user-defined, skipped
            raise f.error(f"unknown CRD record type {text[:2]!r} (expected H1-H9, C0-C7, 00, 10-12, 20, 21, 30, "
                          "40, 41, 50, 60 or 9x)")

    def _open(self, f: Fields) -> None:
        if self.session is not None:
            raise f.error("H4 before the H8 that ends the previous session")
        missing = [h for h in ("h1", "h2", "h3") if getattr(self, h) is None]
        if missing:
            raise f.error(f"H4 session header before any {', '.join(m.upper() for m in missing)} record")
        rec = decode(f, "H4")
        self.session = {"session": len(self.sessions), "line": f.number, "format_version": self.h1["version"],
                        **self.h2, **self.h3, **rec}
        self.sessions.append(self.session)

    def _need_session(self, f: Fields) -> dict:
        if self.session is None:
            raise f.error(f"{f.record} record outside a session (no H4 before it, or after its H8)")
        return self.session

    def _dated(self, f: Fields, kind: str) -> dict:
        s = self._need_session(f)
        rec = decode(f, kind)
        day = s["start"].astype("datetime64[D]").astype("datetime64[ns]")
        epoch = day + np.timedelta64(rec.pop("sod"), "ns")
        if (s["start"] - epoch).astype(np.int64) > ROLLOVER_NS:
            epoch += np.timedelta64(NS_PER_DAY, "ns")
        return {"session": s["session"], "line": f.number, "epoch": epoch, "kind": kind, **rec}


def read(path, errors: str = "raise") -> TrackingData:
    """Read a CRD file into a TrackingData (ranges in the table, every other record in ``meta``)."""
    check_mode(errors)
    path = Path(path)
    report = ParseReport()
    r = _Reader(path)
    for number, text in numbered_lines(path):
        if not text.strip():
            continue
        try:
            r.line(number, text.rstrip())
        except ParseError as err:
            handle(err, errors, report)
    if not r.sessions:
        handle(ParseError(path, "no H4 session header: not a CRD file with data"), errors, report)
    sessions = pd.DataFrame(r.sessions)
    config = pd.DataFrame(r.configuration)
    meta = {name: pd.DataFrame(rows) for name, rows in r.meta.items()}
    meta.update(sessions=sessions, configuration=config)
    ranges = _checked_ranges(path, r.ranges, sessions, config, errors, report)
    return TrackingData(table=_table(ranges, sessions, config, meta["meteo"], str(path)), ramps=tt.empty_ramps(),
                        report=report, meta=meta)


def _checked_ranges(path, rows, sessions, config, errors, report) -> list[dict]:
    """Range records whose epoch event is defined and whose system id has a C0 record in their session."""
    systems = set()
    if len(config):
        c0 = config[config["record"] == "C0"]
        systems = set(zip(c0["session"], c0["system_id"]))
    kept = []
    for rec in rows:
        why = None
        if rec["epoch_event"] not in range(7):
            why = f"epoch event {rec['epoch_event']} is not one of 0-6"
        elif (rec["session"], rec["system_id"]) not in systems:
            why = f"system configuration {rec['system_id']!r} has no C0 record in this session"
        elif not rec["tof_s"] > 0:
            why = f"time of flight {rec['tof_s']} s is not positive"
        if why:
            handle(ParseError(path, why, line=rec["line"], record=rec["kind"]), errors, report)
        else:
            kept.append(rec)
    return kept


def _table(rows: list[dict], sessions: pd.DataFrame, config: pd.DataFrame, meteo: pd.DataFrame,
           source: str) -> pd.DataFrame:
    """TrackingTable rows of the 10/11 records, in time order."""
    extra = {"tof_s": "float64", "epoch_event": "int64", "epoch_file": "datetime64[ns]", "system_id": "str",
             "wavelength_nm": "float64", "station_code": "str", "session": "int64", "line": "int64",
             "window_s": "float64", "n_raw": "int64", "bin_rms_ps": "float64", "validity": "int64",
             "pressure_mbar": "float64", "temperature_k": "float64", "humidity_pct": "float64"}
    if not rows:
        return tt.empty(extra)
    df = pd.DataFrame(rows)
    s = sessions.set_index("session").loc[df["session"]]
    tof = df["tof_s"].to_numpy(float)
    event = df["epoch_event"].to_numpy(np.int64)
    t = df["epoch"].to_numpy("datetime64[ns]")
    two_way = np.isin(event, TWO_WAY_EVENTS)
    shift = np.where(event == 2, tof, np.where(event == 1, tof / 2, 0.0))
    receive = t + np.round(shift * 1e9).astype(np.int64).astype("timedelta64[ns]")
    epoch = np.where(two_way, receive, t)
    tag = np.where(two_way, "receive", [ONE_WAY_TAG.get(e, "") for e in event])
    station = s["pad_id"].astype(str).to_numpy(object)
    uplink = two_way | np.isin(event, (3, 5))
    downlink = two_way | np.isin(event, (4, 6))
    pressure, temperature, humidity = _meteo_at(epoch, df["session"].to_numpy(), meteo)
    out = tt.build(
        len(df), epoch=epoch, tag=tag.astype(object),
        observable=np.where(two_way, "range", "range_1way").astype(object),
        value=np.where(two_way, C_LIGHT / 2, C_LIGHT) * tof, unit="m", count_time=0.0,
        station_tx=np.where(uplink, station, "").astype(object),
        station_rx=np.where(downlink, station, "").astype(object),
        spacecraft=s["target"].astype(str).to_numpy(object), source=source,
        record=df["line"].to_numpy(np.int64) - 1, flags=0,
        tof_s=tof, epoch_event=event, epoch_file=t, system_id=df["system_id"].astype(str).to_numpy(object),
        wavelength_nm=_wavelengths(df, config), station_code=s["station_code"].astype(str).to_numpy(object),
        session=df["session"].to_numpy(np.int64), line=df["line"].to_numpy(np.int64),
        window_s=df.get("window_s", pd.Series(np.nan, df.index)).to_numpy(float),
        n_raw=df.get("n_raw", pd.Series(-1, df.index)).fillna(-1).to_numpy(np.int64),
        bin_rms_ps=df.get("bin_rms_ps", pd.Series(np.nan, df.index)).to_numpy(float),
        validity=(df.get("filter_flag", pd.Series(-1, df.index)).fillna(-1).to_numpy(np.int64) == 1).astype(np.int64),
        pressure_mbar=pressure, temperature_k=temperature, humidity_pct=humidity,
    )
    return out.sort_values("epoch", kind="stable").reset_index(drop=True)


def _wavelengths(df: pd.DataFrame, config: pd.DataFrame) -> np.ndarray:
    """nm; the C0 wavelength of each row's (session, system id)."""
    c0 = config[config["record"] == "C0"].drop_duplicates(["session", "system_id"], keep="last")
    key = pd.MultiIndex.from_frame(df[["session", "system_id"]])
    return c0.set_index(["session", "system_id"])["wavelength_nm"].reindex(key).to_numpy(float)


def _meteo_at(epoch: np.ndarray, session: np.ndarray, meteo: pd.DataFrame):
    """(pressure mbar, temperature K, humidity %) per row, interpolated in time within the row's session."""
    out = np.full((3, len(epoch)), np.nan)
    if not len(meteo):
        return out
    cols = ["pressure_mbar", "temperature_k", "humidity_pct"]
    for sid, m in meteo.sort_values("epoch", kind="stable").groupby("session"):
        rows = session == sid
        tm = m["epoch"].to_numpy("datetime64[ns]").astype(np.int64).astype(float)
        for k, col in enumerate(cols):
            out[k, rows] = np.interp(epoch[rows].astype(np.int64).astype(float), tm, m[col].to_numpy(float))
    return out
