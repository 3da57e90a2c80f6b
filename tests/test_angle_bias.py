"""Angle biases estimated as angles and angle sigmas given in angle units (issue 22).

A simulated HEO (the pipeline tests' cislunar orbit: perigee 6,900 km from the geocentre) tracked by
DSS-14 and DSS-43 in range (1 m) and azimuth/elevation (0.01 deg). DSS-14's azimuth carries a known
+0.05 deg bias. Fitted after perigee (station ranges a few thousand to 40,000 km) and a day later
(200,000 km), the bias comes back the same in radians within its formal sigma in both, and the angle
residuals match the stated 0.01 deg: a bias along the line of sight in metres (the old model) could not
be one number over such a change of range.
"""

import numpy as np
import pandas as pd
import pytest
from scipy.stats import chi2

from odpipe.dynamics.forces import ForceModel, PointMasses
from odpipe.dynamics.propagator import propagate
from odpipe.environment.ephemeris import Ephemeris
from odpipe.measurements import MeasurementSetup, compute
from odpipe.od.arc import ArcSetup, data_sigma, fit_arc
from odpipe.simulate.schedule import TrackingPlan, visible_epochs
from parsers.table import build
from tests.heo_case import EPOCH0, R0, V0, tdb

BIAS = np.radians(0.05)
SIGMA = np.radians(0.01)
STATIONS = ("DSS-14", "DSS-43")


@pytest.fixture(scope="module")
def heo():
    eph = Ephemeris.open("de440")
    fm = ForceModel("earth", [PointMasses(["sun", "moon"])], 500.0, eph)
    t0 = tdb(EPOCH0)
    truth = propagate(np.r_[R0, V0], t0, t0 + 30 * 3600.0, fm, with_stm=False)
    return truth, fm, MeasurementSetup.default()


def _tracking(truth, setup, start, end, rng):
    plan = TrackingPlan(STATIONS, np.datetime64(start, "ns"), np.datetime64(end, "ns"), doppler_step=120.0,
                        spacecraft="SC1")
    parts = []
    for st, (epochs, ids) in visible_epochs(truth, plan, setup).items():
        up = ids >= 0
        for obs, unit in (("angle_az", "rad"), ("angle_el", "rad"), ("range", "m")):
            parts.append(build(int(up.sum()), epoch=epochs[up], observable=obs, unit=unit, station_tx=st,
                               station_rx=st, spacecraft="SC1", tag="receive", count_time=0.0, band_up="X",
                               band_down="X", uplink_hz=7.16e9, ramped=False, pass_id=ids[up], flags=0,
                               value=0.0))
    table = pd.concat(parts, ignore_index=True).sort_values("epoch", kind="stable").reset_index(drop=True)
    ev = compute(table, {"SC1": truth}, setup)
    angle = (table["unit"] == "rad").to_numpy()
    biased = ((table["observable"] == "angle_az") & (table["station_rx"] == "DSS-14")).to_numpy()
    table["value"] = ev.value + np.where(angle, SIGMA, 1.0) * rng.standard_normal(len(table)) + biased * BIAS
    return table, ev.to_los


@pytest.mark.parametrize("start, end, ranges_km", [
    ("2003-06-01T00:05:00", "2003-06-01T02:00:00", (1_000, 40_000)),     # after perigee
    ("2003-06-02T00:30:00", "2003-06-02T04:30:00", (190_000, 230_000)),  # near apogee
])
def test_azimuth_bias_comes_back_in_radians_at_low_and_high_range(heo, start, end, ranges_km):
    truth, fm, setup = heo
    rng = np.random.default_rng(22)
    table, rho = _tracking(truth, setup, start, end, rng)
    az14 = (table["observable"] == "angle_az") & (table["station_rx"] == "DSS-14")
    assert az14.sum() >= 20
    assert ranges_km[0] * 1e3 < rho[az14].min() and rho[az14].max() < ranges_km[1] * 1e3
    t0, t1 = tdb(start), tdb(end)
    x0 = truth.state(np.array([t0]))[0]
    arc = ArcSetup("SC1", t0, t1, x0 + np.r_[300.0, -300.0, 300.0, 0.03, -0.03, 0.03], fm, setup,
                   sigma_position=10e3, sigma_velocity=1.0, srp_scale_sigma=None, range_bias_sigma=None,
                   angle_bias_sigma=np.radians(0.5), growing_days=None, edit_k=(np.inf,),
                   data_sigma={"range": 1.0, "angle_az": "0.01 deg", "angle_el": "36 arcsec"})
    sol = fit_arc(table, arc)
    assert sol.converged
    p = sol.parameters.set_index("name")
    est = p.loc["bias.angle_az.DSS-14"]
    assert ((est["estimate"] - BIAS) / est["sigma"]) ** 2 < chi2.ppf(0.999, 1)
    assert est["sigma"] < BIAS / 5                                           # rad, well determined
    for name in p.index[p.index.str.startswith("bias.") & (p.index != "bias.angle_az.DSS-14")]:
        assert (p.loc[name, "estimate"] / p.loc[name, "sigma"]) ** 2 < chi2.ppf(0.999, 1)
    # post-fit angle residuals in rad match the 0.01 deg given (chi-square bounds on their mean square)
    r = sol.residuals[sol.residuals["observable"].str.startswith("angle_")]
    n = len(r)
    ms = np.mean((r["postfit"] / SIGMA) ** 2)
    assert chi2.ppf(0.001, n) / n < ms < chi2.ppf(0.999, n) / n


def test_angle_sigmas_carry_their_unit():
    rows = pd.DataFrame({"observable": ["angle_az", "angle_el", "range", "angle_az"],
                         "station_rx": ["A", "A", "A", "B"]})
    got = data_sigma(rows, {"angle_az": "0.01 deg", "angle_el": "36 arcsec", "range": 2.0, "angle_az:B": 1e-4})
    assert got == pytest.approx([np.radians(0.01), np.radians(0.01), 2.0, 1e-4], rel=1e-12)
    with pytest.raises(ValueError, match=r"data_sigma.range: '2 m' is not a number \(only angle observables"):
        data_sigma(rows, {"range": "2 m"})
    with pytest.raises(ValueError, match=r"data_sigma.angle_az: '0.01 degrees' is not an angle with its unit, one of"):
        data_sigma(rows, {"angle_az": "0.01 degrees"})


def test_run_config_takes_angle_sigmas_with_units(tmp_path):
    from odpipe.pipeline.config import load_config
    from odpipe.operations.schema import ConfigError
    from tests.heo_case import write_config

    from odpipe.preprocess import store

    store.write(tmp_path / "tracking.parquet", build(1, epoch=np.datetime64("2003-06-01T01:00", "ns"),
                                                     observable="angle_az", unit="rad", value=0.0))
    write_config(tmp_path, "angles", "2003-06-01T00:05:00", "2003-06-01T02:00:00", np.r_[R0, V0])
    text = (tmp_path / "arc.toml").read_text()
    good = 'data_sigma = { range = 1.0, angle_az = "0.01 deg", angle_el = 1.7e-4 }'
    (tmp_path / "arc.toml").write_text(text.replace("data_sigma = { range = 1.0, doppler_2way = 1e-4 }", good))
    assert load_config(tmp_path / "arc.toml").estimation.data_sigma["angle_az"] == "0.01 deg"
    (tmp_path / "arc.toml").write_text(text.replace("data_sigma = { range = 1.0, doppler_2way = 1e-4 }",
                                                    'data_sigma = { range = "1 m" }'))
    with pytest.raises(ConfigError, match=r"arc.toml:\d+: \[estimation\.data_sigma\.range\] '1 m' is not a number"):
        load_config(tmp_path / "arc.toml")


def test_azimuth_residuals_across_north_are_small():
    from types import SimpleNamespace

    from odpipe.measurements import residuals

    rows = pd.DataFrame({"observable": ["angle_az", "angle_az", "angle_el"], "value": np.radians([0.1, 359.9, 0.1])})
    res, los = residuals(rows, SimpleNamespace(value=np.radians([359.9, 0.1, 359.9]), to_los=2.0))
    assert np.degrees(res) == pytest.approx([0.2, -0.2, -359.8], abs=1e-9)
    assert los == pytest.approx(2 * res)
