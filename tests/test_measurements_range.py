"""DSN sequential/PN range in range units and metres: definition, modulus, ramp, delays, partials."""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.constants import C_LIGHT
from odpipe.measurements.bands import RANGE_UNIT_FACTOR, TURNAROUND, range_unit_factor, turnaround_ratio
from odpipe.measurements.computed import ConstantUplink
from odpipe.measurements.dsn import dsn_range
from odpipe.measurements.lighttime import anchor_from_utc, solve_path
from odpipe.measurements.nodes import SpacecraftNode, StationNode
from odpipe.measurements.partials import epoch_state_partials, station_partials
from parsers.ramps import RampStore
from test_doppler import EPOCHS, T0, _scenario, _solve
from test_measurements_helpers import DSS14_ITRS, rigid_earth

F_S = 2.1e9


def test_band_tables_are_moyers_ratios():
    assert TURNAROUND[("S", "S")] == 240 / 221 and TURNAROUND[("X", "X")] == 880 / 749
    assert TURNAROUND[("S", "X")] == 880 / 221 and TURNAROUND[("X", "Ka")] == 3344 / 749
    assert TURNAROUND[("Ka", "Ka")] == 3360 / 3599
    # every pair maps a DSN uplink allocation into its downlink allocation (Hz)
    up = {"S": 2.115e9, "X": 7.16e9, "Ka": 34.35e9}
    down = {"S": (2.29e9, 2.30e9), "X": (8.40e9, 8.50e9), "Ka": (31.8e9, 32.3e9)}
    for (u, d), m2 in TURNAROUND.items():
        assert down[d][0] < m2 * up[u] < down[d][1], (u, d)
    np.testing.assert_allclose(turnaround_ratio(["s", "X", "x"], ["S", "X", "ka"]), [240 / 221, 880 / 749, 3344 / 749])
    np.testing.assert_allclose(range_unit_factor(["S", "X", "Ka"]), [0.5, 221 / 1498, 221 / 7198])
    assert np.isnan(turnaround_ratio(["S"], [""])[0])
    # an X-band uplink near 7.16 GHz gives range units of about 0.94 ns of round trip (~14 cm one-way)
    ru_s = 1 / (RANGE_UNIT_FACTOR["X"] * 7.16e9)
    assert 0.9e-9 < ru_s < 1.0e-9


def test_range_units_are_f_times_rtlt_and_wrap_at_the_modulus():
    traj, st = _scenario()
    sol = _solve(traj, st, EPOCHS)
    up = ConstantUplink(F_S)
    r_ru = dsn_range(sol, up, "DSS-14", EPOCHS, 0.5).value
    np.testing.assert_allclose(r_ru, 0.5 * F_S * sol.clock_time, rtol=1e-15)
    r_m = dsn_range(sol, up, "DSS-14", EPOCHS, 0.5, unit="m")
    np.testing.assert_allclose(r_m.value, C_LIGHT * sol.clock_time / 2, rtol=1e-15)
    # converting RU to metres with to_los gives the metres
    r_full = dsn_range(sol, up, "DSS-14", EPOCHS, 0.5)
    np.testing.assert_allclose(r_full.value * r_full.to_los, r_m.value, rtol=1e-12)
    m = 2.0**20
    wrapped = dsn_range(sol, up, "DSS-14", EPOCHS, 0.5, modulus=m).value
    np.testing.assert_allclose(wrapped, np.mod(r_ru, m), rtol=1e-12)
    assert np.all((wrapped >= 0) & (wrapped < m))
    # station + transponder delay adds F f delay
    d = dsn_range(sol, up, "DSS-14", EPOCHS, 0.5, delay_s=1e-6).value
    np.testing.assert_allclose(d - r_ru, 0.5 * F_S * 1e-6, rtol=1e-6)


def test_ramped_range_integrates_the_uplink_over_the_round_trip():
    """A 10 Hz/s ramp: R = F (f(t1) rho + rate rho^2 / 2), f evaluated at transmission."""
    traj, st = _scenario()
    sol = _solve(traj, st, EPOCHS)
    rate, f0 = 10.0, F_S
    start = T0 - np.timedelta64(1, "h")
    ramps = RampStore(pd.DataFrame({"station": ["DSS-14"], "start": [start], "end": [T0 + np.timedelta64(10, "h")],
                                    "freq_hz": [f0], "rate_hz_s": [rate], "band": ["S"], "source": ["t"], "record": [0]}))
    r = dsn_range(sol, ramps, "DSS-14", EPOCHS, 0.5).value
    rho = sol.clock_time
    t1 = (EPOCHS - start).astype(np.int64) * 1e-9 - rho
    np.testing.assert_allclose(r, 0.5 * ((f0 + rate * t1) * rho + rate * rho**2 / 2), rtol=1e-13)


def test_range_read_at_another_uplink_epoch_integrates_from_t1_to_that_epoch():
    """R = F integral(f_T, t1, s): a 10 Hz/s ramp read 300 s before reception (NaT rows: at reception)."""
    traj, st = _scenario()
    sol = _solve(traj, st, EPOCHS)
    rate, f0, start = 10.0, F_S, T0 - np.timedelta64(1, "h")
    ramps = RampStore(pd.DataFrame({"station": ["DSS-14"], "start": [start], "end": [T0 + np.timedelta64(10, "h")],
                                    "freq_hz": [f0], "rate_hz_s": [rate], "band": ["S"], "source": ["t"], "record": [0]}))
    s = EPOCHS - np.timedelta64(300, "s")
    s[::2] = np.datetime64("NaT")
    r = dsn_range(sol, ramps, "DSS-14", EPOCHS, 0.5, uplink_epoch=s)
    rho = sol.clock_time
    t1 = (EPOCHS - start).astype(np.int64) * 1e-9 - rho
    span = np.where(np.isnat(s), rho, rho - 300.0)
    np.testing.assert_allclose(r.value, 0.5 * ((f0 + rate * t1) * span + rate * span**2 / 2), rtol=1e-13)
    plain = dsn_range(sol, ramps, "DSS-14", EPOCHS, 0.5)  # the orbit enters through t1 alone: same partials
    for a, b in zip(r.events, plain.events):
        np.testing.assert_array_equal(a.d_pos, b.d_pos)


def test_range_partials_vs_finite_differences():
    traj, st = _scenario()
    up = ConstantUplink(F_S)
    r = dsn_range(_solve(traj, st, EPOCHS), up, "DSS-14", EPOCHS, 0.5)
    h = np.array([10.0] * 3 + [0.01] * 3)
    fd = np.zeros((EPOCHS.size, 6))
    for i in range(6):
        dx = np.zeros(6)
        dx[i] = h[i]
        vals = [dsn_range(_solve(traj.with_epoch_state(traj.x0 + s * dx), st, EPOCHS), up, "DSS-14", EPOCHS, 0.5).value
                for s in (1, -1)]
        fd[:, i] = (vals[0] - vals[1]) / (2 * h[i])
    np.testing.assert_allclose(epoch_state_partials(r, "spacecraft", traj), fd, rtol=1e-6)
    # station coordinates: the same antenna transmits and receives
    fd = np.zeros((EPOCHS.size, 3))
    for i in range(3):
        d = np.zeros(3)
        d[i] = 1.0
        vals = [dsn_range(_solve(traj, StationNode(DSS14_ITRS + s * d, rigid_earth(), None, "earth"), EPOCHS), up,
                          "DSS-14", EPOCHS, 0.5).value for s in (1, -1)]
        fd[:, i] = (vals[0] - vals[1]) / 2
    an = station_partials(r, "station_tx", st) + station_partials(r, "station_rx", st)
    np.testing.assert_allclose(an, fd, rtol=1e-5)
    np.testing.assert_allclose(r.params["delay"], 0.5 * F_S, rtol=1e-9)
