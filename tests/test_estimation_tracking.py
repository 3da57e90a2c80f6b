"""The fit on the product's models through the TrackingProblem adapter.

A lunar-distance Earth orbiter (Moon and Sun point masses from DE440, SRP) is
tracked by DSS-14 / DSS-43 / DSS-63 with two-way range (m, light time solved)
and instantaneous range-rate, every 20 min for 2 days. The truth trajectory
(epoch state off by 2 km / 2 cm/s, SRP scale 1.06) is propagated by
odpipe.dynamics and observed by odpipe.measurements plus noise; the fit must
recover state and SRP scale within the reported covariance; a second case adds
Gauss-Markov RTN accelerations (5e-9 m/s^2, tau 1 d, 8-h batches) to the truth
and the registry.
"""

import numpy as np
import pytest
from scipy.stats import chi2

from odpipe.dynamics.forces import EmpiricalRTN, ForceModel, PointMasses, SolarRadiationPressure
from odpipe.dynamics.propagator import propagate
from odpipe.estimation.fit import FitOptions, fit
from odpipe.estimation.registry import ParameterRegistry
from odpipe.estimation.tracking import TrackingProblem, observations_from_rows
from odpipe.measurements.compute import MeasurementSetup, compute
from odpipe.time.scales import utc_to_tdb
from parsers.table import build

T0 = np.datetime64("2025-03-01T00:00:00", "ns")
X0 = np.array([2.6e8, -2.2e8, 0.9e8, 450.0, 620.0, -150.0])


@pytest.fixture(scope="module")
def setup():
    return MeasurementSetup.default()


def _tracked(setup, stochastic):
    t0 = float(utc_to_tdb(np.array([T0]))[0])

    def force_model(x, emp=()):
        comps = [PointMasses(["moon", "sun"]), SolarRadiationPressure(cr_area=40.0, scale=x[6])]
        return ForceModel("earth", comps + list(emp), mass=500.0, ephemeris=setup.ephemeris)

    reg = ParameterRegistry()
    reg.add_state("A", X0, 1e4, 0.1)
    reg.add("A.srp_scale", "dynamic", 1.0, 0.1, owner="A")
    rng = np.random.default_rng(8)
    x_true = np.concatenate([X0 + [2e3, -1.5e3, 1e3, 0.02, -0.015, 0.01], [1.06]])
    emp = ()
    if stochastic:                         # Gauss-Markov RTN accelerations, 8-h batches
        batch, sig = 8 * 3600.0, 5e-9
        reg.add_stochastic_acceleration("A", sig, 86400.0, batch)
        m, q = reg.stochastic_groups()[0][1].step()
        a = [rng.normal(size=3) * sig]
        for _ in range(5):
            a.append(m * a[-1] + rng.normal(size=3) * np.sqrt(q))
        emp = [EmpiricalRTN(np.array([[t0 + j * batch, t0 + (j + 1) * batch, *a[j]]
                                      for j in range(6)]))]
        x_true = np.concatenate([x_true, a[0]])
    epochs = T0 + (np.arange(1200, 2 * 86400, 1200)).astype("timedelta64[s]")
    stations = np.array(["DSS-14", "DSS-43", "DSS-63"])
    n = epochs.size * 2
    st = np.repeat(stations[np.arange(epochs.size) % 3], 2)
    obs = np.tile(np.array(["range", "range_rate"], dtype=object), epochs.size)
    sigma = np.where(obs == "range", 1.0, 1e-4)
    rows = build(n, epoch=np.repeat(epochs, 2), observable=obs,
                 unit=np.where(obs == "range", "m", "m/s"), station_tx=st, station_rx=st,
                 spacecraft="A", tag="receive", count_time=0.0, band_up="X", band_down="X",
                 uplink_hz=7.16e9, value=0.0, sigma=sigma)
    t_end = t0 + 2 * 86400.0
    truth = propagate(x_true[:6], t0, t_end, force_model(x_true, emp))
    rows["value"] = compute(rows, {"A": truth}, setup).value + rng.normal(size=n) * sigma
    prob = TrackingProblem(reg, "A", force_model, rows, setup)
    sol = fit(prob, observations_from_rows(rows), t0, t_end, FitOptions(block=4 * 3600.0))
    return sol, x_true


@pytest.mark.parametrize("stochastic", [False, True], ids=["constant", "gauss-markov"])
def test_tracking_adapter_recovers_truth(setup, stochastic):
    sol, x_true = _tracked(setup, stochastic)
    d = sol.x0 - x_true
    sig = np.sqrt(np.diag(sol.P0))
    print("iterations", len(sol.history), "errors/sigma", np.round(d / sig, 2), "sigma", sig)
    assert sol.converged
    assert d @ np.linalg.solve(sol.P0, d) < chi2.ppf(0.999, d.size)
    assert sig[6] < 0.02                                   # SRP scale learned from 0.1
    assert sol.history[-1]["postfit_rms"] == pytest.approx(1.0, abs=0.15)
