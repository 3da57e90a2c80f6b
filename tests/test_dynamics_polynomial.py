"""Inertial polynomial acceleration: the analytic motion without gravity (state, STM and
sensitivities), d a/d p vs central differences, parameter names and the activity window."""

import numpy as np

from odpipe.dynamics import (EmpiricalRTN, ForceModel, InertialPolynomialAcceleration, propagate)
from odpipe.dynamics.forces import compile_model
from odpipe.dynamics.rhs import acceleration

GM = 3.986004418e14
X0 = np.array([7.0e6, -1.0e6, 0.5e6, 1.0e3, 7.2e3, -0.4e3])


def _accel(model, t, x):
    model.segment[0] = t
    dadp = np.zeros((model.n_params, 3))
    acc = np.zeros(3)
    acceleration(t, x[:3].copy(), x[3:].copy(), model, acc, np.zeros((3, 3)), np.zeros((3, 3)), dadp)
    return acc, dadp


def test_free_motion_state_stm_and_sensitivities_are_the_polynomial_integrals():
    t0, span, s = 1000.0, 5000.0, 300.0  # t_ref = t0 - s
    c0, c1 = np.array([2e-6, -1e-6, 5e-7]), np.array([3e-10, 1e-10, -2e-10])
    fm = ForceModel("earth", [InertialPolynomialAcceleration(t0 - s, c0, c1)], central_gm=0.0)
    traj = propagate(X0, t0, t0 + span, fm)
    assert traj.param_names == [f"poly[0].{c}" for c in ("x0", "y0", "z0", "x1", "y1", "z1")]
    tau = np.linspace(0.0, span, 7)
    t = t0 + tau
    a0 = c0 + c1 * s
    r = X0[:3] + np.outer(tau, X0[3:]) + np.outer(tau**2 / 2, a0) + np.outer(tau**3 / 6, c1)
    v = X0[3:] + np.outer(tau, a0) + np.outer(tau**2 / 2, c1)
    np.testing.assert_allclose(traj.state(t), np.hstack([r, v]), rtol=1e-13, atol=1e-9)
    stm = np.tile(np.eye(6), (len(t), 1, 1))
    stm[:, :3, 3:] = tau[:, None, None] * np.eye(3)
    np.testing.assert_allclose(traj.stm(t), stm, rtol=0, atol=1e-11 * span)
    sens = traj.sensitivity(t)
    for i in range(3):
        np.testing.assert_allclose(sens[:, i, i], tau**2 / 2, rtol=1e-12, atol=1e-12)              # dr/dc0
        np.testing.assert_allclose(sens[:, 3 + i, i], tau, rtol=1e-12, atol=1e-12)                 # dv/dc0
        np.testing.assert_allclose(sens[:, i, 3 + i], s * tau**2 / 2 + tau**3 / 6, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(sens[:, 3 + i, 3 + i], s * tau + tau**2 / 2, rtol=1e-12, atol=1e-12)
    off = sens.copy()
    for i in range(3):
        off[:, [i, 3 + i], i] = 0.0
        off[:, [i, 3 + i], 3 + i] = 0.0
    assert np.abs(off).max() < 1e-9  # no coupling between axes without gravity


def test_partials_vs_central_differences_beside_other_parameters():
    t_ref = 50.0
    polys = [InertialPolynomialAcceleration(t_ref, [1e-6, 2e-6, -1e-6], [1e-9, -2e-9, 3e-9]),
             InertialPolynomialAcceleration(0.0, [0.0, 0.0, 1e-7], [0.0, 0.0, 0.0], t_start=-100.0, t_end=1e4)]
    fm = ForceModel("earth", [EmpiricalRTN(np.array([[-1e4, 1e4, 1e-8, 0.0, 0.0]])), *polys], central_gm=GM)
    names = fm.parameter_names()
    assert names == ["emp[0].R", "emp[0].T", "emp[0].N"] + [f"poly[{k}].{c}" for k in range(2)
                                                            for c in ("x0", "y0", "z0", "x1", "y1", "z1")]
    t = 1234.5
    acc, dadp = _accel(compile_model(fm, 0.0, 3600.0, names, True), t, X0)
    for p, name in enumerate(names[3:], start=3):
        k, comp = int(name[5]), name[-2:]
        field = "c0" if comp[1] == "0" else "c1"
        axis = "xyz".index(comp[0])
        h = 1e-7

        def moved(delta, k=k, field=field, axis=axis):
            c = np.array(getattr(polys[k], field), float)
            c[axis] += delta
            setattr(polys[k], field, c)
            return _accel(compile_model(fm, 0.0, 3600.0, [], False), t, X0)[0]

        up, down = moved(h), moved(-2 * h)
        moved(h)
        expect = np.zeros(3)
        expect[axis] = 1.0 if field == "c0" else t - polys[k].t_ref
        np.testing.assert_allclose((up - down) / (2 * h), expect, rtol=1e-6, atol=1e-9 * abs(expect).max(),
                                   err_msg=name)
        np.testing.assert_array_equal(dadp[p], expect, err_msg=name)


def test_active_only_inside_its_window_and_segments_restart_at_its_ends():
    pa = InertialPolynomialAcceleration(0.0, [1e-5, 0.0, 0.0], t_start=100.0, t_end=200.0)
    fm = ForceModel("earth", [pa], central_gm=0.0)
    assert fm.breakpoints() == [100.0, 200.0]
    model = compile_model(fm, 0.0, 300.0, [], False)
    for t, expect in ((50.0, 0.0), (150.0, 1e-5), (250.0, 0.0)):
        assert _accel(model, t, X0)[0][0] == expect
    traj = propagate(X0, 0.0, 300.0, fm, with_stm=False)
    # the velocity gains 100 s x 1e-5 m/s^2 along x (to the rounding of |v| = 7.3 km/s)
    np.testing.assert_allclose(traj.state(300.0)[0][3:] - X0[3:], [1e-3, 0.0, 0.0], rtol=0, atol=1e-11)
