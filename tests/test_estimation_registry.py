"""Parameter registry: ordering, index ranges, Gauss-Markov discretization."""

import numpy as np
import pytest

from odpipe.estimation.registry import GaussMarkov, ParameterRegistry


def _registry():
    reg = ParameterRegistry()
    reg.add_state("halo", np.arange(6.0), 1e5, 1.0)
    reg.add("station.dss14.x", "station", 0.0, 0.03, owner="dss14", consider=True)
    reg.add_stochastic_acceleration("halo", 5e-9, 86400.0, 8 * 3600.0)
    reg.add_state("geo", np.arange(6.0) + 10, 100.0, 0.01)
    reg.add_maneuver("halo", "sk1", 1000.0, sigma_epoch=10.0)
    reg.add("bias.range.p1", "bias", 0.0, 5.0, owner="pass1")
    return reg


def test_consider_parameters_come_last_and_slices_are_contiguous():
    reg = _registry()
    assert len(reg) == 6 + 1 + 3 + 6 + 4 + 1
    assert reg.n_estimated == len(reg) - 1
    assert reg.names[-1] == "station.dss14.x" and reg.parameters[-1].consider
    assert reg.slice("state", "halo") == slice(0, 6)
    assert reg.slice("state", "geo") == slice(9, 15)
    assert reg.slice("stochastic") == slice(6, 9)
    assert reg.slice("maneuver", "halo.sk1") == slice(15, 18)
    assert list(reg.indices(owner="halo")) == list(range(0, 9)) + [15, 16, 17, 18]
    assert reg.apriori[reg.index("geo.vx")] == 13.0
    assert reg.sigma[reg.index("halo.sk1.dv_y")] == 0.01          # Table 4.1: 10 mm/s
    assert reg.sigma[reg.index("halo.sk1.dt")] == 10.0            # and 10 s in epoch
    with pytest.raises(KeyError):
        reg.slice("state")                                         # two spacecraft: not one range


def test_registry_rejects_bad_entries():
    reg = _registry()
    with pytest.raises(ValueError):
        reg.add("halo.x", "state", 0.0, 1.0)
    with pytest.raises(ValueError):
        reg.add("foo", "nonsense", 0.0, 1.0)
    with pytest.raises(ValueError):
        reg.add("foo", "bias", 0.0, 0.0)
    with pytest.raises(ValueError):
        reg.add("foo", "stochastic", 0.0, 1.0, consider=True, process=GaussMarkov(1, 1, 1))


def test_gauss_markov_discretization_preserves_steady_state_variance():
    gm = GaussMarkov(tau=3600.0, sigma=2e-9, batch=600.0)
    m, q = gm.step()
    assert m == pytest.approx(np.exp(-600.0 / 3600.0), rel=1e-15)
    # steady state: var = m^2 var + q  => var = sigma^2
    assert m * m * gm.sigma**2 + q == pytest.approx(gm.sigma**2, rel=1e-12)
    # autocorrelation over k batches is sigma^2 exp(-k dt / tau): simulate and compare
    rng = np.random.default_rng(0)
    p = rng.normal(size=20000) * gm.sigma
    series = [p]
    for _ in range(6):
        p = m * p + rng.normal(size=p.size) * np.sqrt(q)
        series.append(p)
    acf = np.mean(series[0] * series[6]) / gm.sigma**2
    assert acf == pytest.approx(np.exp(-3600.0 / 3600.0), abs=0.03)
    assert GaussMarkov(0.0, 1.0, 10.0).step() == (0.0, 1.0)           # white
    assert GaussMarkov(np.inf, 1.0, 10.0).step() == (1.0, 1.0)        # random walk


def test_stochastic_groups_one_per_process():
    reg = _registry()
    reg.add_stochastic_acceleration("geo", 1e-9, 0.0, 3600.0)
    groups = reg.stochastic_groups()
    assert [list(g[0]) for g in groups] == [[6, 7, 8], [20, 21, 22]]
    assert groups[1][1].tau == 0.0


def test_stochastic_accelerations_with_one_sigma_per_axis():
    reg = ParameterRegistry()
    reg.add_stochastic_acceleration("leo", [1e-5, 1e-6, 1e-5], 0.0, 60.0)      # seed 003 Table 11, R/T/N
    sig = [reg.parameters[i].sigma for i in reg.indices("stochastic")]
    assert sig == [1e-5, 1e-6, 1e-5]
    groups = reg.stochastic_groups()                                        # equal sigmas share a process
    assert sorted(list(g[0]) for g in groups) == [[0, 2], [1]]
    assert sorted(g[1].sigma for g in groups) == [1e-6, 1e-5]
