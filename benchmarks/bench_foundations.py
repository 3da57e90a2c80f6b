"""Foundations benchmark: time conversion, GCRS↔ITRS, Moon PA, ephemeris for 100,000 epochs.

Run: .venv/bin/python benchmarks/bench_foundations.py
"""

from __future__ import annotations

import time

import numpy as np

from odpipe.environment.ephemeris import Ephemeris, interp_positions
from odpipe.environment.solid_tides import solid_earth_tide
from odpipe.frames.earth import _cip_xys_direct, cip_xys, gcrs_to_itrs, itrs_to_gcrs_state
from odpipe.frames.moon import moon_pa_to_icrf
from odpipe.time import utc_to_tdb

N = 100_000


def timed(label, fn, repeat=3):
    fn()  # warm up (numba compile, table loads)
    best = min(_once(fn) for _ in range(repeat))
    print(f"{label:<58s} {best * 1e3:9.1f} ms  ({best / N * 1e9:7.0f} ns/epoch)")


def _once(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def main():
    utc = np.datetime64("2012-04-08T00:00", "ns") + (np.arange(N) * 864_000_000).astype("timedelta64[ns]")  # 1 day
    utc30 = np.datetime64("2012-04-08T00:00", "ns") + (np.arange(N) * 25_920_000_000).astype("timedelta64[ns]")
    t = utc_to_tdb(utc)
    r = np.tile([-2353621.42, -4641341.472, 3677052.318], (N, 1))
    print(f"N = {N} epochs")
    timed("UTC -> TDB (datetime64 -> float s)", lambda: utc_to_tdb(utc))
    timed("GCRS->ITRS matrices, 1-day arc (CIP grid)", lambda: gcrs_to_itrs(utc))
    timed("GCRS->ITRS matrices, 30-day arc (CIP grid)", lambda: gcrs_to_itrs(utc30))
    timed("GCRS->ITRS matrices from TDB floats, 1-day arc", lambda: gcrs_to_itrs(t))
    timed("ITRS->GCRS station state (r, v), 1-day arc", lambda: itrs_to_gcrs_state(utc, r))
    timed("CIP X,Y,s full IAU 2006/2000A series (no grid)", lambda: _cip_xys_direct(t / 86400.0), repeat=1)
    x, y, s = cip_xys(np.asarray(t / 86400.0))
    xd, yd, sd = _cip_xys_direct(t[::97] / 86400.0)
    err = max(np.abs(x[::97] - xd).max(), np.abs(y[::97] - yd).max(), np.abs(s[::97] - sd).max())
    print(f"{'  CIP grid interpolation error (max over 1031 epochs)':<58s} {err:9.2e} rad")
    eph = Ephemeris.open()
    timed("Sun + Moon geocentric positions (jplephem, vectorized)",
          lambda: (eph.position("sun", "earth", t), eph.position("moon", "earth", t)))
    interp = eph.interpolant(["sun", "moon"], "earth", t[0], t[-1])
    c, t0, h = interp.coeffs, interp.t_start, interp.t_step
    timed("Sun + Moon via njit interp_positions (python loop)", lambda: [interp_positions(c, t0, h, x) for x in t])
    timed("Sun + Moon interpolant build (1-day arc)", lambda: eph.interpolant(["sun", "moon"], "earth", t[0], t[-1]))
    timed("Moon PA->ICRF matrices (DE421 librations)", lambda: moon_pa_to_icrf(t))
    sun, moon = eph.position("sun", "earth", t), eph.position("moon", "earth", t)
    timed("Solid Earth tide displacement (IERS 2010 steps 1-2)", lambda: solid_earth_tide(r, sun, moon, utc))


if __name__ == "__main__":
    main()
