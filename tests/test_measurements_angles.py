"""Antenna angles: against the station catalog's topocentric az/el, X/Y identities, and finite differences."""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.environment.stations import Station, topocentric
from odpipe.measurements.angles import antenna_angle
from odpipe.measurements.lighttime import solve_path
from odpipe.measurements.nodes import SpacecraftNode, StationNode
from odpipe.measurements.partials import epoch_state_partials, station_partials
from test_measurements_helpers import DSS14_ITRS, CircularTrajectory, LinearTrajectory, rigid_earth

T = 7.9e8 + np.array([0.0, 3000.0, 9000.0, 15000.0])
TRAJ = LinearTrajectory([3.0e7, -3.5e7, 2.8e7], [-1500.0, 800.0, 300.0], 7.9e8, "earth")


def _angles(kind, traj=TRAJ, itrs=DSS14_ITRS):
    st = StationNode(itrs, rigid_earth(), None, "earth")
    sol = solve_path([SpacecraftNode(traj, None, "earth"), st], T, shapiro_bodies=())
    return antenna_angle(sol, st, kind), sol, st


def test_az_el_match_the_catalog_topocentric_of_the_light_time_position():
    az, sol, st = _angles("azimuth")
    el, _, _ = _angles("elevation")
    r_itrs = np.einsum("nji,nj->ni", st.itrs_to_frame(sol.epochs[:, 1]), sol.states[:, 0, :3])  # frame -> ITRS
    ref_az, ref_el, _ = topocentric(Station("DSS-14", DSS14_ITRS), r_itrs)
    np.testing.assert_allclose(az.value, ref_az, atol=1e-12)
    np.testing.assert_allclose(el.value, ref_el, atol=1e-12)


def test_xy_are_consistent_with_az_el():
    az, _, _ = _angles("azimuth")
    el, _, _ = _angles("elevation")
    x, _, _ = _angles("x")
    y, _, _ = _angles("y")
    ce = np.cos(el.value)
    np.testing.assert_allclose(np.tan(x.value), ce * np.sin(az.value) / np.sin(el.value), rtol=1e-10)
    np.testing.assert_allclose(np.sin(y.value), ce * np.cos(az.value), rtol=1e-10, atol=1e-14)


@pytest.mark.parametrize("kind", ["azimuth", "elevation", "x", "y"])
def test_angle_partials_vs_finite_differences(kind):
    base, _, st = _angles(kind)
    h = np.array([10.0] * 3 + [0.01] * 3)
    fd = np.zeros((T.size, 6))
    for i in range(6):
        dx = np.zeros(6)
        dx[i] = h[i]
        vals = [_angles(kind, TRAJ.with_epoch_state(TRAJ.x0 + s * dx))[0].value for s in (1, -1)]
        fd[:, i] = (vals[0] - vals[1]) / (2 * h[i])
    np.testing.assert_allclose(epoch_state_partials(base, "spacecraft", TRAJ), fd, rtol=1e-5, atol=1e-14)
    fd = np.zeros((T.size, 3))
    for i in range(3):
        d = np.zeros(3)
        d[i] = 10.0
        fd[:, i] = (_angles(kind, itrs=DSS14_ITRS + d)[0].value - _angles(kind, itrs=DSS14_ITRS - d)[0].value) / 20.0
    # moving the antenna also turns its horizon (geodetic axes), which dominates here
    np.testing.assert_allclose(station_partials(base, "station_rx", st), fd, rtol=1e-5, atol=1e-13)
