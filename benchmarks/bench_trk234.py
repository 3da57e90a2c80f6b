"""Benchmark: TRK-2-34 and CCSDS TDM read/write on synthetic files made by our writers.

Prints wall times and rates; nothing is asserted. Run: .venv/bin/python benchmarks/bench_trk234.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from parsers import TrackingData, tdm, trk234
from parsers.tdm.message import Segment


def _clock(label: str, fn, n: int):
    t0 = time.perf_counter()
    out = fn()
    dt = time.perf_counter() - t0
    print(f"{label:<48s} {dt:8.2f} s  {n / dt / 1e6:7.2f} M records/s")
    return out


def doppler_blocks(n: int, interleave_every: int = 0) -> list[trk234.Block]:
    """n one-second 2-way Doppler counts; with interleave_every, a ramp SFDU after every k counts."""
    sec = np.arange(n, dtype=float)
    year, doy = 2012, 100 + (sec // 86400).astype(int)
    blocks = [trk234.new_block(6, n, year=year, doy=doy, sec=sec % 86400, scft_id=181, dl_dss_id=25,
                               ul_prdx_stn=25, prdx_mode=2, cnt_time=1.0, ul_freq=2.1e9, dop_cnt=sec * 2.3e9)]
    if interleave_every:
        k = n // interleave_every
        at = np.arange(k) * interleave_every
        blocks[0].index = np.arange(n) + np.searchsorted(at, np.arange(n), side="right")
        blocks.append(trk234.new_block(9, k, index=at + np.arange(k), year=year, doy=doy[at], sec=sec[at] % 86400,
                                       ul_dss_id=25, ramp_freq=2.1e9 + at, ramp_rate=0.1))
    return blocks


def bench_trk234(folder: Path) -> None:
    n = 1_000_000
    blocks = _clock("TRK-2-34 build 10^6 Doppler SFDUs", lambda: doppler_blocks(n), n)
    path = folder / "big.tnf"
    _clock("TRK-2-34 write 10^6 SFDUs (220 MB)", lambda: trk234.write(path, blocks), n)
    d = _clock("TRK-2-34 read 10^6 SFDUs -> TrackingTable", lambda: trk234.read(path), n)
    print(f"    rows {len(d.table)}, file {path.stat().st_size / 1e6:.0f} MB")
    mixed = doppler_blocks(200_000, interleave_every=10)
    path2 = folder / "mixed.tnf"
    trk234.write(path2, mixed)
    d = _clock("TRK-2-34 read 2.2e5 SFDUs, ramp every 10 counts", lambda: trk234.read(path2), 220_000)
    print(f"    rows {len(d.table)}, ramps {len(d.ramps)}")


def bench_tdm(folder: Path) -> None:
    n = 500_000
    epochs = np.datetime64("2024-01-01T00:00:00", "ns") + np.arange(n).astype("timedelta64[s]")
    meta = {"TIME_SYSTEM": "UTC", "PARTICIPANT_1": "DSS-25", "PARTICIPANT_2": "SC", "MODE": "SEQUENTIAL",
            "PATH": "1,2,1", "INTEGRATION_INTERVAL": "1.0", "INTEGRATION_REF": "MIDDLE", "RANGE_UNITS": "km"}
    keys = np.where(np.arange(n) % 2 == 0, "DOPPLER_INTEGRATED", "RANGE").astype(object)
    table = pd.DataFrame({"epoch": epochs, "keyword": keys, "segment": 0, "record": np.arange(n),
                          "value": np.random.default_rng(1).normal(1e6, 1e3, n)})
    data = TrackingData(table, meta={"version": "2.0", "header": {"ORIGINATOR": "odpipe"},
                                            "segments": [Segment(meta=meta)]})
    for syntax in ("kvn", "xml"):
        path = folder / f"big.{syntax}"
        _clock(f"TDM write {n} lines ({syntax})", lambda: tdm.write(path, data, syntax=syntax), n)
        d = _clock(f"TDM read {n} lines ({syntax}) -> TrackingTable", lambda: tdm.read(path), n)
        print(f"    rows {len(d.table)}, file {path.stat().st_size / 1e6:.0f} MB")


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        bench_trk234(Path(tmp))
        bench_tdm(Path(tmp))
