"""Libration-orbit pieces of the simulator: CRTBP Lyapunov orbit, pulsating-frame conversions, spin signature."""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.dynamics import jacobi_constant, propagate_crtbp
from odpipe.simulate.libration import collinear_point, icrf_to_rotating, lyapunov_orbit, rotating_to_icrf
from odpipe.simulate.observe import spin_signature

MU = 0.012150584269940356


@pytest.mark.parametrize("point, amplitude", [(1, 0.01), (2, 0.02)])
def test_lyapunov_orbit_closes_and_keeps_jacobi(point, amplitude):
    s, period = lyapunov_orbit(MU, point, amplitude)
    tr = propagate_crtbp(s, 0.0, period, MU, with_stm=False)
    x = tr.state(np.linspace(0.0, period, 400))
    assert np.abs(tr.state(period)[0] - s).max() < 1e-9
    assert np.ptp(jacobi_constant(x, MU)) < 1e-10
    assert np.abs(x[:, 0] - collinear_point(MU, point)).max() <= amplitude * 1.3   # stays about its L point
    assert 2.4 < period < 3.6                                                         # 10-16 days


def test_collinear_points_are_equilibria():
    for k in (1, 2):
        x = collinear_point(MU, k)
        r1, r2 = abs(x + MU), abs(x - 1 + MU)
        assert abs(x - (1 - MU) * (x + MU) / r1**3 - MU * (x - 1 + MU) / r2**3) < 1e-14


def test_pulsating_frame_round_trip_and_velocity_is_the_rate_of_position():
    from odpipe.environment.ephemeris import Ephemeris

    eph = Ephemeris.open("de421")
    t0 = 343483200.0
    moon = eph.state("moon", "earth", np.array([t0]))[0]
    s = np.array([0.83, 0.02, 0.001, 0.01, -0.05, 0.002])
    x = rotating_to_icrf(s, MU, moon)
    np.testing.assert_allclose(icrf_to_rotating(x, MU, moon)[0], s, rtol=0, atol=1e-13)
    # a straight inertial path: rotating position differenced in time (outside check of the velocity terms)
    h = 60.0
    ts = t0 + np.array([-h, 0.0, h])
    xs = x + np.outer(ts - t0, np.r_[x[3:], 0, 0, 0])
    rot = icrf_to_rotating(xs, MU, eph.state("moon", "earth", ts))
    w = np.linalg.norm(np.cross(moon[:3], moon[3:])) / np.sum(moon[:3] ** 2)
    rate = (rot[2, :3] - rot[0, :3]) / (2 * h) / w
    # 1e-4 (10 cm/s): the synodic frame's turn about its x axis (Moon's out-of-plane acceleration) is not
    # modelled; leaving out the pulsation term d'/d would miss by ~0.04 (40 m/s)
    np.testing.assert_allclose(rate, s[3:], rtol=0, atol=1e-4)


def test_spin_signature_is_the_count_average_of_the_rate():
    a, w, phi, ct = 0.002, 2 * np.pi / 3.0, 0.7, 60.0
    t = np.array([100.0, 1234.5])
    got = spin_signature(t, np.full(2, ct), a, w, phi)
    tau = np.linspace(0.0, 1.0, 200001)
    for k in range(2):
        rate = a * w * np.cos(w * (t[k] - ct + ct * tau) + phi)
        assert abs(np.trapezoid(rate, tau) - got[k]) < 1e-10


def test_embedded_case_stays_at_l1_four_weeks_with_small_station_keeping():
    from pathlib import Path

    from odpipe.environment.ephemeris import Ephemeris
    from odpipe.simulate.case import load
    from odpipe.simulate.truth import simulate_truth

    case = load(Path(__file__).resolve().parents[1] / "runs" / "artemis_p2_like.toml")
    eph = Ephemeris.open("de421")
    truth = simulate_truth(case, eph, np.random.default_rng(case.seed))
    mu = eph.gm("moon") / (eph.gm("moon") + eph.gm("earth"))
    t = np.linspace(truth.trajectory.t0, truth.trajectory.t1, 600)
    assert t[-1] - t[0] >= 28 * 86400.0
    rot = icrf_to_rotating(truth.trajectory.state(t), mu, eph.state("moon", "earth", t))
    # the Lyapunov orbit's size (0.01 in x, 0.04 in y; 1 = 384400 km) kept to within 25 %
    assert np.abs(rot[:, 0] - collinear_point(MU, 1)).max() < 0.0125
    assert np.abs(rot[:, 1]).max() < 0.05
    sk = np.array([m["kind"] == "station-keeping" for m in truth.maneuvers])
    assert sk.sum() == 4 and np.allclose(np.diff(truth.epochs[sk]), 7 * 86400.0, atol=0.01)   # TDB - UTC wobble
    dv = np.linalg.norm(truth.designed[sk], axis=1)
    assert dv.max() < 1.0 and dv.min() > 0.0
    err = np.linalg.norm(truth.executed - truth.designed, axis=1) / np.linalg.norm(truth.designed, axis=1)
    assert 0 < err.max() < 0.05          # execution errors applied (0.5 %, 0.5 deg 1-sigma)
