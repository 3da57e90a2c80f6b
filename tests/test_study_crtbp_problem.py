"""Two-spacecraft CRTBP crosslink problem: partials against central differences."""

import numpy as np
import pytest

from odpipe.estimation.registry import ParameterRegistry
from odpipe.studies.crtbp_problem import CrosslinkProblem, crosslink_rows, units_from_mu

U = units_from_mu(384747.96e3, 398600.4415e9 / (1 - 0.01215), 0.01215)
X1 = U.to_si(np.array([0.8326, 0.0, 0.1289, 0.0, 0.2425, 0.0]))
X2 = U.to_si(np.array([0.9878, 0.01, 0.02, 0.3, 0.5, 0.1]))


def test_row_partials_match_central_differences():
    t = np.array([0.0, 0.0])
    kind = np.array([0, 1])
    _, H = crosslink_rows(X1[None].repeat(2, 0), X2[None].repeat(2, 0), t, kind)
    x = np.concatenate([X1, X2])
    steps = np.array([1.0] * 3 + [1e-3] * 3)
    for j in range(12):
        h = np.zeros(12)
        h[j] = steps[j % 6]
        zp, _ = crosslink_rows((x + h)[None, :6].repeat(2, 0), (x + h)[None, 6:].repeat(2, 0), t, kind)
        zm, _ = crosslink_rows((x - h)[None, :6].repeat(2, 0), (x - h)[None, 6:].repeat(2, 0), t, kind)
        assert np.allclose((zp - zm) / (2 * h[j]), H[:, j], rtol=1e-5, atol=1e-12)


def test_predict_maps_partials_to_the_grid_epoch():
    reg = ParameterRegistry()
    reg.add_state("sc1", X1, 1e3, 1e-2)
    reg.add_state("sc2", X2, 1e3, 1e-2)
    t = np.array([3600.0, 7200.0, 7200.0, 86400.0])
    kind = np.array([0, 0, 1, 1])
    prob = CrosslinkProblem(reg, U, t, kind)
    x0 = reg.apriori
    rows = np.arange(4)
    z, H = prob.predict(0.0, x0, rows)
    steps = np.tile([10.0] * 3 + [1e-3] * 3, 2)
    for j in range(12):
        h = np.zeros(12)
        h[j] = steps[j]
        d = (prob.predict(0.0, x0 + h, rows)[0] - prob.predict(0.0, x0 - h, rows)[0]) / (2 * h[j])
        assert np.allclose(d, H[:, j], rtol=1e-5, atol=1e-10 * np.abs(H).max())
    x1, Phi = prob.transition(0.0, 86400.0, x0)
    z2, _ = prob.predict(86400.0, x1, np.array([3]))
    assert abs(z2[0] - z[3]) < 1e-6                                # same truth from either epoch
    assert np.allclose(Phi[:6, 6:], 0)
    assert np.linalg.det(Phi[:6, :6]) == pytest.approx(1.0, abs=1e-6)   # symplectic flow
