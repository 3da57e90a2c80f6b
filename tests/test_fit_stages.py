"""Data-weight stages and step halving of the iterated filter-smoother (two-body arc with simulated truth)."""

from dataclasses import replace

import numpy as np
import pytest

from odpipe.estimation.fit import FitDiverged, FitOptions, fit
from estimation_cases import twobody_case

DAY = 86400.0


@pytest.fixture(scope="module")
def case():
    prob, obs, truth = twobody_case(np.random.default_rng(3))
    plain = fit(prob, obs, 0.0, DAY, FitOptions(block=600.0))
    return prob, obs, truth, plain


def test_staged_weights_reach_the_same_solution(case):
    prob, obs, truth, plain = case
    staged = fit(prob, obs, 0.0, DAY, FitOptions(block=600.0, sigma_scale=(100.0, 10.0, 1.0), max_iter=15))
    assert plain.converged and staged.converged
    scales = [h["sigma_scale"] for h in staged.history]
    assert scales[0] == 100.0 and scales[-1] == 1.0 and scales == sorted(scales, reverse=True)
    sig = np.sqrt(np.diag(plain.P0))
    assert np.max(np.abs(staged.x0 - plain.x0) / sig) < 1e-2
    np.testing.assert_allclose(np.sqrt(np.diag(staged.P0)), sig, rtol=1e-6)
    d = staged.x0 - truth["x0"]
    assert d @ np.linalg.solve(staged.P0, d) < 40.0   # chi-square, 15 parameters, far below 0.1 %


class _FailsOnce:
    """The problem, except that the first corrected reference 'cannot be integrated'."""

    def __init__(self, problem, x_apriori):
        self.problem, self.registry, self.x_apriori, self.failed = problem, problem.registry, x_apriori, False

    def transition(self, t0, t1, x0):
        if not self.failed and t0 == 0.0 and not np.allclose(x0[:6], self.x_apriori[:6]):
            self.failed = True
            raise RuntimeError("DOP853: step size underflow")
        return self.problem.transition(t0, t1, x0)

    def predict(self, t0, x0, rows):
        return self.problem.predict(t0, x0, rows)


def test_a_reference_that_cannot_be_integrated_halves_the_step(case):
    prob, obs, truth, plain = case
    flaky = _FailsOnce(prob, prob.registry.apriori.copy())
    sol = fit(flaky, obs, 0.0, DAY, FitOptions(block=600.0))
    assert flaky.failed and sol.converged
    assert sol.history[1]["halvings"] == 1
    assert np.max(np.abs(sol.x0 - plain.x0) / np.sqrt(np.diag(plain.P0))) < 1e-2


class _Worsening:
    """The problem, with a model error (alternating in sign, 300 sigma more at each pass) no
    parameter absorbs: the iterations can only make the fit worse."""

    def __init__(self, problem, sigma):
        self.problem, self.registry, self.sigma, self.passes = problem, problem.registry, sigma, 0

    def transition(self, t0, t1, x0):
        self.passes += t0 == 0.0
        return self.problem.transition(t0, t1, x0)

    def predict(self, t0, x0, rows):
        value, H = self.problem.predict(t0, x0, rows)
        return value + (-1.0) ** rows * 300.0 * (self.passes - 1) * self.sigma[rows], H


def test_a_fit_made_worse_by_its_iterations_raises_instead_of_returning_products(case):
    prob, obs, _, _ = case
    with pytest.raises(FitDiverged, match="not converged in 3 iterations"):
        fit(_Worsening(prob, obs.sigma), obs, 0.0, DAY, FitOptions(block=600.0, max_iter=3, edit_k=(np.inf,)))


def test_a_new_stages_first_pass_keeps_a_blunder_edited(case):
    """Rows the last stage edited are tested again at the next stage's first pass, not let back in: a 30-sigma
    blunder (at the tight weight) stays out of every pass once edited, and the stages end on the plain fit's
    solution without it."""
    prob, obs, truth, plain = case
    value = obs.value.copy()
    value[len(value) // 2] += 30.0 * obs.sigma[len(value) // 2]
    bad = replace(obs, value=value)
    staged = fit(prob, bad, 0.0, DAY, FitOptions(block=600.0, sigma_scale=(100.0, 10.0, 1.0), max_iter=15,
                                                 edit_k=(np.inf, 10.0, 5.0)))
    assert staged.converged
    edited = [h["edited"] for h in staged.history]
    first = next(i for i, h in enumerate(staged.history) if h["sigma_scale"] == 1.0)
    assert edited[first] == 1 and edited[-1] == 1   # the new stage's first pass too (it let it back in: 0)
    assert np.max(np.abs(staged.x0 - plain.x0) / np.sqrt(np.diag(plain.P0))) < 0.05


class _SpansNothing:
    """The problem, with a ``span`` that answers no interval (a reference segment ending before the next grid
    epoch): the fit must stop with a reason instead of sweeping forever."""

    def __init__(self, problem):
        self.problem, self.registry = problem, problem.registry

    def span(self, epochs, x0, bounds):
        n = x0.size
        return x0[None, :], np.empty((0, n, n)), np.empty(0), np.empty((0, n))

    def transition(self, t0, t1, x0):
        return self.problem.transition(t0, t1, x0)

    def predict(self, t0, x0, rows):
        return self.problem.predict(t0, x0, rows)


def test_a_span_that_answers_no_interval_stops_the_fit_with_a_reason(case):
    prob, obs, _, _ = case
    with pytest.raises(FitDiverged, match="span answered no grid interval from 0.000 s TDB"):
        fit(_SpansNothing(prob), obs, 0.0, DAY, FitOptions(block=600.0, max_iter=2))
