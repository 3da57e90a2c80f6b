"""With ``edit_against_reference`` the innovation test edits blunders, not rows the forward filter alone
finds surprising; without it (the default) those rows go, as a pure innovation test does.

A forward filter started from a tight a priori that the data overrule (an estimated burn whose execution
differs from its design by more than its a priori sigma, a plume after it) predicts the first rows many of
its sigmas off although the smoothed solution, the next pass's reference, fits them to the noise: edited on
the innovation alone they would all go, each keeping the filter on its a priori (lock-out).
Exactly linear case (position and velocity on a line, rows of position), values analytic.
"""

import numpy as np
import pytest

from estimation_cases import LinearProblem
from odpipe.estimation.fit import EDIT_INNOVATION, FitOptions, NothingToFit, Observations, fit
from odpipe.estimation.registry import ParameterRegistry

N, SIGMA, V = 200, 1e-3, 1.0      # rows, their sigma, true velocity


def _fit(blunders=(), against_reference=True):
    reg = ParameterRegistry()
    reg.add("x", "dynamic", 0.0, 1e-3)  # a priori right
    reg.add("v", "dynamic", 0.0, 0.05)  # a priori 20 sigma below the truth, the data overrule it
    A = np.array([[0.0, 1.0], [0.0, 0.0]])
    t = np.linspace(1.0, 100.0, N)
    y = V * t + SIGMA * np.random.default_rng(5).standard_normal(N)
    y[list(blunders)] += 20 * SIGMA
    prob = LinearProblem(reg, A, np.tile([1.0, 0.0], (N, 1)), t)
    return fit(prob, Observations(t, y, np.full(N, SIGMA), np.zeros(N)), 0.0, 100.0,
               FitOptions(block=10.0, edit_k=(np.inf, 5.0), edit_against_reference=against_reference))


def test_rows_the_reference_fits_are_kept():
    sol = _fit()
    assert sol.converged
    assert not np.any(sol.residuals["flags"] & EDIT_INNOVATION)
    assert abs(sol.x0[1] - V) < 5 * np.sqrt(sol.P0[1, 1])
    # the forward filter was surprised all the same: its first innovations are far beyond 5 sigma
    z = (sol.residuals["innovation"] / sol.residuals["innovation_sigma"]).abs()
    assert z.iloc[:3].min() > 5.0


def test_blunders_are_still_edited():
    sol = _fit(blunders=(60, 120, 170))
    edited = np.flatnonzero(sol.residuals["flags"].to_numpy() & EDIT_INNOVATION)
    assert list(edited) == [60, 120, 170]


def test_the_innovation_test_alone_locks_the_filter_out():
    with pytest.raises(NothingToFit, match="200 edited by the innovation test"):   # what the option avoids
        _fit(against_reference=False)
