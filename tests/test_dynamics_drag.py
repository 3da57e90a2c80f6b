"""Atmospheric drag: Harris-Priester density vs Montenbruck & Gill Table 3.8, the analytic
decay rate of a circular orbit, and the acceleration partials vs central differences."""

import numpy as np
import pytest

from odpipe.dynamics.drag import OMEGA_EARTH, R_EQUATOR, harris_priester
from odpipe.dynamics.forces import AtmosphericDrag, ForceModel, compile_model
from odpipe.dynamics.propagator import propagate
from odpipe.dynamics.rhs import acceleration
from odpipe.environment.ephemeris import Ephemeris

T0 = 725_846_469.0  # 2023-01-01 (TDB s past J2000)
GM = 3.986004418e14


@pytest.fixture(scope="module")
def eph():
    return Ephemeris.open("de440")


# M&G (2000) Table 3.8, mean solar activity: (height km, rho_min, rho_max) in g/km^3
MG_TABLE_38 = [(200, 255.7, 316.2), (400, 2.249, 7.492), (500, 0.3916, 2.042), (800, 0.007069, 0.08059)]


@pytest.mark.parametrize("h_km, rho_min, rho_max", MG_TABLE_38)
def test_density_at_table_heights_night_and_bulge_apex(h_km, rho_min, rho_max):
    r = np.array([R_EQUATOR + h_km * 1e3, 0.0, 0.0])   # equator: geodetic height = h
    lag = np.radians(30.0)
    apex = np.array([np.cos(-lag), np.sin(-lag), 0.0]) * 1.5e11   # Sun 30 deg east of the apex
    anti = -apex
    for n in (2.0, 6.0):
        assert harris_priester(r, apex, n)[0] == pytest.approx(rho_max * 1e-12, rel=1e-9)
        assert harris_priester(r, anti, n)[0] == pytest.approx(rho_min * 1e-12, rel=1e-9)
    # halfway between the apex and the antapex: cos^n(psi/2) = 0.5^(n/2)
    side = np.array([np.cos(-lag + np.pi / 2), np.sin(-lag + np.pi / 2), 0.0]) * 1.5e11
    expect = rho_min + (rho_max - rho_min) * 0.5**3
    assert harris_priester(r, side, 6.0)[0] == pytest.approx(expect * 1e-12, rel=1e-9)


def test_density_decays_exponentially_between_table_heights():
    # 450 km night side: geometric mean of the 440 and 460 km values (M&G eq. 3.100)
    r = np.array([R_EQUATOR + 450e3, 0.0, 0.0])
    sun = np.array([np.cos(np.radians(150.0)), np.sin(np.radians(150.0)), 0.0]) * 1.5e11   # bulge apex at -x
    assert harris_priester(r, sun, 2.0)[0] == pytest.approx(np.sqrt(1.091 * 0.7701) * 1e-12, rel=1e-9)
    assert harris_priester(np.array([R_EQUATOR + 1001e3, 0.0, 0.0]), sun, 2.0)[0] == 0.0


def _accel(model, t, x):
    npar = model.n_params
    acc, gr, gv, dp = np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((npar, 3))
    acceleration(t, x[:3].copy(), x[3:].copy(), model, acc, gr, gv, dp)
    return acc, gr, gv, dp


def test_drag_partials_vs_central_differences(eph):
    x = np.array([4.1e6, 4.9e6, 2.2e6, -5.8e3, 3.1e3, 3.9e3])   # about 400 km
    drag = AtmosphericDrag(cd=2.5, area=2.0, n_bulge=6.0)
    fm = ForceModel("earth", [drag], mass=1000.0, ephemeris=eph, central_gm=0.0)
    model = compile_model(fm, T0, T0 + 3600.0, ["cd"], True)
    t = T0 + 600.0
    acc, gr, gv, dp = _accel(model, t, x)
    assert 1e-7 < np.linalg.norm(acc) < 1e-5
    assert np.dot(acc, x[3:]) < 0     # opposes the motion
    for j in range(3):
        e = np.zeros(6)
        e[j] = 10.0
        fd = (_accel(model, t, x + e)[0] - _accel(model, t, x - e)[0]) / 20.0
        np.testing.assert_allclose(gr[:, j], fd, rtol=0, atol=1e-5 * np.abs(gr).max())
        e = np.zeros(6)
        e[3 + j] = 0.1
        fd = (_accel(model, t, x + e)[0] - _accel(model, t, x - e)[0]) / 0.2
        np.testing.assert_allclose(gv[:, j], fd, rtol=0, atol=1e-6 * np.abs(gv).max())
    np.testing.assert_allclose(dp[0], acc / 2.5, rtol=1e-12)
    # the drag is the component: point-mass only model differs by exactly it
    drag.cd = 0.0
    assert np.allclose(_accel(compile_model(fm, T0, T0 + 3600.0, [], False), t, x)[0], 0.0)


def test_circular_orbit_decay_rate_matches_analytic(eph):
    """Equatorial circular orbit, point-mass Earth + drag: da/dt = -(Cd A/m) rho sqrt(GM a) (1 - w/n)^2
    (King-Hele; v_r = v (1 - w/n) in a co-rotating atmosphere), integrated over the sampled density."""
    a0 = R_EQUATOR + 400e3
    v0 = np.sqrt(GM / a0)
    x0 = np.array([a0, 0.0, 0.0, 0.0, v0, 0.0])
    cd, area, mass = 2.2, 4.0, 500.0
    fm = ForceModel("earth", [AtmosphericDrag(cd, area, 2.0)], mass=mass, ephemeris=eph, central_gm=GM)
    day = 86400.0
    tr = propagate(x0, T0, T0 + day, fm, with_stm=False)
    t = np.linspace(T0, T0 + day, 4001)
    X = tr.state(t)
    r = np.linalg.norm(X[:, :3], axis=1)
    a = 1.0 / (2.0 / r - np.sum(X[:, 3:] ** 2, axis=1) / GM)
    sun = eph.position("sun", "earth", t)
    rho = np.array([harris_priester(X[k, :3], sun[k], 2.0)[0] for k in range(t.size)])
    n = np.sqrt(GM / a**3)
    rate = -(cd * area / mass) * rho * np.sqrt(GM * a) * (1.0 - OMEGA_EARTH / n) ** 2
    expect = np.sum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t))
    assert expect < -20.0                     # tens of metres a day at 400 km
    assert a[-1] - a[0] == pytest.approx(expect, rel=0.01)
