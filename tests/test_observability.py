"""Observability Gramian and measures on a linear system with a closed-form Gramian."""

import numpy as np
import pytest

from odpipe.analysis.observability import (cumulative_gramians, gramian, map_to_epoch,
                                           observability_measures, snr_ratio)


def _double_integrator(t):
    """Phi(t, 0) of x'' = 0 (1-D): [[1, t], [0, 1]] per epoch."""
    Phi = np.zeros((t.size, 2, 2))
    Phi[:, 0, 0] = Phi[:, 1, 1] = 1.0
    Phi[:, 0, 1] = t
    return Phi


def test_gramian_of_position_samples_is_closed_form():
    t = np.linspace(0.0, 50.0, 11)
    sig = 2.0
    H = np.tile([1.0, 0.0], (t.size, 1))
    N = gramian(map_to_epoch(H, _double_integrator(t)), np.full(t.size, sig**-2))
    m = t.size
    # sum over samples of [1, t]^T [1, t] / sig^2
    a, b, c = m / sig**2, t.sum() / sig**2, (t**2).sum() / sig**2
    assert np.allclose(N, [[a, b], [b, c]], rtol=1e-14)
    # eigenvalues of a symmetric 2x2
    mid, rad = (a + c) / 2, np.hypot((a - c) / 2, b)
    meas = observability_measures(N)
    assert np.allclose(meas.singular_values, [mid + rad, mid - rad], rtol=1e-12)
    assert meas.condition_number == pytest.approx((mid + rad) / (mid - rad), rel=1e-10)
    assert meas.unobservability_index == pytest.approx(1 / (mid - rad), rel=1e-10)
    assert meas.rank() == 2
    # the inverse Gramian is the least-squares covariance of (x0, v0): velocity sigma
    # of a straight-line fit is sig / sqrt(sum (t - mean)^2)
    P = np.linalg.inv(N)
    assert np.sqrt(P[1, 1]) == pytest.approx(sig / np.sqrt(np.sum((t - t.mean()) ** 2)), rel=1e-12)


def test_velocity_only_data_leave_position_unobservable():
    t = np.linspace(0.0, 10.0, 5)
    H = np.tile([0.0, 1.0], (t.size, 1))
    meas = observability_measures(gramian(map_to_epoch(H, _double_integrator(t))))
    assert meas.rank() == 1
    assert meas.unobservability_index > 1e12 or np.isinf(meas.unobservability_index)


def test_cumulative_gramian_ends_at_the_gramian_and_grows():
    rng = np.random.default_rng(1)
    H = rng.normal(size=(30, 4))
    w = rng.uniform(0.5, 2.0, 30)
    C = cumulative_gramians(H, w)
    assert np.allclose(C[-1], gramian(H, w))
    dets = np.linalg.det(C[4:])
    assert np.all(np.diff(dets) > 0)            # each row adds information once full rank


def test_snr_ratio_is_the_rowwise_gramian_ratio():
    """Xi_i = (sb/sa)|Ha_i/Hb_i| equals (sb/sa) sqrt(Na_ii / Nb_ii) of one-row Gramians."""
    rng = np.random.default_rng(2)
    Ha, Hb = rng.normal(size=(1, 6)), rng.normal(size=(1, 6))
    xi = snr_ratio(Ha, Hb, 1.0, 3e-4)
    ref = 3e-4 * np.sqrt(np.diag(gramian(Ha)) / np.diag(gramian(Hb)))
    assert np.allclose(xi[0], ref)
    assert np.isinf(snr_ratio(np.ones((1, 1)), np.zeros((1, 1)), 1.0, 1.0)[0, 0])
