"""odpipe run end to end on a simulated arc: the products agree with the truth within their covariance."""

import json
from pathlib import Path

import numpy as np
import pytest

from odpipe.dynamics.forces import ForceModel, PointMasses, SolarRadiationPressure
from odpipe.dynamics.propagator import propagate
from odpipe.environment.ephemeris import Ephemeris
from odpipe.measurements import MeasurementSetup
from odpipe.od.simulate import TrackingPlan, simulate_tracking
from odpipe.pipeline.run import run_config
from odpipe.preprocess import store
from odpipe.time import utc_to_tdb
from parsers import oem

# The peers' cislunar HEO (shared/peers/bench/common.py), two days after perigee.
R0 = np.array([6252.878075666748, -360.9143112901398, 2842.206999982947]) * 1e3
V0 = np.array([-0.559937727219993, 10.347539903919273, 2.5458376452827824]) * 1e3
EPOCH0, START, END = "2003-06-01T00:00:00", "2003-06-03T00:00:00", "2003-06-04T12:00:00"


def _tdb(iso):
    return float(utc_to_tdb(np.datetime64(iso, "ns")))


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("pipeline")
    eph = Ephemeris.open("de440")
    fm = ForceModel("earth", [PointMasses(["sun", "moon"]), SolarRadiationPressure(cr_area=1.3 * 5.0)], 500.0, eph)
    t0, ts, te = _tdb(EPOCH0), _tdb(START), _tdb(END)
    x_start = propagate(np.r_[R0, V0], t0, ts, fm, with_stm=False).state(ts)[0]
    x_before = propagate(x_start, ts, ts - 120.0, fm, with_stm=False).state(ts - 120.0)[0]
    truth = propagate(x_before, ts - 120.0, te + 60.0, fm, with_stm=False)  # values only: no partials needed
    plan = TrackingPlan(("DSS-14", "DSS-43", "DSS-63"), np.datetime64(START, "ns") + np.timedelta64(60, "s"),
                        np.datetime64(END, "ns"), spacecraft="SC1", range_bias_sigma=0.0)
    table, _ = simulate_tracking(truth, plan, MeasurementSetup.default(), np.random.default_rng(7))
    store.write(tmp / "tracking.parquet", table)
    guess = x_start + np.r_[500.0, -400.0, 300.0, 0.004, -0.003, 0.002]
    (tmp / "arc.toml").write_text(f"""
[run]
name = "sim_arc"
output = "out"
[arc]
spacecraft = "SC1"
start = "{START}"
end = "{END}"
[data]
files = ["tracking.parquet"]
[calibration]
media = false
[preprocess]
count_time = 60.0
elevation_mask_deg = 10.0
[dynamics]
center = "earth"
third_bodies = ["sun", "moon"]
mass = 500.0
[dynamics.srp]
cr_area = 6.5
[initial_state]
epoch = "{START}"
state = {list(map(float, guess))}
[estimation]
sigma_position = 1000.0
sigma_velocity = 0.01
srp_scale_sigma = 0.1
data_sigma = {{ range = 1.0, doppler_2way = 1e-4 }}
range_bias_sigma = 5.0
reweight = false
[products]
naif_id = -900
step = 300.0
""")
    out = run_config(tmp / "arc.toml", progress=None)
    return tmp, out, truth


def test_run_products_agree_with_truth_within_covariance(case):
    tmp, out, truth = case
    assert out["status"] == "complete" and out["converged"]
    run = Path(out["run"])
    for name in ("trajectory.oem", "trajectory.bsp", "residuals.parquet", "report.html", "manifest.json",
                 "residuals_postfit.png", "parameters.csv", "run.log"):
        assert (run / name).is_file(), name
    seg = oem.read(run / "trajectory.oem")[0]
    t = (seg.epochs - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(1, "s")
    err = seg.states - truth.state(t)
    cov_t = (seg.cov_epochs - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(1, "s")
    k = np.searchsorted(t, cov_t[len(cov_t) // 2])
    sig = np.sqrt(np.diag(seg.covariances[len(cov_t) // 2]))
    assert np.all(np.abs(err[k]) < 3 * sig + 1e-3), (err[k], sig)
    assert np.max(np.linalg.norm(err[:, :3], axis=1)) < 50.0  # m, from a 700-m, 5-mm/s start error
    summary = json.loads((run / "summary.json").read_text())
    rms = [v for k_, v in summary.items() if k_.startswith("postfit RMS doppler_2way")]
    assert rms and all(0.07 < v < 0.13 for v in rms)  # mm/s, the simulated 0.1 mm/s noise


def test_unchanged_arc_is_skipped_and_failed_rerun_keeps_products(case):
    tmp, out, _ = case
    assert run_config(tmp / "arc.toml", progress=None)["status"] == "skipped"
    before = (Path(out["run"]) / "manifest.json").read_text()
    text = (tmp / "arc.toml").read_text()
    bad = tmp / "arc.toml"
    bad.write_text(text.replace('files = ["tracking.parquet"]', 'files = ["tracking.parquet", "missing.odf"]'))
    try:
        with pytest.raises(Exception):
            run_config(bad, progress=None)
    finally:
        bad.write_text(text)
    assert (Path(out["run"]) / "manifest.json").read_text() == before
