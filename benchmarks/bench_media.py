"""Media calibration throughput: 10^5 two-way observations (range + 60 s Doppler), both legs, both media.

Run: .venv/bin/python benchmarks/bench_media.py [shared-data-dir]
Prints wall times of calibrate() with TRK-2-23 cards (Cassini 2006) and with IONEX maps (2019).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from odpipe.media.apply import calibrate
from odpipe.media.ionosphere import IonexModel
from odpipe.media.model import MediaModel
from parsers import table as tt
from parsers.ionex import read_ionex
from parsers.trk223 import read_trk223

DATA = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "shared" / "data"


def make_table(n: int, start: str):
    """n rows over one day from DSS-25/34/65 in turn, alternating range and 60 s Doppler."""
    ep = np.datetime64(start, "ns") + np.sort(np.random.default_rng(0).integers(0, 86400, n)) * np.timedelta64(1, "s")
    hour = (ep - ep[0]) / np.timedelta64(1, "h")
    station = np.array(["DSS-25", "DSS-34", "DSS-65"], dtype=object)[(hour // 8).astype(int) % 3]
    return tt.build(n, epoch=ep, tag="interval_mid", count_time=60.0, value=0.0, unit="m",
                    observable=np.where(np.arange(n) % 2 == 0, "doppler_2way", "range"),
                    station_tx=station, station_rx=station, spacecraft="82", band_up="X", band_down="X",
                    uplink_hz=7.17e9, transponder_ratio=880 / 749)


def overhead(t0):
    """A far target over each station's local noon: always well above the horizon in its 8 h slot."""
    def target(t):
        s = (np.asarray(t, "datetime64[ns]") - t0) / np.timedelta64(1, "s")
        slot = (s // (8 * 3600)).astype(int) % 3
        lon = np.radians(np.array([243.1, 148.98, 355.75]))[slot]
        lat = np.radians(np.array([35.3, -35.4, 40.4]))[slot]
        return 1.3e12 * np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], -1)
    return target


def bench(label, table, model, target):
    t = time.perf_counter()
    out, report = calibrate(table, model, target_itrs=target)
    dt = time.perf_counter() - t
    ok = np.isfinite(out["media_m"]).mean()
    print(f"{label}: {len(table):,} rows, {len(report)} passes: {dt:.2f} s "
          f"({dt / len(table) * 1e6:.1f} us/row), finite corrections {ok:.1%}")


def main():
    n = 100_000
    d = DATA / "cassini"
    cal = read_trk223(d / "S18TIGE2006_032_2006_059.TRO", d / "S18TIGE2006_032_2006_059.ION")
    t0 = np.datetime64("2006-02-20T00:00", "ns")
    bench("TRK-2-23 TRO+ION", make_table(n, "2006-02-20T00:00"), MediaModel(cal), overhead(t0))
    t = time.perf_counter()
    gim = IonexModel(read_ionex(DATA / "ionex" / "gpsg0150.19i"))
    print(f"IONEX read: {time.perf_counter() - t:.2f} s")
    t0 = np.datetime64("2019-01-15T00:00", "ns")
    bench("seasonal + IONEX", make_table(n, "2019-01-15T00:00"), MediaModel(None, gim), overhead(t0))


if __name__ == "__main__":
    main()
