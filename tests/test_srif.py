"""SRIF and SRIS against a textbook covariance Kalman filter and RTS smoother.

Reference: Kalman filter with Joseph-form update and the Rauch-Tung-Striebel
smoother, written here independently in covariance form (Tapley, Schutz & Born
2004, sections 4.7 and 4.15). The system is a 2-D constant-velocity body driven
by first-order Gauss-Markov accelerations (piecewise constant over each step),
with a measurement bias and linear range-like measurements.
"""

import numpy as np
import pytest

from odpipe.estimation.smoother import smooth
from odpipe.estimation.srif import SRIF


def _system(dt=60.0, tau=600.0, sig_a=1e-4):
    """Phi over one step with the acceleration held constant; state [r(2), v(2), a(2), b].

    tau = 0: white noise (m = 0); tau = inf: random walk (m = 1)."""
    Phi = np.eye(7)
    Phi[0:2, 2:4] = dt * np.eye(2)
    Phi[0:2, 4:6] = 0.5 * dt**2 * np.eye(2)
    Phi[2:4, 4:6] = dt * np.eye(2)
    m = 0.0 if tau == 0 else (1.0 if np.isinf(tau) else np.exp(-dt / tau))
    q = sig_a**2 * (1 - m * m) if 0 < m < 1 else sig_a**2
    return Phi, m, q


def _run(rng, K=40, tau=600.0):
    Phi, m, q = _system(tau=tau)
    n = 7
    sig0 = np.array([100.0, 100.0, 1.0, 1.0, 1e-4, 1e-4, 5.0])
    H_all = [np.column_stack([rng.normal(size=(3, 4)), np.zeros((3, 2)), np.ones((3, 1))])
             for _ in range(K)]
    y_all = [rng.normal(size=3) * 10 for _ in range(K)]
    sig_y = np.array([1.0, 2.0, 0.5])
    idx = np.array([4, 5])
    offset = np.array([1e-5, -2e-5])

    # -- SRIF --
    f = SRIF.from_apriori(sig0, dx=rng.normal(size=n) * sig0 * 0.1)
    x0, P0 = f.gaussian().x.copy(), np.diag(sig0**2)
    filt_srif = []
    for k in range(K):
        if k > 0:
            f.process_noise(idx, m, q, offset)
        f.measurement_update(H_all[k], y_all[k], sig_y)
        filt_srif.append(f.gaussian())
        f.mark(k)
        f.time_update(Phi)
    sm = smooth(f)

    # -- textbook covariance KF + RTS --
    x, P = x0, P0
    xs_f, Ps_f, xs_p, Ps_p, Fs = [], [], [], [], []
    M = np.eye(n)
    M[4, 4] = M[5, 5] = m
    Qn = np.zeros((n, n))
    Qn[4, 4] = Qn[5, 5] = q
    c = np.zeros(n)
    c[idx] = offset
    for k in range(K):
        if k > 0:
            x = Phi @ x
            P = Phi @ P @ Phi.T
            x = M @ x + c
            P = M @ P @ M.T + Qn
            Fs.append(M @ Phi)
        xs_p.append(x)
        Ps_p.append(P)
        H, Rm = H_all[k], np.diag(sig_y**2)
        Kg = P @ H.T @ np.linalg.inv(H @ P @ H.T + Rm)
        x = x + Kg @ (y_all[k] - H @ x)
        IKH = np.eye(n) - Kg @ H
        P = IKH @ P @ IKH.T + Kg @ Rm @ Kg.T
        xs_f.append(x)
        Ps_f.append(P)
    xsm, Psm = [xs_f[-1]], [Ps_f[-1]]
    for k in range(K - 2, -1, -1):
        G = Ps_f[k] @ Fs[k].T @ np.linalg.inv(Ps_p[k + 1])
        xsm.insert(0, xs_f[k] + G @ (xsm[0] - xs_p[k + 1]))
        Psm.insert(0, Ps_f[k] + G @ (Psm[0] - Ps_p[k + 1]) @ G.T)
    return filt_srif, sm, xs_f, Ps_f, xsm, Psm


def _rel(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


@pytest.mark.parametrize("tau", [600.0, 0.0, np.inf], ids=["gauss-markov", "white", "random-walk"])
def test_srif_and_sris_match_textbook_kalman_and_rts(tau):
    rng = np.random.default_rng(1)
    filt, sm, xf, Pf, xs, Ps = _run(rng, tau=tau)
    K = len(xf)
    worst_f = max(max(_rel(filt[k].x, xf[k]), _rel(filt[k].P, Pf[k])) for k in range(K))
    worst_s = max(max(_rel(sm[k].x, xs[k]), _rel(sm[k].P, Ps[k])) for k in range(K))
    assert worst_f < 1e-9, worst_f
    assert worst_s < 1e-9, worst_s
    # smoothing must have changed something (process noise present)
    assert _rel(sm[0].P, Pf[0]) > 1e-3


def test_consider_covariance_matches_brute_force():
    """Consider covariance = covariance of the estimate's error when the consider
    parameter (bias) is fixed at its a priori while truly random (closed form)."""
    rng = np.random.default_rng(2)
    n_est, sig_c = 4, 3.0
    H = np.column_stack([rng.normal(size=(30, n_est)), np.ones(30)])
    sig_y = 0.7
    sig0 = np.array([10.0, 10.0, 10.0, 10.0, sig_c])
    f = SRIF.from_apriori(sig0, n_est=n_est)
    f.measurement_update(H, rng.normal(size=30), np.full(30, sig_y))
    g = f.gaussian()
    # brute force: x_hat = A (y - Hc*c_bar) with A the weighted LS gain on estimated columns
    He, Hc = H[:, :n_est], H[:, n_est:]
    N = He.T @ He / sig_y**2 + np.diag(1 / sig0[:n_est] ** 2)
    Px = np.linalg.inv(N)
    A = Px @ He.T / sig_y**2
    Pcons = Px + (A @ Hc) @ (A @ Hc).T * sig_c**2
    assert _rel(g.P[:n_est, :n_est], Px) < 1e-10
    assert _rel(g.P_consider[:n_est, :n_est], Pcons) < 1e-10
    assert _rel(g.P_consider[:n_est, n_est:], -(A @ Hc) * sig_c**2) < 1e-10
    assert np.all(np.diag(g.P_consider) >= np.diag(g.P) - 1e-12)


def _min_corr_eig(P):
    """Smallest eigenvalue of the correlation matrix (scale-free definiteness)."""
    d = 1 / np.sqrt(np.diag(P))
    return np.linalg.eigvalsh(P * d[:, None] * d[None, :]).min()


def test_covariance_positive_definite_with_unobservable_bias():
    """Two biases that enter only as a sum, one with a tight a priori: the
    covariance stays symmetric positive definite through filter and smoother."""
    rng = np.random.default_rng(3)
    Phi, m, q = _system()
    Phi8 = np.eye(8)
    Phi8[:7, :7] = Phi
    sig0 = np.array([1e5, 1e5, 1.0, 1.0, 1e-4, 1e-4, 5.0, 1e-6])
    f = SRIF.from_apriori(sig0)
    mins = []
    for k in range(200):
        if k:
            f.process_noise([4, 5], m, q)
        H = np.column_stack([rng.normal(size=(2, 4)), np.zeros((2, 2)), np.ones((2, 2))])
        f.measurement_update(H, rng.normal(size=2), np.array([1.0, 1.0]))
        f.mark(k)
        f.time_update(Phi8)
        P = f.gaussian().P
        assert _rel(P, P.T) < 1e-12
        np.linalg.cholesky(P)
        mins.append(_min_corr_eig(P))
    for g in smooth(f).values():
        assert np.allclose(g.P, g.P.T, rtol=1e-10, atol=0)
        np.linalg.cholesky(g.P)
        mins.append(_min_corr_eig(g.P))
        assert g.sigma[7] == pytest.approx(1e-6, rel=1e-3)   # unobservable: a priori kept
    assert min(mins) > 1e-10, min(mins)


def test_accumulated_chi2_is_the_least_squares_cost():
    """Sum of the squared whitened residuals the Householder updates leave behind equals
    the weighted least-squares cost at the estimate (a priori term included)."""
    rng = np.random.default_rng(6)
    H = rng.normal(size=(40, 3))
    y = H @ np.array([1.0, -2.0, 0.5]) + rng.normal(size=40) * 0.3
    sig0 = np.array([10.0, 10.0, 10.0])
    f = SRIF.from_apriori(sig0)
    for k in range(0, 40, 7):                     # blocks of uneven size
        f.measurement_update(H[k:k + 7], y[k:k + 7], np.full(len(y[k:k + 7]), 0.3))
    x = f.gaussian().x
    cost = np.sum(((y - H @ x) / 0.3) ** 2) + np.sum((x / sig0) ** 2)
    assert f.chi2 == pytest.approx(cost, rel=1e-10)


def test_compiled_intervals_match_textbook_kalman_rts_and_edit_a_blunder():
    """``SRIF.intervals`` (one compiled pass: marks, innovation test, updates, maps) against the textbook
    covariance filter and RTS smoother without process noise: filtered and smoothed estimates and covariances
    at every mark, each row's innovation and its predicted sigma (H P H^T + sigma^2), and a 20-sigma blunder
    edited by the 5-sigma test (the covariance filter leaves that row out)."""
    rng = np.random.default_rng(7)
    Phi, _, _ = _system()
    n, K = 7, 30
    sig0 = np.array([100.0, 100.0, 1.0, 1.0, 1e-4, 1e-4, 5.0])
    counts = rng.integers(0, 4, size=K)                       # uneven blocks, some empty
    bounds = np.concatenate([[0], np.cumsum(counts)])
    H = np.column_stack([rng.normal(size=(bounds[-1], 4)), np.zeros((bounds[-1], 2)), np.ones((bounds[-1], 1))])
    sig_y = rng.uniform(0.5, 2.0, size=bounds[-1])
    y = rng.normal(size=bounds[-1]) * sig_y
    blunder = int(bounds[K // 2])
    y[blunder] += 20 * np.sqrt(np.sum((H[blunder] * sig0) ** 2) + sig_y[blunder] ** 2)
    f = SRIF.from_apriori(sig0, dx=rng.normal(size=n) * sig0 * 0.1)
    x, P = f.gaussian().x.copy(), np.diag(sig0**2)
    Rs, zs, nu, s, bad = f.intervals(0, np.repeat(Phi[None], K, 0), H, y, sig_y, np.ones(y.size, bool), bounds, 5.0)
    f.mark(K)
    sm = smooth(f)
    xs_f, Ps_f, nu_kf, s_kf = [], [], np.empty(y.size), np.empty(y.size)
    for k in range(K):
        xs_f.append(x)
        Ps_f.append(P)
        r = slice(bounds[k], bounds[k + 1])
        nu_kf[r] = y[r] - H[r] @ x
        s_kf[r] = np.sqrt(np.einsum("ij,jk,ik->i", H[r], P, H[r]) + sig_y[r] ** 2)
        keep = np.arange(bounds[k], bounds[k + 1]) != blunder
        Hk, Rm = H[r][keep], np.diag(sig_y[r][keep] ** 2)
        if len(Hk):
            Kg = P @ Hk.T @ np.linalg.inv(Hk @ P @ Hk.T + Rm)
            x = x + Kg @ (y[r][keep] - Hk @ x)
            IKH = np.eye(n) - Kg @ Hk
            P = IKH @ P @ IKH.T + Kg @ Rm @ Kg.T
        x, P = Phi @ x, Phi @ P @ Phi.T
    xs_f.append(x)
    Ps_f.append(P)
    Phi_inv = np.linalg.inv(Phi)
    xsm, Psm = [x], [P]                                       # no process noise: the final estimate mapped back
    for k in range(K - 1, -1, -1):
        xsm.insert(0, Phi_inv @ xsm[0])
        Psm.insert(0, Phi_inv @ Psm[0] @ Phi_inv.T)
    filt = [SRIF(R, z).gaussian() for R, z in zip(Rs, zs)]
    assert max(max(_rel(filt[k].x, xs_f[k]), _rel(filt[k].P, Ps_f[k])) for k in range(K)) < 1e-9
    assert max(max(_rel(sm[k].x, xsm[k]), _rel(sm[k].P, Psm[k])) for k in range(K + 1)) < 1e-9
    assert _rel(nu, nu_kf) < 1e-9 and _rel(s, s_kf) < 1e-9
    assert np.flatnonzero(bad).tolist() == [blunder]
