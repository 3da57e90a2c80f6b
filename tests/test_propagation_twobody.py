"""Two-body propagation, dense output, backward arcs and maneuvers vs Kepler's closed form."""

import numpy as np
import pytest

from odpipe.dynamics.forces import FiniteBurn, ForceModel, ImpulsiveManeuver
from odpipe.dynamics.propagator import propagate, propagate_many

GM = 3.986004415e14


def kepler(x0, dt, gm=GM):
    """Closed-form two-body state after dt (elliptic), via Kepler's equation (Newton)."""
    r0, v0 = np.asarray(x0[:3], float), np.asarray(x0[3:], float)
    r, v2 = np.linalg.norm(r0), v0 @ v0
    a = 1.0 / (2.0 / r - v2 / gm)
    h = np.cross(r0, v0)
    e_vec = np.cross(v0, h) / gm - r0 / r
    e = np.linalg.norm(e_vec)
    p_hat = e_vec / e
    q_hat = np.cross(h / np.linalg.norm(h), p_hat)
    nu0 = np.arctan2(r0 @ q_hat, r0 @ p_hat)
    E0 = 2 * np.arctan(np.sqrt((1 - e) / (1 + e)) * np.tan(nu0 / 2))
    n = np.sqrt(gm / a**3)
    M = E0 - e * np.sin(E0) + n * dt
    E = M
    for _ in range(50):
        E -= (E - e * np.sin(E) - M) / (1 - e * np.cos(E))
    b = a * np.sqrt(1 - e * e)
    pos = a * (np.cos(E) - e) * p_hat + b * np.sin(E) * q_hat
    Edot = n / (1 - e * np.cos(E))
    vel = -a * np.sin(E) * Edot * p_hat + b * np.cos(E) * Edot * q_hat
    return np.concatenate([pos, vel])


X0 = np.array([7.0e6, -1.0e6, 0.5e6, 1.0e3, 8.2e3, 1.5e3])  # e ~ 0.2, period ~ 2.4 h


def test_hundred_orbits_vs_kepler():
    fm = ForceModel("earth", central_gm=GM)
    t1 = 100 * 8600.0
    traj = propagate(X0, 0.0, t1, fm, with_stm=False, rtol=1e-13, atol=1e-12)
    err = np.linalg.norm(traj.state(t1)[0][:3] - kepler(X0, t1)[:3])
    # ~100 orbits: measured 4.7 mm (5.6 cm at rtol 1e-12, as scipy's DOP853 gives)
    assert err < 1e-2, err
    # dense output anywhere in the arc (not only at step ends)
    tq = np.linspace(0.0, t1, 777)
    ref = np.array([kepler(X0, t) for t in tq])
    dense_err = np.abs(traj.state(tq)[:, :3] - ref[:, :3]).max()
    assert dense_err < 1e-2, dense_err


def test_backward_arc_and_stm_inverse():
    fm = ForceModel("earth", central_gm=GM)
    fwd = propagate(X0, 0.0, 20000.0, fm, rtol=1e-13)
    back = propagate(fwd.state(20000.0)[0], 20000.0, 0.0, fm, rtol=1e-13)
    np.testing.assert_allclose(back.state(0.0)[0], X0, rtol=0, atol=2e-3)
    np.testing.assert_allclose(back.state(7000.0)[0], kepler(X0, 7000.0), rtol=0, atol=2e-3)
    # Phi(0, T) Phi(T, 0) = I
    prod = back.stm(0.0)[0] @ fwd.stm(20000.0)[0]
    np.testing.assert_allclose(prod, np.eye(6), rtol=0, atol=1e-6)  # |Phi| entries up to 1e4
    with pytest.raises(ValueError):
        fwd.state(20001.0)


def test_stm_of_two_body_vs_finite_differences():
    fm = ForceModel("earth", central_gm=GM)
    T = 30000.0
    phi = propagate(X0, 0.0, T, fm).stm(T)[0]
    steps = np.array([1.0, 1.0, 1.0, 1e-3, 1e-3, 1e-3])
    fd = np.column_stack([(kepler(X0 + h * e, T) - kepler(X0 - h * e, T)) / (2 * h)
                          for h, e in zip(steps, np.eye(6))])
    np.testing.assert_allclose(phi, fd, rtol=1e-6, atol=1e-6 * np.abs(fd).max())


def test_impulsive_maneuver_and_its_partials():
    tm, T = 5000.0, 16000.0
    dv = np.array([10.0, -5.0, 3.0])
    fm = ForceModel("earth", [ImpulsiveManeuver(tm, dv)], central_gm=GM)
    traj = propagate(X0, 0.0, T, fm, rtol=1e-13)
    assert traj.param_names == ["dv[0].x", "dv[0].y", "dv[0].z", "dv[0].t"]
    post = kepler(X0, tm) + np.r_[0, 0, 0, dv]
    np.testing.assert_allclose(traj.state(tm)[0], post, rtol=0, atol=1e-4)  # post-maneuver at tm
    np.testing.assert_allclose(traj.state(T)[0], kepler(post, T - tm), rtol=0, atol=1e-4)
    sens = traj.sensitivity(T)[0]

    def final(dv_, tm_):
        return kepler(kepler(X0, tm_) + np.r_[0, 0, 0, dv_], T - tm_)

    for k in range(3):
        e = np.eye(3)[k] * 1e-3
        fd = (final(dv + e, tm) - final(dv - e, tm)) / 2e-3
        np.testing.assert_allclose(sens[:, k], fd, rtol=1e-6, atol=1e-6)
    fd_t = (final(dv, tm + 0.01) - final(dv, tm - 0.01)) / 0.02
    np.testing.assert_allclose(sens[:, 3], fd_t, rtol=1e-5, atol=1e-6)
    assert np.all(traj.sensitivity(tm - 1.0) == 0.0)


def test_finite_burn_matches_rocket_equation():
    """Constant inertial thrust with no gravity: Tsiolkovsky velocity and its integral."""
    F, mdot, m0, T = 400.0, 0.13, 900.0, 600.0
    u = np.array([0.6, 0.0, 0.8])
    fm = ForceModel("earth", [FiniteBurn(100.0, 100.0 + T, F, u, mdot)], mass=m0, central_gm=0.0)
    x0 = np.array([1e7, 0, 0, 0, 0, 0])
    traj = propagate(x0, 0.0, 1000.0, fm, with_stm=False)
    ve = F / mdot
    dv = ve * np.log(m0 / (m0 - mdot * T))
    np.testing.assert_allclose(traj.state(1000.0)[0][3:], dv * u, rtol=1e-11)
    # distance during the burn: x(T) = ve [T - (m0/mdot - T) ln(m0/(m0 - mdot T))]... closed form
    m1 = m0 - mdot * T
    burn_dist = ve * (T - m1 / mdot * np.log(m0 / m1))
    coast = dv * 300.0
    np.testing.assert_allclose(traj.state(1000.0)[0][:3] - x0[:3], (burn_dist + coast) * u, rtol=1e-10)


def test_several_spacecraft():
    fm = ForceModel("earth", central_gm=GM)
    x1 = X0 * np.r_[1, 1, 1, 1.01, 1, 1]
    tset = propagate_many({"a": X0, "b": x1}, 0.0, 3000.0, fm, with_stm=False)
    states = tset.states(3000.0)
    np.testing.assert_allclose(states["a"][0], kepler(X0, 3000.0), atol=1e-6)
    np.testing.assert_allclose(states["b"][0], kepler(x1, 3000.0), atol=1e-6)


def test_transverse_empirical_acceleration_raises_semi_major_axis():
    """Gauss's equation on a circular orbit: da/dt = 2 a^1.5 aT / sqrt(GM); radial and normal leave a."""
    from odpipe.dynamics.forces import EmpiricalRTN

    a0 = 7.0e6
    x0 = np.array([a0, 0.0, 0.0, 0.0, np.sqrt(GM / a0), 0.0])
    T, aT = 6 * 5828.5, 1e-6
    fm = ForceModel("earth", [EmpiricalRTN(np.array([[0.0, T, 0.0, aT, 0.0]]))], central_gm=GM)
    s = propagate(x0, 0.0, T, fm, with_stm=False).state(T)[0]
    a1 = 1.0 / (2.0 / np.linalg.norm(s[:3]) - s[3:] @ s[3:] / GM)
    expected = 2 * a0**1.5 * aT / np.sqrt(GM) * T  # first order in aT
    assert a1 - a0 == pytest.approx(expected, rel=1e-3)
    assert abs(s[2]) < 1e-6  # no out-of-plane motion from a transverse thrust


def test_backward_arc_through_a_maneuver():
    """Backward from the post-maneuver arc end: the impulse is removed, partials keep their meaning."""
    tm, T = 5000.0, 16000.0
    dv = np.array([10.0, -5.0, 3.0])
    fm = ForceModel("earth", [ImpulsiveManeuver(tm, dv)], central_gm=GM)
    xT = kepler(kepler(X0, tm) + np.r_[0, 0, 0, dv], T - tm)
    back = propagate(xT, T, 0.0, fm, rtol=1e-13)
    np.testing.assert_allclose(back.state(0.0)[0], X0, rtol=0, atol=1e-4)
    np.testing.assert_allclose(back.state(tm)[0], kepler(X0, tm) + np.r_[0, 0, 0, dv], rtol=0, atol=1e-4)

    def initial(dv_, tm_):
        return kepler(kepler(xT, tm_ - T) - np.r_[0, 0, 0, dv_], -tm_)

    sens = back.sensitivity(0.0)[0]
    e = np.eye(3)[1] * 1e-3
    np.testing.assert_allclose(sens[:, 1], (initial(dv + e, tm) - initial(dv - e, tm)) / 2e-3, rtol=1e-6, atol=1e-6)
    fd_t = (initial(dv, tm + 0.01) - initial(dv, tm - 0.01)) / 0.02
    np.testing.assert_allclose(sens[:, 3], fd_t, rtol=1e-5, atol=1e-6)


def test_fixed_steps_are_eighth_order():
    """rtol = inf: steps of exactly max_step; the error after one orbit falls as h^8 (Kepler)."""
    fm = ForceModel("earth", central_gm=GM)
    t1 = 8640.0
    errs = []
    for h in (480.0, 240.0):
        traj = propagate(X0, 0.0, t1, fm, with_stm=False, rtol=np.inf, max_step=h)
        assert traj.n_steps == t1 / h
        errs.append(np.linalg.norm(traj.state(t1)[0][:3] - kepler(X0, t1)[:3]))
    print("fixed-step errors (m)", errs, "ratio", errs[0] / errs[1])
    assert errs[1] > 1e-6                                          # still truncation error, not round-off
    assert 2**6 < errs[0] / errs[1] < 2**10                        # 8th order: 2^8 per halving


def test_rk4_is_fourth_order_and_its_dense_output_is_hermite():
    fm = ForceModel("earth", central_gm=GM)
    t1 = 8640.0
    errs = []
    for h in (120.0, 60.0):
        traj = propagate(X0, 0.0, t1, fm, with_stm=True, method="rk4", max_step=h)
        assert traj.n_steps == t1 / h
        errs.append(np.linalg.norm(traj.state(t1)[0][:3] - kepler(X0, t1)[:3]))
    print("RK4 errors (m)", errs, "ratio", errs[0] / errs[1])
    assert 2**3 < errs[0] / errs[1] < 2**5                         # 4th order: 2^4 per halving
    mid = traj.state(t1 - 30.0)[0]                                 # between two step ends
    assert np.linalg.norm(mid[:3] - kepler(X0, t1 - 30.0)[:3]) < 2 * errs[1] + 1e-3
    with pytest.raises(ValueError, match="rk4"):
        propagate(X0, 0.0, t1, fm, method="rk4")                  # needs a step


def test_first_step_replaces_the_starting_estimate():
    """A given first step is the first step taken (accepted: two 60-s steps of 15 evaluations and the
    initial one cover 120 s), the arc stays within the tolerance of Kepler's closed form, and DOP853's own
    start (0.01 of the state's scale over its rate, under a second here) needs more steps."""
    fm = ForceModel("earth", central_gm=GM)
    default = propagate(X0, 0.0, -120.0, fm, with_stm=False, rtol=1e-11, atol=1e-5)
    hinted = propagate(X0, 0.0, -120.0, fm, with_stm=False, rtol=1e-11, atol=1e-5, first_step=60.0)
    assert (hinted.n_steps, hinted.n_eval, hinted.median_step) == (2, 31, 60.0)
    assert default.n_steps > 2 and default.n_eval > 31
    for traj in (default, hinted):
        assert np.abs(traj.state(-120.0)[0][:3] - kepler(X0, -120.0)[:3]).max() < 1e-4
