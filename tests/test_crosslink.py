"""LiAISON crosslinks: two-way range/Doppler vs the paper's own recursion, DOWR clock partials vs eq. 10, FD partials.

Scenario: the GEO and Earth-Moon L1 halo states of Fujimoto et al., Table 1
(Earth-centred, m and m/s), flown in straight lines over the short test windows.
"""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.constants import C_LIGHT
from odpipe.measurements.crosslink import ClockModel, dual_one_way, two_way_doppler, two_way_range
from odpipe.measurements.instantaneous import instantaneous_range, instantaneous_range_rate
from odpipe.measurements.lighttime import solve_path
from odpipe.measurements.nodes import SpacecraftNode
from odpipe.measurements.partials import epoch_state_partials
from test_measurements_helpers import LinearTrajectory

L1 = LinearTrajectory([3.33321e8, -7.61342e7, -2.08739e7], [2.57178e2, 9.30274e2, 3.46177e2], 0.0, "earth")
GEO = LinearTrajectory([4.21600e7, 0.0, 0.0], [0.0, 3.07497e3, 5.36683e-1], 0.0, "earth")
T = np.array([100.0, 1000.0, 5000.0])


def _nodes(geo=GEO, l1=L1):
    g, h = SpacecraftNode(geo, None, "earth"), SpacecraftNode(l1, None, "earth")
    return [h, g, h]  # sc1 = halo (transmits and receives), sc2 = GEO


def _seed_rtlpl(t, r1, r2, extrapolate):
    """Fujimoto et al. eqs. 1-3 by their fixed-point recursion (eq. 2's linear extrapolation optional)."""
    def lt(t_tx, tx, rx):
        s_tx = tx.state(np.array([t_tx]))[0]
        s_rx0 = rx.state(np.array([t_tx]))[0]
        tau = 0.0
        for _ in range(30):
            p = s_rx0[:3] + s_rx0[3:] * tau if extrapolate else rx.state(np.array([t_tx + tau]))[0, :3]
            tau = np.linalg.norm(s_tx[:3] - p) / C_LIGHT
        return tau

    lt12 = lt(t, r1, r2)
    return C_LIGHT * (lt12 + lt(t + lt12, r2, r1))


def test_two_way_range_matches_the_papers_recursion():
    sol = solve_path(_nodes(), T, anchor="transmit", shapiro_bodies=())
    rng = two_way_range(sol).value
    exact = np.array([_seed_rtlpl(t, L1, GEO, False) for t in T]) / 2
    np.testing.assert_allclose(rng, exact, rtol=0, atol=1e-6)
    # eq. 2's extrapolation is exact for straight-line motion too
    lin = np.array([_seed_rtlpl(t, L1, GEO, True) for t in T]) / 2
    np.testing.assert_allclose(rng, lin, rtol=0, atol=1e-6)


def test_two_way_doppler_is_eq4_and_tends_to_twice_the_range_rate():
    tc = 60.0
    s = solve_path(_nodes(), T - tc, anchor="transmit", shapiro_bodies=())
    e = solve_path(_nodes(), T, anchor="transmit", shapiro_bodies=())
    d = two_way_doppler(s, e, tc)
    eq4 = np.array([(_seed_rtlpl(t, L1, GEO, False) - _seed_rtlpl(t - tc, L1, GEO, False)) / tc for t in T])
    np.testing.assert_allclose(d.value, eq4, rtol=0, atol=1e-7)
    mid = solve_path(_nodes(), T - tc / 2, anchor="transmit", shapiro_bodies=())
    lim = C_LIGHT * mid.rate  # the limit at mid-interval
    tb = mid.epochs[:, 1]  # bounce at the GEO satellite
    rr = instantaneous_range_rate(L1.state(tb), GEO.state(tb), tb).value
    # straight lines: the count average equals the limit up to O(Tc^2 rho'') and both are 2 rr to O(rr v / c)
    np.testing.assert_allclose(d.value, lim, atol=2e-3)
    assert np.all(np.abs(lim - 2 * rr) < 4 * np.abs(rr) * 3.1e3 / C_LIGHT + 1e-6)
    assert np.all(np.sign(d.value) == np.sign(rr))


@pytest.mark.parametrize("which", ["two_way_range", "two_way_doppler"])
def test_crosslink_partials_vs_finite_differences(which):
    def value(geo, l1):
        if which == "two_way_range":
            return two_way_range(solve_path(_nodes(geo, l1), T, anchor="transmit", shapiro_bodies=()))
        s = solve_path(_nodes(geo, l1), T - 60.0, anchor="transmit", shapiro_bodies=())
        e = solve_path(_nodes(geo, l1), T, anchor="transmit", shapiro_bodies=())
        return two_way_doppler(s, e, 60.0)

    base = value(GEO, L1)
    for role, traj in (("sc1", L1), ("sc2", GEO)):
        h = np.array([10.0] * 3 + [1e-3] * 3)
        fd = np.zeros((T.size, 6))
        for i in range(6):
            dx = np.zeros(6)
            dx[i] = h[i]
            vals = []
            for s in (1, -1):
                moved = traj.with_epoch_state(traj.x0 + s * dx)
                vals.append(value(moved, L1) if role == "sc2" else value(GEO, moved))
            fd[:, i] = (vals[0].value - vals[1].value) / (2 * h[i])
        an = epoch_state_partials(base, role, traj)
        scale = np.max(np.abs(fd), axis=0)
        np.testing.assert_allclose(an, fd, rtol=1e-4, atol=1e-6 * scale.max())


def test_instantaneous_partials_are_the_thesis_eqs_3_103_to_3_114():
    s1, s2 = L1.state(T), GEO.state(T)
    rel = s2 - s1
    u = rel[:, :3] / np.linalg.norm(rel[:, :3], axis=1)[:, None]
    rho = np.linalg.norm(rel[:, :3], axis=1)
    rr = instantaneous_range_rate(s1, s2, T)
    r = instantaneous_range(s1, s2, T)
    np.testing.assert_allclose(r.events[1].d_pos, u)  # 3.105
    np.testing.assert_allclose(r.events[0].d_pos, -u)  # 3.103
    proj = np.eye(3) - np.einsum("ni,nj->nij", u, u)
    eq3113 = np.einsum("ni,nij->nj", rel[:, 3:], proj) / rho[:, None]
    np.testing.assert_allclose(rr.events[1].d_pos, eq3113, rtol=1e-12)  # 3.113
    np.testing.assert_allclose(rr.events[0].d_pos, -eq3113, rtol=1e-12)  # 3.111
    np.testing.assert_allclose(rr.events[1].d_vel, u)  # 3.114
    # and they are derivatives: finite differences on participant 2
    h = 1.0
    for i in range(3):
        d = np.zeros(6)
        d[i] = h
        fd = (instantaneous_range_rate(s1, s2 + d, T).value - instantaneous_range_rate(s1, s2 - d, T).value) / (2 * h)
        np.testing.assert_allclose(rr.events[1].d_pos[:, i], fd, rtol=1e-6, atol=1e-15)


def _dowr(clock1, clock2, geo=GEO, l1=L1):
    h, g = SpacecraftNode(l1, None, "earth"), SpacecraftNode(geo, None, "earth")
    return dual_one_way(solve_path([g, h], T, shapiro_bodies=()), solve_path([h, g], T, shapiro_bodies=()),
                        clock1, clock2)


def test_dual_one_way_clock_partials_match_li_eq10_and_finite_differences():
    c1 = ClockModel(a0=2e-6, a1=5e-9, a2=5e-12 / 86400, t_ref=-200.0)  # the 'DRO' rubidium clock of Table 2
    c2 = ClockModel()
    total, diff = _dowr(c1, c2)
    sol12 = solve_path([SpacecraftNode(L1, None, "earth"), SpacecraftNode(GEO, None, "earth")], T, shapiro_bodies=())
    sol21 = solve_path([SpacecraftNode(GEO, None, "earth"), SpacecraftNode(L1, None, "earth")], T, shapiro_bodies=())
    dt = 0.5 * (sol12.light_time + sol21.light_time)
    np.testing.assert_allclose(diff.params["clock_sc1_a0"], 1.0)
    np.testing.assert_allclose(diff.params["clock_sc1_a1"], T - c1.t_ref - dt / 2, atol=1e-9)
    # eq. 10 uses the mean light time dt; the exact partial uses tau_12 of the signal sc2 received (4e-9 apart here)
    eq10 = 0.25 * ((T - c1.t_ref) ** 2 + (T - c1.t_ref - dt) ** 2)
    np.testing.assert_allclose(diff.params["clock_sc1_a2"], eq10, rtol=1e-7)
    exact = 0.25 * ((T - c1.t_ref) ** 2 + (T - c1.t_ref - sol12.light_time) ** 2)
    np.testing.assert_allclose(diff.params["clock_sc1_a2"], exact, rtol=1e-13)
    assert np.all(np.abs(total.params["clock_sc1_a0"]) < 1e-12)  # the sum removes the offset
    # eq. 5: the difference is half the geometric asymmetry plus the mean of the two clock readings
    geo = 0.5 * C_LIGHT * (sol21.light_time - sol12.light_time)
    clk = 0.5 * C_LIGHT * (c1.offset(T) + c1.offset(T - sol12.light_time))
    np.testing.assert_allclose(diff.value, geo + clk, rtol=0, atol=1e-6)
    np.testing.assert_allclose(total.value, 0.5 * C_LIGHT * (sol21.light_time + sol12.light_time)
                               + 0.5 * C_LIGHT * (c1.offset(T) - c1.offset(T - sol12.light_time)), rtol=0, atol=1e-6)
    # clock partials are derivatives with respect to c*a_k
    for k, step in (("a0", 1e-7), ("a1", 1e-10), ("a2", 1e-14)):
        up = ClockModel(**{**c1.__dict__, k: getattr(c1, k) + step})
        dn = ClockModel(**{**c1.__dict__, k: getattr(c1, k) - step})
        fd = (_dowr(up, c2)[1].value - _dowr(dn, c2)[1].value) / (2 * step * C_LIGHT)
        np.testing.assert_allclose(diff.params[f"clock_sc1_{k}"], fd, rtol=1e-5)


def test_dual_one_way_sum_state_partials_vs_finite_differences():
    c1 = ClockModel(a0=1e-6, a1=1e-9)
    total, _ = _dowr(c1, ClockModel())
    for role, traj in (("sc1", L1), ("sc2", GEO)):
        fd = np.zeros((T.size, 6))
        h = np.array([10.0] * 3 + [0.1] * 3)
        for i in range(6):
            dx = np.zeros(6)
            dx[i] = h[i]
            v = [(_dowr(c1, ClockModel(), l1=traj.with_epoch_state(traj.x0 + s * dx)) if role == "sc1"
                  else _dowr(c1, ClockModel(), geo=traj.with_epoch_state(traj.x0 + s * dx)))[0].value for s in (1, -1)]
            fd[:, i] = (v[0] - v[1]) / (2 * h[i])
        np.testing.assert_allclose(epoch_state_partials(total, role, traj), fd, rtol=1e-6, atol=1e-9)
