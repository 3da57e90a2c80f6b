"""compute() on trajectories from odpipe.dynamics.propagate: STM and sensitivity composition vs re-propagation."""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.dynamics.forces import ForceModel, PointMasses, SolarRadiationPressure
from odpipe.dynamics.propagator import propagate
from odpipe.measurements.compute import MeasurementSetup, compute
from odpipe.measurements.lighttime import anchor_from_utc
from parsers.table import build

T0 = np.datetime64("2025-03-01T00:00:00", "ns")
X0 = np.array([2.6e8, -2.2e8, 0.9e8, 450.0, 620.0, -150.0])  # lunar-distance Earth orbit


@pytest.fixture(scope="module")
def setup():
    return MeasurementSetup.default()


def _traj(setup, x0=X0, srp_scale=1.0):
    t0 = anchor_from_utc(T0)[0][0]
    fm = ForceModel("earth", [PointMasses(["moon", "sun"]), SolarRadiationPressure(cr_area=40.0, scale=srp_scale)],
                    mass=500.0, ephemeris=setup.ephemeris)
    return propagate(x0, t0 - 600.0, t0 + 6 * 3600.0, fm)


def _rows():
    n = 6
    epoch = T0 + (np.arange(n) * 3600).astype("timedelta64[s]") + np.timedelta64(1800, "s")
    obs = np.array(["range", "doppler_2way"] * 3, dtype=object)
    return build(n, epoch=epoch, observable=obs, unit=np.where(obs == "range", "RU", "Hz"), station_tx="DSS-34",
                 station_rx="DSS-34", spacecraft="A", tag=np.where(obs == "range", "receive", "interval_mid"),
                 count_time=np.where(obs == "range", 0.0, 60.0), band_up="X", band_down="X", uplink_hz=7.16e9, value=0.0)


def test_epoch_state_and_srp_partials_vs_repropagation(setup):
    rows = _rows()
    ev = compute(rows, {"A": _traj(setup)}, setup)
    assert ev.names["dynamic:A"] == ["srp_scale"]
    h = {0: 2000.0, 4: 0.5}  # large steps: dense-output noise (~1e-5 Hz) swamps small ones
    for i, step in h.items():
        dx = np.zeros(6)
        dx[i] = step
        fd = (compute(rows, {"A": _traj(setup, X0 + dx)}, setup).value
              - compute(rows, {"A": _traj(setup, X0 - dx)}, setup).value) / (2 * step)
        np.testing.assert_allclose(ev.partials["state:A"][:, i], fd, rtol=2e-4)
    fd = (compute(rows, {"A": _traj(setup, srp_scale=1.5)}, setup).value
          - compute(rows, {"A": _traj(setup, srp_scale=0.5)}, setup).value)
    np.testing.assert_allclose(ev.partials["dynamic:A"][:, 0], fd, rtol=2e-3)
    assert np.all(np.abs(fd) > 0)  # SRP over hours moves the range by a measurable amount
