"""Throughput of the measurement models (observables with full partials per second).

1. LiAISON crosslink two-way Doppler (halo + GEO, 12 epoch-state partials),
   Earth-centred solve, straight-line trajectories with closed-form STM
   (so the figure is the models', not the integrator's dense output).
2. The same rows as two-way range.
3. DSN two-way Doppler through compute(): DE440, IAU 2006/2000A Earth
   orientation with EOP, Sun+Earth Shapiro, SSB solve, 6 state partials + station + bias.
Run: .venv/bin/python benchmarks/bench_measurements.py [N]
"""

from __future__ import annotations

import sys
import time

import numpy as np

from odpipe.measurements.crosslink import two_way_doppler, two_way_range
from odpipe.measurements.lighttime import solve_path
from odpipe.measurements.nodes import SpacecraftNode
from odpipe.measurements.partials import epoch_state_partials


class Line:
    """r0 + v0 (t - t0), with its STM."""

    def __init__(self, r0, v0, center="earth"):
        self.x0, self.center = np.concatenate([r0, v0]), center

    def state(self, t):
        t = np.atleast_1d(t)
        return np.concatenate([self.x0[:3] + t[:, None] * self.x0[3:], np.broadcast_to(self.x0[3:], (t.size, 3))], 1)

    def stm(self, t):
        t = np.atleast_1d(t)
        phi = np.broadcast_to(np.eye(6), (t.size, 6, 6)).copy()
        phi[:, 0, 3] = phi[:, 1, 4] = phi[:, 2, 5] = t
        return phi


def crosslink(n):
    halo = Line(np.array([3.33321e8, -7.61342e7, -2.08739e7]), np.array([257.178, 930.274, 346.177]))
    geo = Line(np.array([4.216e7, 0.0, 0.0]), np.array([0.0, 3074.97, 0.536683]))
    nodes = [SpacecraftNode(halo, None, "earth"), SpacecraftNode(geo, None, "earth"), SpacecraftNode(halo, None, "earth")]
    t = np.linspace(0.0, 86400.0, n)
    out = {}
    for name in ("doppler", "range"):
        t0 = time.perf_counter()
        if name == "doppler":
            e = solve_path(nodes, t, anchor="transmit", shapiro_bodies=(), origin="earth")
            s = solve_path(nodes, t - 60.0, anchor="transmit", shapiro_bodies=(), origin="earth")
            comp = two_way_doppler(s, e, 60.0)
        else:
            comp = two_way_range(solve_path(nodes, t, anchor="transmit", shapiro_bodies=(), origin="earth"))
        h = np.concatenate([epoch_state_partials(comp, "sc1", halo), epoch_state_partials(comp, "sc2", geo)], 1)
        dt = time.perf_counter() - t0
        assert h.shape == (n, 12) and np.all(np.isfinite(comp.value))
        out[name] = n / dt
    return out


def dsn(n):
    from odpipe.measurements.compute import MeasurementSetup, compute
    from odpipe.measurements.lighttime import anchor_from_utc
    from parsers.table import build

    setup = MeasurementSetup.default()
    epoch = np.datetime64("2025-03-01T00:00:00", "ns") + (np.arange(n) * (86400e9 / n)).astype("timedelta64[ns]")
    t0 = anchor_from_utc(epoch[:1])[0][0]
    sc = Line(np.array([2.0e8, -2.5e8, 1.2e8]), np.array([600.0, 800.0, -200.0]))
    sc.state = (lambda f: lambda t: f(np.atleast_1d(t) - t0))(sc.state)
    sc.stm = (lambda f: lambda t: f(np.atleast_1d(t) - t0))(sc.stm)
    rows = build(n, epoch=epoch, observable="doppler_2way", unit="Hz", station_tx="DSS-14", station_rx="DSS-14",
                 spacecraft="A", tag="interval_mid", count_time=60.0, band_up="X", band_down="X", uplink_hz=7.16e9,
                 value=0.0)
    compute(rows[:10], {"A": sc}, setup)  # warm-up (numba cache, EOP tables)
    t_start = time.perf_counter()
    ev = compute(rows, {"A": sc}, setup)
    dt = time.perf_counter() - t_start
    assert np.all(np.isfinite(ev.value))
    return n / dt


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 200_000
    crosslink(1000)  # compile / warm caches
    runs = [crosslink(n) for _ in range(3)]  # the machine is shared: report the best of three
    r = {k: max(x[k] for x in runs) for k in runs[0]}
    print(f"crosslink two-way Doppler, 12 state partials: {r['doppler']:,.0f} observables/s (N={n})")
    print(f"crosslink two-way range,   12 state partials: {r['range']:,.0f} observables/s (N={n})")
    m = min(n, 50_000)
    print(f"DSN two-way Doppler via compute() (DE440, EOP, Shapiro): {dsn(m):,.0f} observables/s (N={m})")
