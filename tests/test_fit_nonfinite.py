"""Non-finite rows are edited with their reason, not fatal; a fit with nothing left to fit says so.

Simulated two-body arc (tests/estimation_cases.py): the fit with NaN/inf values, bad sigmas and
non-finite computed values injected must equal the fit of the same data without those rows.
"""

import numpy as np
import pytest

from odpipe.estimation.fit import (EDIT_INNOVATION, NONFINITE, FitDiverged, FitOptions, NothingToFit,
                                   Observations, fit)
from estimation_cases import TwoBodyProblem, twobody_case
from odpipe.preprocess.flags import Flag, names

DAY = 86400.0
OPTIONS = FitOptions(block=600.0)
BAD_INPUT = {10: ("value", np.nan), 50: ("value", np.inf), 90: ("value", -np.inf),
             130: ("sigma", np.nan), 170: ("sigma", -1.0), 210: ("sigma", 0.0), 250: ("sigma", np.inf)}
BAD_MODEL = {300: "computed", 340: "partials"}   # the model returns NaN / inf for these rows


class _BadModel:
    """The problem, except that the computed value (NaN) or a partial (inf) of some rows is not finite."""

    def __init__(self, problem):
        self.problem, self.registry = problem, problem.registry

    def transition(self, t0, t1, x0):
        return self.problem.transition(t0, t1, x0)

    def predict(self, t0, x0, rows):
        value, H = self.problem.predict(t0, x0, rows)
        for k, what in BAD_MODEL.items():
            hit = rows == k
            if what == "computed":
                value[hit] = np.nan
            else:
                H[hit, 0] = np.inf
        return value, H


def _subset(prob, obs, keep):
    sub = TwoBodyProblem(prob.registry, prob.times[keep], prob.station[keep], prob.kind[keep], prob.stations)
    return sub, Observations(obs.time[keep], obs.value[keep], obs.sigma[keep], obs.group[keep])


@pytest.fixture(scope="module")
def case():
    prob, obs, truth = twobody_case(np.random.default_rng(3))
    value, sigma = obs.value.copy(), obs.sigma.copy()
    for k, (col, v) in BAD_INPUT.items():
        (value if col == "value" else sigma)[k] = v
    bad = Observations(obs.time, value, sigma, obs.group)
    keep = np.ones(obs.time.size, bool)
    keep[list(BAD_INPUT) + list(BAD_MODEL)] = False
    clean = fit(*_subset(prob, obs, keep), 0.0, DAY, OPTIONS)
    return prob, bad, keep, clean, fit(_BadModel(prob), bad, 0.0, DAY, OPTIONS)


def test_non_finite_rows_are_flagged_and_the_fit_equals_the_fit_without_them(case):
    prob, bad, keep, clean, sol = case
    assert clean.converged and sol.converged
    sig = np.sqrt(np.diag(clean.P0))
    assert np.max(np.abs(sol.x0 - clean.x0) / sig) < 1e-6
    np.testing.assert_allclose(np.sqrt(np.diag(sol.P0)), sig, rtol=1e-8)
    flags = sol.residuals["flags"].to_numpy()
    nonfinite = np.flatnonzero(flags & NONFINITE)
    assert sorted(nonfinite) == sorted(list(BAD_INPUT) + list(BAD_MODEL))
    # the other rows are edited exactly as without the bad rows
    np.testing.assert_array_equal(flags[keep] & EDIT_INNOVATION, clean.residuals["flags"].to_numpy() & EDIT_INNOVATION)
    assert all(h["nonfinite"] == len(nonfinite) for h in sol.history)
    post = sol.residuals["postfit"].to_numpy()
    np.testing.assert_allclose(post[keep], clean.residuals["postfit"].to_numpy(), rtol=0, atol=1e-6 * 2.0)
    assert np.isfinite(sol.history[-1]["postfit_rms"]) and np.isnan(post[~keep]).all()


def test_the_reason_has_a_table_flag():
    assert names(int(Flag.NONFINITE)) == ["nonfinite"]
    assert len({int(f) for f in Flag}) == len(Flag)   # one bit per reason


def test_covariances_stay_symmetric_positive_definite(case):
    *_, sol = case
    for P in (sol.filtered_P, sol.smoothed_P, sol.smoothed_P_consider):
        np.testing.assert_array_equal(P, P.transpose(0, 2, 1))
        for Pk in P:
            np.linalg.cholesky(Pk)   # raises unless positive definite


def _with(obs, value=None, sigma=None):
    return Observations(obs.time, obs.value if value is None else value, obs.sigma if sigma is None else sigma,
                        obs.group)


@pytest.mark.parametrize("corrupt, message", [
    (lambda o: _with(o, value=np.full(o.time.size, np.nan)), r"nothing left to fit: of \d+ rows, \d+ with a non-finite"),
    (lambda o: _with(o, sigma=np.full(o.time.size, np.inf)), r"nothing left to fit: of \d+ rows, \d+ with a non-finite"),
    (lambda o: _with(o, sigma=o.sigma * 1e30), r"carry no information about any estimated parameter"),
])
def test_a_fit_with_nothing_left_to_fit_fails_and_says_so(case, corrupt, message):
    prob, bad, *_ = case
    with pytest.raises(NothingToFit, match=message) as err:
        fit(prob, corrupt(bad), 0.0, DAY, OPTIONS)
    assert isinstance(err.value, FitDiverged)   # the CLI's exit code for a failed arc


def test_rows_all_outside_the_arc_leave_nothing_to_fit(case):
    prob, bad, *_ = case
    with pytest.raises(NothingToFit, match=r"of \d+ rows, \d+ outside the arc"):
        fit(prob, bad, -2 * DAY, -DAY, OPTIONS)
