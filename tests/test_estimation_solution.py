"""Solution round trip through its file, and spacecraft state extraction."""

import numpy as np

from odpipe.estimation.fit import FitOptions, Observations, fit
from odpipe.estimation.solution import Solution
from tests.test_estimation_montecarlo import ARC, BATCH, _setup, _truth


def test_solution_save_load_round_trip(tmp_path):
    reg, prob, t, sigma, kind = _setup()
    rng = np.random.default_rng(5)
    y = np.einsum("mk,mk->m", prob.H_rows, _truth(reg, prob, rng)(t)) + rng.normal(size=t.size) * sigma
    sol = fit(prob, Observations(t, y, sigma, kind), 0.0, ARC, FitOptions(block=BATCH))
    path = tmp_path / "run" / "solution.npz"
    sol.save(path)
    back = Solution.load(path)
    assert back.names == sol.names and back.converged == sol.converged
    for a in ("grid", "filtered_x", "filtered_P", "smoothed_x", "smoothed_P", "smoothed_P_consider"):
        assert np.array_equal(getattr(back, a), getattr(sol, a))
    assert back.residuals.equals(sol.residuals)
    assert back.history == sol.history and back.inputs == sol.inputs
    assert len(sol.inputs["observations"]) == 64
    g, X, P = sol.states("sc")
    assert X.shape == (g.size, 6) and P.shape == (g.size, 6, 6)
    assert np.array_equal(X[:, 3], sol.smoothed_x[:, reg.index("sc.vx")])
    assert [p.name for p in path.parent.iterdir()] == ["solution.npz"]   # no temporary left


def test_string_groups_survive_the_file(tmp_path):
    from estimation_cases import twobody_case

    prob, obs, _ = twobody_case(np.random.default_rng(2), days=0.25, maneuvers=(), stochastic=False)
    sol = fit(prob, obs, 0.0, 0.25 * 86400.0, FitOptions(block=1800.0, max_iter=2))
    sol.save(tmp_path / "s.npz")
    back = Solution.load(tmp_path / "s.npz")
    assert list(back.residuals["group"]) == list(sol.residuals["group"])
    assert back.history[-1]["scales"].keys() == sol.history[-1]["scales"].keys()
