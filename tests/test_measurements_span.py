"""compute() serves the ephemeris and Earth orientation from per-span tables: same observables as the full models.

The reference is the same computation with the DE440 file (jplephem) and the full
IAU 2006/2000A + EOP rotation at every light-time event.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from odpipe.environment.ephemeris import Ephemeris, SpanEphemeris
from odpipe.measurements import MeasurementSetup, compute
from parsers.table import build


class _FileOnly:
    """The DE440 file without the interpolant method: compute() cannot tabulate it."""

    def __init__(self, eph):
        self._eph = eph

    def state(self, target, center, t):
        return self._eph.state(target, center, t)

    def position(self, target, center, t):
        return self._eph.position(target, center, t)

    def gm(self, body):
        return self._eph.gm(body)


class _Untabulated:
    """The full rotation, wrapped so compute() does not replace it."""

    def __init__(self, fn):
        self.fn = fn

    def __call__(self, t):
        return self.fn(t)


def test_span_ephemeris_reproduces_the_file():
    eph = Ephemeris.open("de440")
    t = 7.9e8 + np.linspace(0.0, 3 * 86400.0, 2001)
    span = SpanEphemeris(eph, t[0] - 3600.0, t[-1] + 3600.0)
    for target, center in (("earth", "ssb"), ("moon", "ssb"), ("sun", "earth"), ("moon", "earth")):
        d = span.state(target, center, t) - eph.state(target, center, t)
        assert np.abs(d[:, :3]).max() < 3e-4, (target, center)  # m: float64 rounding at 1 AU
        assert np.abs(d[:, 3:]).max() < 1e-6, (target, center)   # m/s
    # outside the span: the file itself
    assert np.array_equal(span.state("moon", "earth", t[:1] - 86400.0), eph.state("moon", "earth", t[:1] - 86400.0))


def test_tabulated_compute_matches_full_models():
    class Line:
        center = "earth"

        def state(self, t):
            t = np.atleast_1d(t) - 7.9e8
            r0, v0 = np.array([3.0e8, -1.2e8, 0.6e8]), np.array([600.0, 800.0, -200.0])
            return np.concatenate([r0 + t[:, None] * v0, np.broadcast_to(v0, (t.size, 3))], 1)

    n = 400
    epoch = np.datetime64("2025-01-13T12:00:00", "ns") + (np.arange(n) * 180e9).astype("timedelta64[ns]")
    common = dict(epoch=epoch, station_tx="DSS-14", station_rx="DSS-14", spacecraft="A", band_up="X", band_down="X",
                  uplink_hz=7.16e9, value=0.0)
    dop = build(n, observable="doppler_2way", unit="Hz", tag="interval_mid", count_time=60.0, **common)
    rng = build(n, observable="range", unit="m", tag="receive", count_time=0.0, **common)
    fast = MeasurementSetup.default()
    full = replace(fast, ephemeris=_FileOnly(fast.ephemeris), gcrs_to_itrs=_Untabulated(fast.gcrs_to_itrs))
    for rows, tol in ((dop, 1e-6), (rng, 1e-3)):  # m/s along the line of sight; m
        a, b = compute(rows, {"A": Line()}, fast), compute(rows, {"A": Line()}, full)
        assert np.all(a.status == "") and np.all(np.isfinite(a.value))
        assert np.abs((a.value - b.value) * a.to_los).max() < tol


def test_de421_is_smooth_at_one_second():
    """DE421 from the de421 package: the time argument keeps its precision (jplephem's legacy routine
    rounds it to ~0.6 us, 3 mm RMS of noise in the Earth's barycentric position from one second to the next)."""
    eph = Ephemeris.open("de421")
    t = 3.4e8 + np.arange(0.0, 200.0)
    p = eph.position("earth", "ssb", t)
    x = t - t[0]
    fit = np.array([np.polyval(np.polyfit(x, p[:, i], 3), x) for i in range(3)]).T
    assert (p - fit).std() < 1e-4  # m
