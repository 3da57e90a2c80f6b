"""TrackingProblem's transition and partials against finite differences of fresh integrations.

The problem composes Phi and H from one integration per segment (Phi(t1) Phi(t0)^-1,
S(t1) - Phi(t1) Phi(t0)^-1 S(t0)); here they are compared, in the middle of a
segment that starts at a maneuver, with central differences of
:func:`odpipe.dynamics.propagator.propagate` started at t0 and of a new problem
whose arc starts at t0.
"""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.dynamics.propagator import propagate
from odpipe.od import ArcSetup, ManeuverPlan, TrackingProblem
from odpipe.od.arc import a_priori_reference, build_registry, select_rows
from test_od_simulate import force_model, measurement_setup, scenario

STEPS = np.array([100.0, 100.0, 100.0, 0.01, 0.01, 0.01])    # m, m/s: well above the integration noise


@pytest.fixture(scope="module")
def case():
    sc = scenario()
    setup = ArcSetup("SC", sc["t0"], sc["t1"], sc["x0"], force_model(), measurement_setup(),
                     maneuvers=(ManeuverPlan("tcm1", sc["t_man"]),), data_sigma={"range": 1.0, "doppler_2way": 1e-4})
    rows, times = select_rows(sc["table"], setup)
    reg = build_registry(setup, rows)
    x = reg.apriori.copy()
    x[reg.index("SC.srp_scale")] = 1.05
    x[reg.indices("maneuver")] = [0.03, -0.02, 0.03]
    prob = TrackingProblem(reg, rows, times, {"SC": force_model()}, setup.measurements, sc["t0"], sc["t1"])
    x_man, _ = prob.transition(sc["t0"], sc["t_man"], x)
    ta = sc["t_man"] + 3600.0
    while np.count_nonzero((times >= ta) & (times < ta + 3600.0)) < 10:
        ta += 3600.0
    x_a, _ = prob.transition(sc["t_man"], ta, x_man)
    return dict(sc=sc, reg=reg, prob=prob, rows=rows, times=times, x_man=x_man, ta=ta, x_a=x_a, setup=setup)


def _flow(x_state, t0, t1, scale):
    return propagate(x_state, t0, t1, force_model(scale), with_stm=False).state(t1)[0]


def _normalized_error(an, fd):
    return np.max(np.abs(an - fd)) / np.max(np.abs(fd))


def test_transition_mid_segment_matches_reintegration(case):
    reg, prob, ta, x_a = case["reg"], case["prob"], case["ta"], case["x_a"]
    st, i_srp, i_dv = slice(0, 6), reg.index("SC.srp_scale"), reg.indices("maneuver")
    t1 = ta + 3600.0
    x1, Phi = prob.transition(ta, t1, x_a)
    # same state as a fresh integration, to the integrator tolerance (rtol 1e-12 of 2.6e8 m)
    np.testing.assert_allclose(x1[:6], _flow(x_a[:6], ta, t1, 1.05), rtol=0, atol=1e-3)
    for j in range(6):
        d = np.zeros(6)
        d[j] = STEPS[j]
        fd = (_flow(x_a[:6] + d, ta, t1, 1.05) - _flow(x_a[:6] - d, ta, t1, 1.05)) / (2 * STEPS[j])
        assert _normalized_error(Phi[st, j], fd) < 1e-6, j
    fd = (_flow(x_a[:6], ta, t1, 1.55) - _flow(x_a[:6], ta, t1, 0.55)) / 1.0   # big step: SRP is linear in it
    # the SRP column is 0.3 m per unit scale; the two integrations differ by ~1e-5 m (measured 9e-6 m)
    assert _normalized_error(Phi[st, i_srp], fd) < 1e-4
    # the burn is behind: x(ta) already holds it (zero up to rounding of S(t1) - M S(ta))
    assert np.max(np.abs(Phi[st][:, i_dv])) < 1e-9 * np.max(np.abs(Phi[st, 3:6]))
    assert prob.n_propagations == 2             # one integration per segment served every call


def test_transition_from_the_burn_epoch_carries_the_dv_partials(case):
    sc, reg, prob, x_man = case["sc"], case["reg"], case["prob"], case["x_man"]
    t_man, i_dv = sc["t_man"], reg.indices("maneuver")
    t1 = t_man + 7200.0
    _, Phi = prob.transition(t_man, t1, x_man)
    for k, j in enumerate(i_dv):
        d = np.zeros(6)
        d[3 + k] = 1e-3
        x_plus = x_man[:6].copy()
        x_plus[3:] += x_man[i_dv]
        fd = (_flow(x_plus + d, t_man, t1, 1.05) - _flow(x_plus - d, t_man, t1, 1.05)) / 2e-3
        assert _normalized_error(Phi[:6, j], fd) < 1e-6


def test_predict_partials_mid_segment_match_a_problem_started_there(case):
    reg, prob, ta, x_a = case["reg"], case["prob"], case["ta"], case["x_a"]
    times = case["times"]
    sel = np.flatnonzero((times >= ta) & (times < ta + 3600.0))
    computed, H = prob.predict(ta, x_a, sel)
    sub = case["rows"].iloc[sel]

    def values(x):
        fresh = TrackingProblem(reg, sub, times[sel], {"SC": force_model()}, case["setup"].measurements,
                                ta, ta + 3600.0)
        return fresh.predict(ta, x, np.arange(sel.size))[0]

    # the same values from a second integration: equal to within integration noise (1 % of the data sigma)
    assert np.max(np.abs(values(x_a) - computed) / sub["sigma"].to_numpy()) < 0.01
    cols = list(range(6)) + [reg.index("SC.srp_scale")]
    steps = list(STEPS) + [0.5]
    tols = [1e-5] * 6 + [5e-4]     # SRP: the Doppler partials (1e-5 Hz) sit at the integration-noise floor of the FD
    #                                (measured 2.2e-4 here; below 2e-4 from the cannonball truth's epoch state)
    for j, h, tol in zip(cols, steps, tols):
        xp, xm = x_a.copy(), x_a.copy()
        xp[j] += h
        xm[j] -= h
        fd = (values(xp) - values(xm)) / (2 * h)
        assert _normalized_error(H[:, j], fd) < tol, reg.names[j]
    assert np.max(np.abs(H[:, reg.indices("maneuver")])) < 1e-9 * np.max(np.abs(H[:, 3:6]))


def test_integrator_settings_per_spacecraft(case):
    """integrator={'SC': ...}: the reference flies with those steps (here RK4 every 60 s, the
    same states as fixed-step integration outside the problem), the others adaptively."""
    sc, reg, rows, times = case["sc"], case["reg"], case["rows"], case["times"]
    x = reg.apriori.copy()
    t1 = sc["t0"] + 7200.0
    rk4 = {"method": "rk4", "max_step": 60.0}
    prob = TrackingProblem(reg, rows, times, {"SC": force_model()}, case["setup"].measurements, sc["t0"],
                           sc["t1"], integrator={"SC": rk4})
    x1, _ = prob.transition(sc["t0"], t1, x)
    direct = propagate(x[:6], sc["t0"], t1, force_model(), with_stm=False, **rk4).state(t1)[0]
    np.testing.assert_allclose(x1[:6], direct, rtol=0, atol=1e-6)
    adaptive = propagate(x[:6], sc["t0"], t1, force_model(), with_stm=False).state(t1)[0]
    print("RK4 - adaptive (m)", x1[:3] - adaptive[:3])
    assert np.max(np.abs(x1[:3] - adaptive[:3])) > 1e-6       # another integrator, above round-off


def test_linearized_states_match_a_fresh_integration_to_second_order(case):
    """Products of a converged fit read the last reference corrected to first order (``linearized``):
    against the segment integrated from the corrected start (state, SRP scale and dV), what the
    first-order model leaves is below 1e-4 of the correction's own effect (it is second order)."""
    sc, reg, prob, x_man = case["sc"], case["reg"], case["prob"], case["x_man"]
    t_man = sc["t_man"]
    prob.segment(t_man, x_man)
    x = x_man.copy()
    x[:6] += [30.0, -20.0, 10.0, 3e-3, -2e-3, 1e-3]
    x[reg.index("SC.srp_scale")] += 0.02
    x[reg.indices("maneuver")] += [1e-4, -1e-4, 2e-4]
    b, near = prob.linearized(t_man, x)
    end, trajs, _ = prob.trajectories(t_man, x)
    assert b == end
    t = np.linspace(t_man - 100.0, b, 50)
    exact, first = trajs["SC"].state(t), near["SC"](t)
    effect = np.max(np.abs(exact[:, :3] - prob.linearized(t_man, x_man)[1]["SC"](t)[:, :3]))
    print(f"first-order model: {np.max(np.abs(first[:, :3] - exact[:, :3])):.2e} m of a {effect:.1f} m change")
    assert effect > 10.0
    assert np.max(np.abs(first[:, :3] - exact[:, :3])) < 1e-4 * effect
    assert prob.linearized(t_man + 1.0, x) is None          # no held segment starts there


def test_a_priori_reference_is_the_fits_first_reference(case):
    """The geometry step's a priori reference (``a_priori_reference``) flies the arc as one integration
    does (to 1 mm over two days, restarting at the maneuver), and a problem sharing its segments
    evaluates the a priori reference without integrating again."""
    sc, reg, setup, rows, times = case["sc"], case["reg"], case["setup"], case["rows"], case["times"]
    shared = {}
    chain = a_priori_reference(setup, shared)
    t = np.linspace(sc["t0"], sc["t1"], 200)
    direct = propagate(setup.state0, sc["t0"], sc["t1"], force_model(), with_stm=False).state(t)
    assert np.max(np.abs(chain.state(t)[:, :3] - direct[:, :3])) < 1e-3
    prob = TrackingProblem(reg, rows, times, {"SC": setup.force_model}, setup.measurements, sc["t0"], sc["t1"],
                           shared=shared)
    prob.reference(reg.apriori)
    assert prob.n_propagations == 0 and len(shared) == 2
    moved = reg.apriori.copy()
    moved[0] += 1.0
    prob.reference(moved)
    assert prob.n_propagations == 2                     # another reference: integrated


def test_coarse_references_near_an_integrated_one_are_shifted_not_integrated(case):
    """While set_coarse is on, a segment starting near one integrated with the same coarse settings is
    shifted from it to first order (no integration): against the segment integrated from the moved start
    (state, SRP scale and dV), the shift leaves below 1e-4 of the move's own effect. A start further than
    LINEAR_REUSE (relative) away, or the exact settings, integrates again."""
    from odpipe.od.problem import LINEAR_REUSE

    sc, reg, rows, times, x_man = case["sc"], case["reg"], case["rows"], case["times"], case["x_man"]
    t_man = sc["t_man"]
    coarse = {"rtol": 1e-10, "atol": 1e-5}
    prob = TrackingProblem(reg, rows, times, {"SC": force_model()}, case["setup"].measurements, sc["t0"], sc["t1"],
                           coarse=coarse)
    prob.set_coarse(True)
    _, base, _ = prob.trajectories(t_man, x_man)
    assert prob.n_propagations == 1
    x = x_man.copy()
    x[:6] += [30.0, -20.0, 10.0, 3e-3, -2e-3, 1e-3]
    x[reg.index("SC.srp_scale")] += 0.02
    x[reg.indices("maneuver")] += [1e-4, -1e-4, 2e-4]
    b, shifted, _ = prob.trajectories(t_man, x)
    assert prob.n_propagations == 1 and shifted["SC"].n_eval == 0
    exact = TrackingProblem(reg, rows, times, {"SC": force_model()}, case["setup"].measurements, sc["t0"],
                            sc["t1"], **coarse).trajectories(t_man, x)[1]["SC"]
    t = np.linspace(t_man - 100.0, b, 50)
    effect = np.max(np.abs(exact.state(t)[:, :3] - base["SC"].state(t)[:, :3]))
    error = np.max(np.abs(shifted["SC"].state(t)[:, :3] - exact.state(t)[:, :3]))
    print(f"shifted reference: {error:.2e} m of a {effect:.1f} m change")
    assert effect > 10.0 and error < 1e-4 * effect
    np.testing.assert_array_equal(shifted["SC"].stm(t), base["SC"].stm(t))
    far = x_man.copy()
    far[3:6] *= 1.0 + 2.0 * LINEAR_REUSE
    prob.trajectories(t_man, far)
    assert prob.n_propagations == 2
    prob.set_coarse(False)
    prob.trajectories(t_man, x)
    assert prob.n_propagations == 3


def test_span_answers_every_interval_as_predict_and_transition_do(case):
    """``span`` (a segment's intervals at once, the fit's sweep) gives the references, transitions and rows of
    the interval at ``ta`` that ``transition`` and ``predict`` (checked against finite differences above) give,
    and stops at the segment's end."""
    sc, reg, prob, ta, x_a, x_man = case["sc"], case["reg"], case["prob"], case["ta"], case["x_a"], case["x_man"]
    times = case["times"]
    epochs = np.concatenate([np.arange(sc["t_man"], ta, 1800.0), [ta, ta + 3600.0, sc["t1"] + 3600.0]])
    epochs = np.unique(epochs)
    bounds = np.searchsorted(times, epochs, "left")
    refs, Phi, computed, H = prob.span(epochs, x_man, bounds)
    assert Phi.shape[0] == epochs.size - 2            # the last epoch lies past the segment's end (the arc end)
    k = int(np.searchsorted(epochs, ta))
    np.testing.assert_array_equal(refs[k], x_a)
    x1, Phi_ta = prob.transition(ta, ta + 3600.0, x_a)
    np.testing.assert_array_equal(refs[k + 1], x1)
    assert _normalized_error(Phi[k], Phi_ta) < 1e-14
    sel = np.arange(bounds[k], bounds[k + 1])
    c_ta, H_ta = prob.predict(ta, x_a, sel)
    r = slice(bounds[k] - bounds[0], bounds[k + 1] - bounds[0])
    assert _normalized_error(computed[r], c_ta) < 1e-14
    assert _normalized_error(H[r], H_ta) < 1e-12


def test_span_over_a_segment_without_rows_gives_its_transitions(case):
    """A segment holding no rows (an arc whose first data come after a burn, or whose a priori reference starts
    before the first count): ``span`` flies it and answers with no rows, its transitions those of ``transition``."""
    sc, reg, setup = case["sc"], case["reg"], case["setup"]
    later = case["times"] >= sc["t_man"]
    rows, times = case["rows"][later], case["times"][later]
    prob = TrackingProblem(reg, rows, times, {"SC": force_model()}, setup.measurements, sc["t0"], sc["t1"])
    epochs = np.arange(sc["t0"], sc["t_man"] + 1.0, 3600.0)
    refs, Phi, computed, H = prob.span(epochs, reg.apriori, np.zeros(epochs.size, int))
    assert computed.shape == (0,) and H.shape == (0, len(reg))
    x1, Phi_1 = prob.transition(epochs[0], epochs[1], reg.apriori)
    np.testing.assert_array_equal(refs[1], x1)
    assert _normalized_error(Phi[0], Phi_1) < 1e-14


def test_remembered_stm_and_sensitivities_follow_the_epochs_asked(case):
    """A segment remembers the STM and sensitivities of the last epochs asked (a group's partials ask for both
    at the same events): alternating between two sets of epochs gives each set its own values, those of a
    fresh interpolation, and the remembered arrays cannot be changed by a caller."""
    sc, prob, x_man = case["sc"], case["prob"], case["x_man"]
    traj = prob.segment(sc["t_man"], x_man).trajs["SC"]
    a = np.linspace(sc["t_man"] - 50.0, sc["t_man"] + 7200.0, 7)
    b = a[::-1] + 0.5
    for t in (a, b, a, b):
        _, Phi, S = traj._full(t)
        assert np.array_equal(traj.stm(t), Phi) and np.array_equal(traj.sensitivity(t), S)
    with pytest.raises(ValueError):
        traj.stm(b)[0, 0, 0] = 1.0
