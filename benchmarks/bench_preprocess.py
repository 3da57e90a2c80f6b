"""Preprocessing throughput: passes, Doppler compression and editing of 10^6 one-second samples."""

from __future__ import annotations

import time

import numpy as np

from odpipe.preprocess.compress import compress
from odpipe.preprocess.edit import edit
from odpipe.tracking.passes import assign_passes
from parsers.table import build

N = 1_000_000
LINKS = 4


def synthetic(n: int = N) -> "pd.DataFrame":
    """n 1-s two-way Doppler samples over LINKS stations, 8-h passes with 2-h gaps, white noise."""
    rng = np.random.default_rng(0)
    per = n // LINKS
    k = np.arange(per)
    t = (k // 28800) * 36000 + k % 28800 + 0.5  # s: 8-h passes, 2-h gaps
    t = np.tile(t, LINKS)
    station = np.repeat([f"DSS-{s}" for s in (14, 25, 43, 63)[:LINKS]], per)
    value = 2e4 * np.sin(2 * np.pi * t / 6800.0) + rng.normal(0, 0.005, len(t))
    return build(len(t), epoch=np.datetime64("2012-04-09T00:00:00", "ns") + (t * 1e9).astype("timedelta64[ns]"),
                 tag="interval_mid", observable="doppler_2way", value=value, unit="Hz", sigma=0.005,
                 count_time=1.0, station_tx=station, station_rx=station, spacecraft="181", band_up="S",
                 band_down="S", uplink_hz=2.1e9, source="synthetic", record=np.arange(len(t)), flags=0)


def timed(label, fn, *args, **kw):
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    print(f"{label:<34s} {time.perf_counter() - t0:7.2f} s")
    return out


def main() -> None:
    tab = synthetic()
    print(f"{len(tab)} samples, {LINKS} links")
    tab = timed("assign passes", assign_passes, tab)
    timed("compress 1 s -> 60 s", compress, tab, 60.0)
    timed("edit (all editors)", edit, tab)


if __name__ == "__main__":
    main()
