"""The single-pass EKF of the Fujimoto comparison (odpipe.studies.ekf) on analytic cases: a constant
measured directly (the weighted mean), a nonlinear measurement (two hand-computed EKF steps), white
accelerations over a gap (eq. 11), and a linear problem with process noise, where one EKF pass must
equal the forward filter of the fit's first pass (a square-root information filter: another
implementation of the same Kalman filter)."""

import numpy as np
import pytest

from odpipe.estimation.fit import FitOptions, Observations, fit
from odpipe.estimation.registry import GaussMarkov, ParameterRegistry
from odpipe.studies.ekf import ekf, gap_noise


class Kinematic:
    """x = [position, velocity, acceleration held over each grid interval]; rows measure
    ``f(position)`` at their time."""

    def __init__(self, registry, times, f=lambda p: p, df=lambda p: 1.0):
        self.registry, self.times, self.f, self.df = registry, times, f, df

    def transition(self, t0, t1, x0):
        dt = t1 - t0
        Phi = np.eye(len(x0))
        Phi[0, 1], Phi[0, 2], Phi[1, 2] = dt, 0.5 * dt * dt, dt
        return Phi @ x0, Phi

    def predict(self, t0, x0, rows):
        computed, H = [], []
        for r in rows:
            x, Phi = self.transition(t0, self.times[r], x0)
            computed.append(self.f(x[0]))
            H.append(self.df(x[0]) * Phi[0])
        return np.array(computed), np.array(H)


def _registry(sig_p, sig_v, sig_a=None, batch=10.0):
    reg = ParameterRegistry()
    reg.add("p", "state", 0.0, sig_p, owner="a")
    reg.add("v", "state", 0.0, sig_v, owner="a")
    if sig_a is None:
        reg.add("acc", "bias", 0.0, 1e-12, owner="a")          # a constant, practically zero
    else:
        reg.add("acc", "stochastic", 0.0, sig_a, owner="a", process=GaussMarkov(0.0, sig_a, batch))
    return reg


def test_constant_measured_directly_gives_the_weighted_mean():
    reg = _registry(2.0, 1e-12)
    t = np.arange(1.0, 9.0)
    y = np.array([1.3, 0.7, 1.1, 0.9, 1.6, 0.4, 1.0, 1.2])
    obs = Observations(t, y, np.full(t.size, 0.5), np.zeros(t.size, int))
    res = ekf(Kinematic(reg, t), obs, 0.0, 10.0, 1.0)
    info = 1 / 2.0**2 + t.size / 0.5**2
    assert res.x[-1, 0] == pytest.approx((0.0 / 4.0 + y.sum() / 0.25) / info, rel=1e-9)
    assert res.P[-1, 0, 0] == pytest.approx(1 / info, rel=1e-9)


def test_nonlinear_rows_are_linearized_about_the_updated_estimate():
    """y = p^2, a priori p = 2 +- 1, two noiseless rows of p = 3 (sigma 0.1), by hand: each step
    H = 2 p at the current estimate, K = P H / (H P H + R), Joseph P; a linearized filter would keep H = 4."""
    reg = ParameterRegistry()
    reg.add("p", "state", 2.0, 1.0, owner="a")
    reg.add("v", "state", 0.0, 1e-12, owner="a")
    reg.add("acc", "bias", 0.0, 1e-12, owner="a")
    t = np.array([1.0, 2.0])
    obs = Observations(t, np.array([9.0, 9.0]), np.array([0.1, 0.1]), np.zeros(2, int))
    res = ekf(Kinematic(reg, t, f=lambda p: p * p, df=lambda p: 2 * p), obs, 0.0, 3.0, 1.0)
    p, P = 2.0, 1.0
    for k in range(2):
        H = 2 * p
        K = P * H / (H * P * H + 0.01)
        p, P = p + K * (9.0 - p * p), (1 - K * H) ** 2 * P + K * 0.01 * K
        assert res.x[k + 2, 0] == pytest.approx(p, rel=1e-12)
        assert res.P[k + 2, 0, 0] == pytest.approx(P, rel=1e-9)
    # 2 -> 3.249 -> 3.075; a filter linearized about p = 2 (H = 4 for both rows) stops at 2 + 4000/3201 = 3.250
    assert abs(res.x[-1, 0] - 3.0) < 0.1 < abs(2 + 4000 / 3201 - 3.0)


def test_gap_noise_is_a_constant_acceleration_over_the_gap():
    """Position a dt^2/2, velocity a dt for an acceleration a of variance q held over dt."""
    q, dt = 4e-14, 7000.0
    g = np.array([0.5 * dt * dt, dt])
    for i, j in ((0, 0), (0, 3), (3, 3)):
        assert gap_noise(q, dt)[i, j] == pytest.approx(q * g[i // 3] * g[j // 3], rel=1e-14)
    assert gap_noise(q, dt)[0, 1] == 0.0                     # axes independent (Q = q I)


def test_one_pass_with_process_noise_equals_the_fits_forward_filter():
    reg = _registry(5.0, 0.5, sig_a=0.02, batch=10.0)
    rng = np.random.default_rng(4)
    t = np.sort(rng.uniform(0.5, 99.5, 40))
    truth = 1.0 + 0.3 * t - 0.001 * t * t
    obs = Observations(t, truth + rng.normal(size=t.size) * 0.2, np.full(t.size, 0.2), np.zeros(t.size, int))
    prob = Kinematic(reg, t)
    res = ekf(prob, obs, 0.0, 100.0, 10.0)
    sol = fit(prob, obs, 0.0, 100.0, FitOptions(max_iter=1, block=10.0))
    assert np.array_equal(res.grid, sol.grid)
    assert np.allclose(res.x, sol.filtered_x, rtol=0, atol=1e-9)
    assert np.allclose(res.P, sol.filtered_P, rtol=1e-8, atol=1e-14)
    # the process noise keeps the velocity sigma near the 10-s steps' 0.2 m/s, well above a constant's
    assert np.sqrt(res.P[-1, 1, 1]) > 0.05


def test_consider_parameters_are_refused():
    reg = _registry(1.0, 1.0)
    reg.add("c", "bias", 0.0, 1.0, owner="a", consider=True)
    t = np.array([1.0])
    with pytest.raises(ValueError, match="consider"):
        ekf(Kinematic(reg, t), Observations(t, np.ones(1), np.ones(1), np.zeros(1, int)), 0.0, 2.0, 1.0)
