"""Stochastic RTN accelerations: truth flies a different random acceleration every 8 h.

Truth: white piecewise-constant RTN accelerations, 2e-8 m/s^2 per axis per 8-h batch
(~8 m and 0.6 mm/s over a batch). The fit estimates them as white Gauss-Markov batches
of the same statistics, and its SRP as a cannonball while the truth flies a Sun-pointing plate
(``test_od_simulate``): the epoch state and every batch's acceleration must come out within
their covariance (chi-square bounds, ``bounds.py``). Without the accelerations the same data
cannot be fitted to the noise.
"""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.estimation.registry import GaussMarkov
from odpipe.od import ArcSetup, fit_arc
from bounds import assert_within_covariance, max_z, rms_bounds
from test_od_simulate import arc_state, force_model, measurement_setup, scenario

SIGMA_ACC = 2e-8
BATCH = 8 * 3600.0


@pytest.fixture(scope="module")
def case():
    sc = scenario(days=2.0, maneuver=False, stochastic_sigma=SIGMA_ACC, seed=3)
    setup = ArcSetup("SC", sc["t0"], sc["t1"], arc_state(sc), force_model(), measurement_setup(),
                     stochastic=GaussMarkov(0.0, SIGMA_ACC, BATCH),
                     data_sigma={"range": 1.0, "doppler_2way": 1e-4})
    return sc, setup


def test_state_and_batch_accelerations_within_their_covariance(case):
    sc, setup = case
    sol = fit_arc(sc["table"], setup)
    used = int((sol.residuals["flags"] == 0).sum())
    lo, hi = rms_bounds(used, len(sol.parameters))
    assert sol.converged and lo < sol.history[-1]["postfit_rms"] < hi
    assert_within_covariance(sol.states[0] - sc["x0"], sol.covariances[0])
    acc = sol.registry.indices("stochastic")
    k = np.searchsorted(sol.epochs, sc["batches"][:, 0])
    k[0] = 0
    est = sol.solution.smoothed_x[k][:, acc]
    sd = np.sqrt(np.array([np.diag(P)[acc] for P in sol.solution.smoothed_P[k]]))
    truth = sc["batches"][:, 2:]
    assert np.all(np.abs(est - truth) < max_z(truth.size) * sd), (est - truth) / sd
    assert np.all(sd[:, 0] < 0.2 * SIGMA_ACC)            # the Doppler pins the radial component
    assert sol.problem.n_propagations >= 6 * len(sol.history)   # a segment per batch and iteration


def test_without_stochastic_accelerations_the_fit_fails_the_noise(case):
    sc, setup = case
    setup.stochastic = None
    setup.max_iter = 4
    sol = fit_arc(sc["table"], setup)
    assert sol.history[-1]["postfit_rms"] > 1.5
