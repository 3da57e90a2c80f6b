"""Two/three-way and one-way DSN Doppler: sign, constant vs ramped, range differences, quadrature, limits, partials."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from odpipe.constants import C_LIGHT
from odpipe.measurements.bands import TURNAROUND
from odpipe.measurements.computed import ConstantUplink
from odpipe.measurements.dsn import dsn_doppler, dsn_range, one_way_doppler
from odpipe.measurements.lighttime import anchor_from_utc, solve_path
from odpipe.measurements.nodes import SpacecraftNode, StationNode
from odpipe.measurements.partials import epoch_state_partials
from parsers.ramps import RampStore
from test_measurements_helpers import DSS14_ITRS, LinearTrajectory, rigid_earth

T0 = np.datetime64("2025-03-01T06:00:00", "ns")
F_UP = 7.16e9  # Hz, X-band uplink
M2 = TURNAROUND[("X", "X")]


def _scenario(radial=1000.0):
    t0, _ = anchor_from_utc(T0)
    r0 = np.array([2.0e8, -1.5e8, 0.8e8])
    u = r0 / np.linalg.norm(r0)
    v0 = radial * u + np.array([300.0, 500.0, -100.0])
    traj = LinearTrajectory(r0, v0, t0[0], "earth")
    st = StationNode(DSS14_ITRS, rigid_earth(), None, "earth")
    return traj, st


def _solve(traj, st, utc):
    t, c = anchor_from_utc(utc)
    return solve_path([st, SpacecraftNode(traj, None, "earth"), st], t, t_corr=c, shapiro_bodies=())


def _doppler(traj, st, t3e, tc, uplink, **kw):
    t3s = t3e - np.asarray(np.round(np.asarray(tc) * 1e9), dtype="timedelta64[ns]")
    return dsn_doppler(_solve(traj, st, t3s), _solve(traj, st, t3e), uplink, "DSS-14", t3s, t3e, M2, **kw)


EPOCHS = T0 + np.array([600, 3600, 7200, 20000], dtype="timedelta64[s]")


def _ramp(rate, f0=F_UP):
    return RampStore(pd.DataFrame({"station": ["DSS-14"], "start": [T0 - np.timedelta64(1, "h")], "end": [T0 + np.timedelta64(10, "h")],
                                   "freq_hz": [f0 - rate * 3600.0], "rate_hz_s": [rate], "band": ["X"], "source": ["t"], "record": [0]}))


@pytest.mark.parametrize("radial, sign", [(1000.0, 1.0), (-1000.0, -1.0)])
def test_doppler_positive_when_receding(radial, sign):
    traj, st = _scenario(radial)
    d = _doppler(traj, st, EPOCHS, 60.0, ConstantUplink(F_UP))
    assert np.all(np.sign(d.value) == sign)
    # magnitude: 2 M2 f rhodot / c, rhodot = 912 m/s geocentric radial speed +- 465 m/s station rotation
    assert np.all(np.abs(d.value) > 0.4 * 2 * M2 * F_UP * 1000.0 / C_LIGHT)


def test_constant_equals_ramped_with_zero_rate():
    traj, st = _scenario()
    a = _doppler(traj, st, EPOCHS, 60.0, ConstantUplink(F_UP)).value
    b = _doppler(traj, st, EPOCHS, 60.0, _ramp(0.0)).value
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-6)


def test_doppler_is_range_difference_over_count_time():
    """Constant uplink: F = M2 f (2/c)(R_e - R_s)/Tc with R the two-way range in metres at both ends."""
    traj, st = _scenario()
    tc = 60.0
    d = _doppler(traj, st, EPOCHS, tc, ConstantUplink(F_UP)).value
    up = ConstantUplink(F_UP)
    re = dsn_range(_solve(traj, st, EPOCHS), up, "DSS-14", EPOCHS, 0.5, unit="m").value
    rs_t = EPOCHS - np.timedelta64(60, "s")
    rs = dsn_range(_solve(traj, st, rs_t), up, "DSS-14", rs_t, 0.5, unit="m").value
    np.testing.assert_allclose(d, M2 * F_UP * 2 / C_LIGHT * (re - rs) / tc, rtol=1e-12, atol=1e-6)


def test_ramped_doppler_matches_quadrature_of_received_frequency():
    """(1/Tc) integral of [M2 f_R(t3) - M2 f_T(t1) dt1/dt3] dt3 by 12-point Gauss-Legendre, ramp 5 Hz/s."""
    traj, st = _scenario()
    ramp = _ramp(5.0)
    tc = 60.0
    d = _doppler(traj, st, EPOCHS, tc, ramp).value
    x, w = np.polynomial.legendre.leggauss(12)
    acc = np.zeros(EPOCHS.size)
    for xi, wi in zip(x, w):
        t3 = EPOCHS - np.timedelta64(30, "s") + np.timedelta64(int(round(xi * 30e9)), "ns")
        sol = _solve(traj, st, t3)
        f_r = ramp.frequency("DSS-14", t3)
        f_t = ramp.frequency("DSS-14", t3, -sol.clock_time)
        acc += wi * 30.0 * (M2 * f_r - M2 * f_t * (1.0 - sol.rate))
    # the rate is d(rho)/dt3 in TDB; the TDB/TT rate difference (<1e-9 of rho-dot) is below 1e-4 Hz here
    np.testing.assert_allclose(d, acc / tc, rtol=0, atol=2e-4)


def test_doppler_converges_to_range_rate_as_count_time_shrinks():
    traj, st = _scenario()
    t3e = EPOCHS
    errs = []
    for tc in (60.0, 10.0, 1.0):
        d = _doppler(traj, st, t3e - np.timedelta64(int(tc / 2 * 1e9), "ns") + np.timedelta64(int(tc / 2 * 1e9), "ns"),
                     tc, ConstantUplink(F_UP))
        mid = t3e - np.timedelta64(int(tc / 2 * 1e9), "ns")
        limit = M2 * F_UP * _solve(traj, st, mid).rate
        errs.append(np.max(np.abs(d.value - limit)))
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 1e-3  # Hz; second-order in Tc


@pytest.mark.parametrize("uplink, reference", [(ConstantUplink(F_UP), None), (_ramp(50.0), None),
                                               (_ramp(50.0), np.full(EPOCHS.size, F_UP + 1e5))],
                         ids=["constant", "ramped", "ramped-odf-reference"])
def test_doppler_partials_vs_finite_differences_of_epoch_state(uplink, reference):
    """Constant and ramped (50 Hz/s) uplinks, with the transmitter's ramp or an ODF f_REF as the reference."""
    traj, st = _scenario()
    up = uplink
    kw = {} if reference is None else {"reference": reference}
    d = _doppler(traj, st, EPOCHS, 60.0, up, **kw)
    h = np.array([100.0] * 3 + [0.01] * 3)
    fd = np.zeros((EPOCHS.size, 6))
    for i in range(6):
        dx = np.zeros(6)
        dx[i] = h[i]
        plus = _doppler(traj.with_epoch_state(traj.x0 + dx), st, EPOCHS, 60.0, up, **kw).value
        minus = _doppler(traj.with_epoch_state(traj.x0 - dx), st, EPOCHS, 60.0, up, **kw).value
        fd[:, i] = (plus - minus) / (2 * h[i])
    an = epoch_state_partials(d, "spacecraft", traj)
    np.testing.assert_allclose(an[:, 3:], fd[:, 3:], rtol=1e-5)
    np.testing.assert_allclose(an[:, :3], fd[:, :3], rtol=1e-3, atol=1e-9)


def _one_way(traj, st, t3e, tc, **kw):
    t3s = t3e - np.timedelta64(int(tc * 1e9), "ns")
    nodes = [SpacecraftNode(traj, None, "earth"), st]
    sols = [solve_path(nodes, a[0], t_corr=a[1], shapiro_bodies=()) for a in (anchor_from_utc(t3s), anchor_from_utc(t3e))]
    return one_way_doppler(sols[0], sols[1], 8.4e9, tc, **kw)


def test_one_way_doppler_sign_scale_and_oscillator_partials():
    traj, st = _scenario(1000.0)
    base = _one_way(traj, st, EPOCHS, 60.0)
    assert np.all(base.value > 0.4 * 8.4e9 * 1000.0 / C_LIGHT)
    # an oscillator high by 1 Hz (y0 = 1 / 8.4e9) lowers the observable by 1 Hz (f_ref - f_received)
    hi = _one_way(traj, st, EPOCHS, 60.0, y0=1.0 / 8.4e9)
    np.testing.assert_allclose(hi.value - base.value, -1.0, atol=1e-5)
    np.testing.assert_allclose(hi.value - base.value, base.params["osc_y0"] / 8.4e9, rtol=1e-9)
    dr = _one_way(traj, st, EPOCHS, 60.0, y1=1e-16, t_ref=0.0)
    np.testing.assert_allclose((dr.value - base.value) / 1e-16, base.params["osc_y1"], rtol=1e-6)
    # velocity partials vs finite differences
    fd = np.zeros((EPOCHS.size, 3))
    for i in range(3):
        dx = np.zeros(6)
        dx[3 + i] = 0.01
        fd[:, i] = (_one_way(traj.with_epoch_state(traj.x0 + dx), st, EPOCHS, 60.0).value
                    - _one_way(traj.with_epoch_state(traj.x0 - dx), st, EPOCHS, 60.0).value) / 0.02
    np.testing.assert_allclose(epoch_state_partials(base, "spacecraft", traj)[:, 3:], fd, rtol=1e-5)


def test_proper_rate_at_the_geocenter_averages_to_iers_lc():
    """1 - dτ/dt of a clock at the geocentre, from the bodies external to the Earth, averaged over 2000-2020,
    is the IERS 2010 constant L_C = 1.48082686741e-8 (the mean rate of TCG against TCB)."""
    from odpipe.environment.ephemeris import Ephemeris
    from odpipe.measurements.nodes import proper_rate_offset

    t = np.linspace(0.0, 20 * 365.25 * 86400.0, 20000)
    rate = proper_rate_offset(Ephemeris.open("de440"), "earth", t, np.zeros((t.size, 6)),
                              bodies=("sun", "moon", "venus", "mars", "jupiter", "saturn"))
    assert abs(np.mean(rate) - 1.48082686741e-8) < 1e-13
