"""Multi-arc solutions (odpipe.od.multiarc): parameters shared by arcs, each arc with its own state.

1. The combination from each arc's marginal posterior equals the joint least-squares solution of all arcs'
   data at once (every arc's local parameters and the shared ones in one normal matrix, solved with numpy):
   a linear-Gaussian case where the two must agree to rounding.
2. Simulated truth that differs from the filter's model: two consecutive days of the cislunar HEO of
   ``test_od_simulate`` (the truth flies a Sun-pointing plate, the filter a cannonball whose scale it
   estimates; the plate's equivalent scale ``TRUE_SRP_SCALE`` = 0.93 comes from the plate formula), fitted
   as two daily arcs that share the SRP scale, each with its own epoch state and range biases.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2

from bounds import assert_within_covariance, max_z
from odpipe.od import ArcSetup
from odpipe.od.multiarc import ArcShare, combine, fit_multiarc, share_of, with_shared
from test_od_simulate import PERTURBATION, TRUE_SRP_SCALE, force_model, measurement_setup, scenario


def test_combination_equals_the_joint_least_squares_of_all_arcs():
    rng = np.random.default_rng(3)
    n_loc, n_g, arcs = 4, 2, 3
    g0, s0 = np.array([1.0, -0.5]), np.array([0.3, 0.2])
    loc_sigma = 5.0
    g_true = g0 + s0 * rng.standard_normal(n_g)
    blocks, shares = [], []
    for _ in range(arcs):
        A, B = rng.standard_normal((30, n_loc)), rng.standard_normal((30, n_g))
        x = loc_sigma * rng.standard_normal(n_loc)
        y = A @ x + B @ g_true + 0.1 * rng.standard_normal(30)
        blocks.append((A, B, y))
        # the arc alone: locals (prior 0 ± loc_sigma) and shared (prior g0 ± s0), weights 1/0.1^2
        H = np.hstack([A, B]) / 0.1
        N = H.T @ H + np.diag(np.r_[np.full(n_loc, loc_sigma ** -2.0), s0 ** -2.0])
        b = H.T @ (y / 0.1) + np.r_[np.zeros(n_loc), g0 / s0 ** 2]
        P = np.linalg.inv(N)
        est = P @ b
        shares.append(ArcShare(est[n_loc:], P[n_loc:, n_loc:], g0, s0))
    # all arcs at once: [x_1 .. x_arcs | g]
    n = arcs * n_loc + n_g
    N, b = np.zeros((n, n)), np.zeros(n)
    for k, (A, B, y) in enumerate(blocks):
        H = np.zeros((y.size, n))
        H[:, k * n_loc:(k + 1) * n_loc], H[:, -n_g:] = A, B
        N += H.T @ H / 0.01
        b += H.T @ y / 0.01
    N += np.diag(np.r_[np.full(arcs * n_loc, loc_sigma ** -2.0), s0 ** -2.0])
    b[-n_g:] += g0 / s0 ** 2
    P = np.linalg.inv(N)
    c = combine(shares, g0, s0, ("a", "b"))
    np.testing.assert_allclose(c.estimate, (P @ b)[-n_g:], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(c.covariance, P[-n_g:, -n_g:], rtol=1e-9, atol=1e-15)
    assert np.all(c.chi2 < chi2.ppf(0.999, n_g)), c.chi2


@pytest.fixture(scope="module")
def two_days():
    sc = scenario(days=2.0, maneuver=False)
    mid = sc["t0"] + 86400.0
    arcs = []
    for a, b in ((sc["t0"], mid), (mid, sc["t1"])):
        x0 = sc["truth"].state(a)[0] + PERTURBATION
        arcs.append((sc["table"], ArcSetup("SC", a, b, x0, force_model(), measurement_setup(),
                                           data_sigma={"range": 1.0, "doppler_2way": 1e-4})))
    return sc, arcs, fit_multiarc(arcs, ("srp_scale",), rounds=2)


def test_shared_srp_scale_comes_back_within_its_sigma_tighter_than_either_day(two_days):
    sc, arcs, sol = two_days
    c = sol.shared
    assert abs(c.estimate[0] - TRUE_SRP_SCALE) < max_z(1) * c.sigma[0], (c.estimate, c.sigma)
    # each day alone (with the common prior) is a sub-estimate: the two days together must be tighter
    alone = np.sqrt(c.arc_covariances[:, 0, 0])
    assert np.all(c.sigma[0] < 0.9 * alone), (c.sigma, alone)
    assert np.all(np.abs(c.arc_estimates[:, 0] - TRUE_SRP_SCALE) < max_z(2) * alone), (c.arc_estimates, alone)
    assert np.all(c.chi2 < chi2.ppf(0.999, 1)), c.chi2


def test_each_day_with_the_shared_scale_fixed_has_its_epoch_state_within_its_covariance(two_days):
    sc, arcs, sol = two_days
    for arc, (_, setup) in zip(sol.arcs, arcs):
        assert arc.converged
        assert "SC.srp_scale" not in list(arc.parameters["name"])
        assert_within_covariance(arc.states[0] - sc["truth"].state(setup.start)[0], arc.covariances[0])


def test_fixing_part_of_a_polynomial_acceleration_is_refused():
    from odpipe.dynamics.forces import InertialPolynomialAcceleration

    poly = InertialPolynomialAcceleration(0.0)
    setup = ArcSetup("SC", 0.0, 86400.0, np.zeros(6), force_model(extra=[poly]), measurement_setup(),
                     polynomial_sigma=(1e-9, 1e-14))
    with pytest.raises(ValueError, match="whole"):
        with_shared(setup, ("poly[0].x0",), (1e-10,), fixed=True)
    fixed = with_shared(setup, ("srp_scale",), (0.9,), fixed=True)
    assert fixed.srp_scale_sigma is None and fixed.polynomial_sigma == (1e-9, 1e-14)


def test_a_multiarc_config_names_what_is_wrong(tmp_path):
    from odpipe.operations.schema import ConfigError
    from odpipe.pipeline.multiarc import load_multiarc

    cfg = tmp_path / "m.toml"
    cfg.write_text('[multiarc]\nname = "m"\narcs = ["a.toml"]\nshared = ["srp_scale", "mass"]\n')
    with pytest.raises(ConfigError) as err:
        load_multiarc(cfg)
    assert "multiarc.arcs" in str(err.value) and "multiarc.shared[1]" in str(err.value)
    cfg.write_text('[multiarc]\nname = "m"\narcs = ["a.toml", "b.toml"]\nshared = ["srp_scale"]\nrounds = 2\n')
    sec = load_multiarc(cfg)
    assert sec.arcs == [tmp_path / "a.toml", tmp_path / "b.toml"] and sec.rounds == 2


def test_the_multiarc_command_refuses_bad_configs_and_arcs_not_yet_run(tmp_path, capsys):
    """``odpipe multiarc``: a wrong config and arcs without a complete run are one line each, exit status 2."""
    from odpipe.cli import main
    from test_cli_batch import arc_text

    bad = tmp_path / "bad.toml"
    bad.write_text('[multiarc]\nname = "m"\narcs = ["a.toml"]\nshared = ["mass"]\n')
    assert main(["multiarc", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "multiarc.arcs" in err and "'mass'" in err and "Traceback" not in err
    for name in ("a", "b"):
        (tmp_path / f"{name}.toml").write_text(arc_text(name))
    good = tmp_path / "m.toml"
    good.write_text('[multiarc]\nname = "m"\narcs = ["a.toml", "b.toml"]\nshared = ["srp_scale"]\n')
    assert main(["multiarc", str(good)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "a.toml" in err and "run this arc first" in err
