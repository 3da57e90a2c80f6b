"""Local orbital frames and the Earth–Moon rotating frame, checked by their defining properties."""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.environment.ephemeris import Ephemeris
from odpipe.frames.local import earth_moon_rotating_state, ric_matrix, rtn_matrix


def test_rtn_axes_for_an_inclined_orbit():
    # circular orbit, inclination 30 deg, at the ascending node: R = x, T = (0, cos i, sin i), N = (0, -sin i, cos i)
    i = np.radians(30.0)
    r = np.array([7.0e6, 0.0, 0.0])
    v = 7.5e3 * np.array([0.0, np.cos(i), np.sin(i)])
    m = rtn_matrix(r, v)
    np.testing.assert_allclose(m, [[1, 0, 0], [0, np.cos(i), np.sin(i)], [0, -np.sin(i), np.cos(i)]], atol=1e-15)
    assert ric_matrix is rtn_matrix
    with pytest.raises(ValueError, match="degenerate"):
        rtn_matrix(r, 2 * r)


def test_rotating_frame_puts_the_moon_on_the_x_axis_at_rest():
    eph = Ephemeris.open()
    t = np.linspace(0.0, 27 * 86400.0, 50)
    moon = eph.state("moon", "earth", t)
    mu = eph.gm("moon") / (eph.gm("moon") + eph.gm("earth"))
    r, v = earth_moon_rotating_state(moon[:, :3], moon[:, 3:], moon[:, :3], moon[:, 3:], mass_ratio=mu,
                                     normalize=True)
    np.testing.assert_allclose(r, np.tile([1 - mu, 0, 0], (50, 1)), atol=1e-12)
    np.testing.assert_allclose(v[:, 1:], 0.0, atol=1e-12)          # only the radial breathing remains
    assert np.abs(v[:, 0]).max() < 0.1
    # the Earth sits at -mu on the x axis and moves with -mu times the Moon's radial rate
    r_e, _ = earth_moon_rotating_state(np.zeros((50, 3)), np.zeros((50, 3)), moon[:, :3], moon[:, 3:],
                                       mass_ratio=mu, normalize=True)
    np.testing.assert_allclose(r_e, np.tile([-mu, 0, 0], (50, 1)), atol=1e-12)
