"""CRLB recursion (thesis eqs. 3.30-3.32) against the Kalman filter and the literal equations."""

import numpy as np
import pytest
from scipy.stats import chi2

from odpipe.analysis.crlb import crlb_history, fisher_step, snc_gamma, snc_process_noise
from odpipe.analysis.montecarlo import monte_carlo, rms_over_runs

DT = 60.0
SIG_ACC = 1e-4
SIG_Z = 5.0


def _cv_phi(dt):
    """Constant-velocity transition in 3-D, state [r, v]."""
    return np.block([[np.eye(3), dt * np.eye(3)], [np.zeros((3, 3)), np.eye(3)]])


def _rows(k):
    """Position component k % 3 measured at epoch k."""
    H = np.zeros((1, 6))
    H[0, k % 3] = 1.0
    return H


def test_snc_noise_is_the_constant_acceleration_integral():
    Q = snc_process_noise(DT, [SIG_ACC, 2 * SIG_ACC])
    s2 = SIG_ACC**2
    assert Q.shape == (12, 12)
    assert Q[0, 0] == pytest.approx(DT**4 / 4 * s2)
    assert Q[0, 3] == pytest.approx(DT**3 / 2 * s2)
    assert Q[3, 3] == pytest.approx(DT**2 * s2)
    assert Q[6, 6] == pytest.approx(4 * DT**4 / 4 * s2)
    assert np.all(Q[:6, 6:] == 0)
    assert np.allclose(snc_gamma(DT)[3:], DT * np.eye(3))


def test_crlb_equals_kalman_covariance_linear_gaussian():
    """For a linear-Gaussian system the CRLB is the Kalman filter covariance."""
    K = 200
    P0 = np.diag([1e3] * 3 + [1.0] * 3) ** 2
    Phi, Q = _cv_phi(DT), snc_process_noise(DT, SIG_ACC)
    Hs = [_rows(k) for k in range(K)]
    P_crlb = crlb_history(P0, [Phi] * K, Hs, [np.array([SIG_Z**-2])] * K, [Q] * K)
    P = P0.copy()
    for k in range(K):
        P = Phi @ P @ Phi.T + Q
        H = Hs[k]
        S = H @ P @ H.T + SIG_Z**2
        G = P @ H.T / S
        I_GH = np.eye(6) - G @ H
        P = I_GH @ P @ I_GH.T + SIG_Z**2 * G @ G.T        # Joseph form
        assert np.allclose(P_crlb[k], P, rtol=1e-7, atol=1e-12)
    assert np.sqrt(P_crlb[-1][0, 0]) < SIG_Z                # data did something


def test_fisher_step_is_literal_eq_3_31_and_3_30():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(6, 6))
    J = A @ A.T + 6 * np.eye(6)
    Phi = _cv_phi(DT) + 0.01 * rng.normal(size=(6, 6))
    H = rng.normal(size=(2, 6))
    R_inv = np.array([4.0, 0.25])
    B = rng.normal(size=(6, 6))
    Q = B @ B.T + np.eye(6)                                 # invertible: 3.31 is defined
    Qi = np.linalg.inv(Q)
    lit = (Qi + H.T @ np.diag(R_inv) @ H
           - Qi @ Phi @ np.linalg.inv(J + Phi.T @ Qi @ Phi) @ Phi.T @ Qi)
    assert np.allclose(fisher_step(J, Phi, H, R_inv, Q), lit, rtol=1e-9)
    lit30 = np.linalg.inv(Phi @ np.linalg.inv(J) @ Phi.T) + H.T @ np.diag(R_inv) @ H
    assert np.allclose(fisher_step(J, Phi, H, R_inv), lit30, rtol=1e-9)


def _kf_trial(rng, index, K=60):
    """Simulate the constant-velocity system with process noise and filter it; final error."""
    P0 = np.diag([100.0] * 3 + [0.1] * 3) ** 2
    Phi, Q = _cv_phi(DT), snc_process_noise(DT, SIG_ACC)
    x = rng.multivariate_normal(np.zeros(6), P0)
    xh, P = np.zeros(6), P0
    for k in range(K):
        x = Phi @ x + snc_gamma(DT) @ rng.normal(size=3) * SIG_ACC
        xh, P = Phi @ xh, Phi @ P @ Phi.T + Q
        H = _rows(k)
        z = H @ x + rng.normal() * SIG_Z
        G = P @ H.T / (H @ P @ H.T + SIG_Z**2)
        xh, P = xh + (G @ (z - H @ xh)), (np.eye(6) - G @ H) @ P
    return x - xh


def test_montecarlo_rms_matches_crlb():
    """Seeded Monte Carlo of the filter: per-component mean squared error is chi-square
    distributed about the CRLB."""
    n = 300
    err = np.array(monte_carlo(_kf_trial, n, seed=11))
    P0 = np.diag([100.0] * 3 + [0.1] * 3) ** 2
    P = crlb_history(P0, [_cv_phi(DT)] * 60, [_rows(k) for k in range(60)],
                     [np.array([SIG_Z**-2])] * 60, [snc_process_noise(DT, SIG_ACC)] * 60)[-1]
    ratio = rms_over_runs(err[:, None, :])[0] ** 2 / np.diag(P)
    lo, hi = chi2.ppf([0.0005, 0.9995], n) / n
    assert np.all((ratio > lo) & (ratio < hi)), ratio
    # seeded: each run draws from its own generator, spawned by index, so the first runs again are the same
    assert np.array_equal(err[:30], np.array(monte_carlo(_kf_trial, 30, seed=11)))
    assert not np.array_equal(err[:30], np.array(monte_carlo(_kf_trial, 30, seed=12)))


def test_montecarlo_parallel_equals_serial():
    """Runs on a local Dask cluster give the serial results, in run order."""
    import sys

    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    serial = monte_carlo(_kf_trial, 8, seed=5)
    parallel = monte_carlo(_kf_trial, 8, seed=5, parallel=True, n_workers=2)
    assert np.array_equal(np.array(serial), np.array(parallel))
