"""An arc's convergence threshold and exact integration tolerances (``estimation.tol_dx``,
``estimation.reference_rtol``/``reference_atol``; ArcSetup ``tol_dx`` and ``integration``).

The simulated 2-day arc (``test_od_simulate``, no maneuver) is fitted with the defaults and with a
looser threshold (0.05 sigma, the GRAIL-B nightly's) and tolerances (1e-11, 1e-5): the looser fit ends
with an epoch correction below its threshold in no more passes than the default, its references fly the tolerances
given (fewer force evaluations per segment), and its epoch state is within its covariance of the
truth (chi-square bound, ``bounds.py``) and within a tenth of a sigma of the default fit's.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from odpipe.od import ArcSetup, fit_arc
from bounds import assert_within_covariance
from test_od_simulate import arc_state, force_model, measurement_setup, scenario

LOOSE = dict(tol_dx=0.05, integration={"rtol": 1e-11, "atol": 1e-5})


@pytest.fixture(scope="module")
def fits():
    sc = scenario(days=2.0, maneuver=False, seed=5)
    setup = ArcSetup("SC", sc["t0"], sc["t1"], arc_state(sc), force_model(), measurement_setup(),
                     data_sigma={"range": 1.0, "doppler_2way": 1e-4}, growing_days=None)
    return sc, fit_arc(sc["table"], setup), fit_arc(sc["table"], replace(setup, **LOOSE))


def evaluations_per_segment(sol) -> float:
    held = [traj for _, traj in sol.problem.shared.values()]
    return np.mean([traj.n_eval for traj in held])


def test_looser_fit_stops_at_its_threshold_with_its_tolerances(fits):
    _, default, loose = fits
    corr = [h["max_correction_sigma"] for h in loose.history]
    assert loose.converged and corr[-1] < LOOSE["tol_dx"]
    assert len(loose.history) <= len(default.history)
    assert (loose.problem.rtol, loose.problem.atol) == (1e-11, 1e-5)
    assert evaluations_per_segment(loose) < evaluations_per_segment(default)


def test_looser_fit_within_its_covariance_and_near_the_default(fits):
    sc, default, loose = fits
    assert default.converged
    assert_within_covariance(loose.states[0] - sc["x0"], loose.covariances[0])
    sd = np.sqrt(np.diag(default.covariances[0]))
    assert np.all(np.abs(loose.states[0] - default.states[0]) < 0.1 * sd)
