"""Writing a simulated case: DSN data as TRK-2-34, other stations as UTDF, calibrations, maneuvers, truth.

Encodings (what the project's readers decode back):

* TRK-2-34 format 7 (range): ``rng_obs`` RU modulo ``rng_modulo``, ``ul_freq`` the uplink at the tag;
  format 6 (Doppler counts): per pass a record at the first count start (count 0) and one per
  interval end, ``dop_cnt`` = cumulative cycles of (``dop_cnt_bias_freq`` + Doppler), so
  Doppler (Hz) = diff(count) / count_time - bias; format 9: the uplink ramps.
* CCSDS TDM (KVN): one segment per station and observable, path 1,2,1; RANGE in RU (modulus
  in the metadata) or s, two-way Doppler as DOPPLER_INTEGRATED = Doppler (Hz) times the
  models' m/s per Hz at the row (``to_los``), count interval and END reference.
* UTDF: destruct Doppler (validity bit 6) count = round((240 MHz - 1000 Doppler) * interval) (shift
  positive approaching),
  range as round-trip delay in 1/256 ns; pad ids from the case, spacecraft id as SIC.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.products.oem import write_oem
from odpipe.products.segments import EphemerisSegment
from odpipe.products.spk import write_spk
from odpipe.time import utc_to_doy
from parsers import tdm, trk234, utdf
from parsers.atomic import write_bytes, write_parquet, write_text
from parsers.maneuvers import PLAN_COLUMNS, write_plan
from parsers.table import TrackingData
from parsers.tdm.message import Segment
from parsers.trk234 import layout

DOPPLER_BIAS_HZ = 1.0e6
_BAND_CODE = {v: k for k, v in layout.BANDS.items()}


def _time_fields(epochs) -> dict:
    year, doy, sec = utc_to_doy(epochs)
    return {"year": year, "doy": doy, "sec": sec}


def _link_fields(rows: pd.DataFrame, sc: int) -> dict:
    dss = rows["station_rx"].str.replace("DSS-", "").astype(int).to_numpy()
    band = rows["band_up"].map(_BAND_CODE).to_numpy()
    return dict(scft_id=sc, dl_dss_id=dss, ul_prdx_stn=dss, prdx_mode=2, ul_band=band, vld_dl_band=band,
                ul_band_dl=band, scft_transpd_turn_num=240, scft_transpd_turn_den=221)


def trk234_blocks(table: pd.DataFrame, ramps: pd.DataFrame, uplink_at_tag: np.ndarray, sc: int) -> list:
    """TRK-2-34 blocks of DSN rows (range, 2-way Doppler) and ramps."""
    blocks = []
    rng_rows = table[table["observable"] == "range"]
    if len(rng_rows):
        blocks.append(trk234.new_block(7, len(rng_rows), **_time_fields(rng_rows["epoch"]),
                                       **_link_fields(rng_rows, sc), rng_obs=rng_rows["value"].to_numpy(),
                                       rng_modulo=rng_rows["range_modulus"].to_numpy().astype(np.uint32),
                                       ul_freq=uplink_at_tag[rng_rows.index]))
    dop = table[table["observable"] == "doppler_2way"]
    for _, g in dop.groupby("pass_id"):
        ct = g["count_time"].to_numpy()
        ends = g["epoch"].to_numpy()
        epochs = np.concatenate([ends[:1] - np.timedelta64(int(ct[0] * 1e9), "ns"), ends])
        counts = np.concatenate([[0.0], np.cumsum((g["value"].to_numpy() + DOPPLER_BIAS_HZ) * ct)])
        rows = pd.concat([g.iloc[:1], g], ignore_index=True)
        blocks.append(trk234.new_block(6, len(epochs), **_time_fields(epochs), **_link_fields(rows, sc),
                                       cnt_time=np.concatenate([[0.0], ct]), dop_cnt=counts,
                                       dop_cnt_bias_freq=DOPPLER_BIAS_HZ,
                                       ul_freq=np.concatenate([[np.nan], uplink_at_tag[g.index]])))
    if len(ramps):
        dss = ramps["station"].str.replace("DSS-", "").astype(int).to_numpy()
        blocks.append(trk234.new_block(9, len(ramps), **_time_fields(ramps["start"]), scft_id=sc, ul_dss_id=dss,
                                       ul_band=ramps["band"].map(_BAND_CODE).to_numpy(),
                                       ramp_freq=ramps["freq_hz"].to_numpy(), ramp_rate=ramps["rate_hz_s"].to_numpy()))
    order = np.argsort(np.concatenate([np.datetime64(0, "ns") + _ns(b) for b in blocks]), kind="stable")
    start = 0
    for b in blocks:
        b.index = order.argsort()[start:start + len(b.records)]
        start += len(b.records)
    return blocks


def _ns(block) -> np.ndarray:
    r = block.records
    return (trk234.observables.utc(r["year"], r["doy"], r["sec"]) - np.datetime64(0, "ns")).astype(np.int64)


def utdf_records(table: pd.DataFrame, pad: int, sc: int) -> pd.DataFrame:
    """UTDF records (parsers.utdf.RECORD_FIELDS) of one station's rows: one record per row."""
    n = len(table)
    epochs = table["epoch"].to_numpy()
    year = epochs.astype("datetime64[Y]")
    ns = (epochs - year.astype("datetime64[ns]")).astype(np.int64)
    is_range = (table["observable"] == "range").to_numpy()
    ct = table["count_time"].to_numpy()
    value = table["value"].to_numpy()
    # the format counts bias + M * shift, the shift positive approaching (minus the DSN-convention Doppler)
    doppler = np.where(is_range, 0, np.rint((utdf.DOPPLER_BIAS_HZ - 1000.0 * value) * np.where(is_range, 0, ct)))
    rng = np.where(is_range, np.rint(value * 256e9), 0)
    interval = np.where(is_range, 0, np.rint(ct)).astype(np.int64)
    return pd.DataFrame({
        "front": utdf.FRONT, "router": "SM", "year": (year.astype(np.int64) + 1970) % 100, "sic": sc, "vid": 1,
        "seconds_of_year": ns // 1_000_000_000, "microseconds": (ns % 1_000_000_000) // 1000,
        "angle1": 0, "angle2": 0, "range_delay": rng.astype(np.int64), "doppler_count": doppler.astype(np.int64),
        "agc": 0, "transmit_freq_10hz": np.rint(table["uplink_hz"].to_numpy() / 10).astype(np.int64),
        "tx_antenna_type": 0, "tx_pad": pad, "rx_antenna_type": 0, "rx_pad": pad, "mode": 0,
        "validity": np.where(is_range, 1, 2 | 64), "band_and_type": 3 << 4, "tracker_and_interval": interval,
        "tdrss": b"\x00" * 18, "rear": utdf.REAR,
    }, index=pd.RangeIndex(n, name="record"))[utdf.RECORD_FIELDS]


def tdm_data(table: pd.DataFrame, to_los: np.ndarray, created: np.datetime64) -> TrackingData:
    """A TrackingData that parsers.tdm.write renders as a TDM of the range and two-way Doppler rows."""
    templates, parts = [], []
    for (station, obs), g in table.groupby(["station_rx", "observable"], sort=True):
        meta = {"TIME_SYSTEM": "UTC", "PARTICIPANT_1": station, "PARTICIPANT_2": str(g["spacecraft"].iloc[0]),
                "MODE": "SEQUENTIAL", "PATH": "1,2,1", "TIMETAG_REF": "RECEIVE", "TRANSMIT_BAND": g["band_up"].iloc[0],
                "RECEIVE_BAND": g["band_down"].iloc[0], "TURNAROUND_NUMERATOR": "240", "TURNAROUND_DENOMINATOR": "221"}
        if obs == "range":
            unit = g["unit"].iloc[0]
            meta["RANGE_UNITS"] = unit
            if unit == "RU":
                meta["RANGE_MODULUS"] = repr(float(g["range_modulus"].iloc[0]))
            keyword, value = "RANGE", g["value"].to_numpy()
        else:
            meta.update(INTEGRATION_INTERVAL=repr(float(g["count_time"].iloc[0])), INTEGRATION_REF="END")
            keyword, value = "DOPPLER_INTEGRATED", g["value"].to_numpy() * to_los[g.index]
        parts.append(pd.DataFrame({"segment": len(templates), "keyword": keyword, "value": value,
                                   "epoch": g["epoch"].to_numpy(), "record": g.index.to_numpy()}))
        templates.append(Segment(meta=meta))
    rows = pd.concat(parts, ignore_index=True)
    header = {"CREATION_DATE": str(created.astype("datetime64[s]")), "ORIGINATOR": "odpipe-simulate"}
    return TrackingData(rows, meta={"header": header, "segments": templates})


def maneuver_plan(maneuvers, dv=None) -> pd.DataFrame:
    """Maneuvers (as planned, or ``dv`` (K,3) instead) in the parsers.maneuvers plan schema (ICRF, impulsive).

    As planned (thesis §4.2.4): station keeping with its designed delta-v; other burns (attitude) with their
    time only, delta-v 0, unless the case says ``planned_dv`` (a priori sigma 1 mm/s against 10 mm/s for
    station keeping, Table 4.1)."""
    rows = [{"name": m["name"], "epoch": m["epoch"], "kind": "impulsive", "frame": "ICRF",
             **dict(zip(("dv1", "dv2", "dv3"), m["dv"] if m["kind"] == "station-keeping" or m.get("planned")
                        else np.zeros(3))),
             "sigma_dv": 0.01 if m["kind"] == "station-keeping" else 0.001, "sigma_time": 10.0} for m in maneuvers]
    plan = pd.DataFrame(rows, columns=PLAN_COLUMNS).astype({c: float for c in PLAN_COLUMNS[4:]})
    if dv is not None:
        plan[["dv1", "dv2", "dv3"]] = dv
    return plan


def write_case(out: Path, case, truth, obs, calibrations: dict, setup, stations_csv: Path, step_s: float = 600.0) -> dict:
    """Write every product of a simulated case into ``out`` (``calibrations``: {'tro'|'ion': TRK-2-23 text}); {role: path}."""
    out.mkdir(parents=True, exist_ok=True)
    sc = case.spacecraft
    t = obs.table
    paths = {}
    ramps = obs.ramps
    up = np.full(len(t), np.nan)
    if setup.ramps is not None:
        ramped = t["ramped"].to_numpy(bool)
        up[ramped] = setup.ramps.frequency(t["station_tx"].to_numpy(object)[ramped], t["epoch"].to_numpy()[ramped])
    up = np.where(np.isnan(up), t["uplink_hz"].to_numpy(float), up)
    dsn = t["station_rx"].str.startswith("DSS-").to_numpy()
    if dsn.any():
        paths["trk234"] = out / f"{case.name}.tnf"
        trk234.write(paths["trk234"], trk234_blocks(t[dsn], ramps, up, sc))
    for net in case.networks:
        if net.format == "utdf":
            rows = t[t["station_rx"] == net.station]
            if len(rows):
                paths[f"utdf:{net.station}"] = out / f"{case.name}_{net.station}.utdf"
                utdf.write(paths[f"utdf:{net.station}"], utdf_records(rows, net.pad, sc))
    paths["tdm"] = out / f"{case.name}.tdm"
    tdm.write(paths["tdm"], tdm_data(t, obs.errors["to_los"].to_numpy(), case.start))
    paths["table"] = out / "tracking.parquet"
    write_parquet(paths["table"], t)
    paths["ramps"] = out / "ramps.parquet"
    write_parquet(paths["ramps"], ramps)
    paths["errors"] = out / "simulated_errors.parquet"
    write_parquet(paths["errors"], obs.errors)
    for kind, text in calibrations.items():
        paths[kind] = out / f"{case.name}.{kind.upper()}"
        write_text(paths[kind], text)
    paths["maneuvers"] = out / "maneuvers_designed.csv"
    write_plan(maneuver_plan(truth.maneuvers), paths["maneuvers"])
    paths["maneuvers_executed"] = out / "maneuvers_executed_truth.csv"
    write_plan(maneuver_plan(truth.maneuvers, truth.executed), paths["maneuvers_executed"])
    paths["stations"] = out / "stations.csv"
    write_bytes(paths["stations"], Path(stations_csv).read_bytes())
    seg = _segments(truth.trajectory, truth.epochs, step_s)
    paths["spk"] = out / f"{case.name}_truth.bsp"
    write_spk(paths["spk"], seg, case.naif_id)
    paths["oem"] = out / f"{case.name}_truth.oem"
    write_oem(paths["oem"], seg, case.name, str(case.naif_id))
    return paths


def _segments(traj, breaks, step_s) -> list:
    """One EphemerisSegment per span between maneuvers (the velocity jumps there)."""
    edges = np.concatenate([[traj.t0], np.sort(breaks), [traj.t1]])
    segs = []
    for a, b in zip(edges[:-1], edges[1:]):
        ts = np.linspace(a, b, int(np.ceil((b - a) / step_s - 1e-6)) + 1)   # even steps <= step_s, ends exact
        states = traj.state(ts)
        if b in breaks:  # end of a segment: the pre-maneuver state (the trajectory gives the post-maneuver one)
            states[-1] = traj.state(np.nextafter(b, a))[0]
        segs.append(EphemerisSegment(ts, states, center="earth"))
    return segs
