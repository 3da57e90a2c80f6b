"""odpipe run on a simulated arc with an unlogged burn: the innovation test finds it, the refit estimates it.

Truth: the peers' cislunar HEO with a 6 mm/s impulsive burn nobody logged, tracked by three DSN sites
(60-s two-way Doppler at 0.1 mm/s, range every 10 min). The run must report one finding just before the
burn and, with ``estimation.detected_maneuver_sigma`` set, estimate a dV and a firing epoch within 3 sigma
of the truth; post-fit Doppler RMS back at the noise.
"""

import numpy as np
import pandas as pd
import pytest

from odpipe.dynamics.forces import ForceModel, ImpulsiveManeuver, PointMasses, SolarRadiationPressure
from odpipe.dynamics.propagator import propagate
from odpipe.environment.ephemeris import Ephemeris
from odpipe.measurements import MeasurementSetup
from odpipe.od.simulate import TrackingPlan, simulate_tracking
from odpipe.pipeline.run import run_config
from odpipe.preprocess import store
from odpipe.time import utc_to_tdb

R0 = np.array([6252.878075666748, -360.9143112901398, 2842.206999982947]) * 1e3
V0 = np.array([-0.559937727219993, 10.347539903919273, 2.5458376452827824]) * 1e3
EPOCH0, START, END, BURN = "2003-06-01T00:00:00", "2003-06-03T00:00:00", "2003-06-04T00:00:00", "2003-06-03T14:00:30"
DV = np.array([0.004, -0.003, 0.0035])  # m/s, ICRF


def _tdb(iso):
    return float(utc_to_tdb(np.datetime64(iso, "ns")))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("unlogged")
    eph = Ephemeris.open("de440")
    comps = [PointMasses(["sun", "moon"]), SolarRadiationPressure(cr_area=6.5)]
    t0, ts, te = _tdb(EPOCH0), _tdb(START), _tdb(END)
    fm = ForceModel("earth", comps, 500.0, eph)
    x_start = propagate(np.r_[R0, V0], t0, ts, fm, with_stm=False).state(ts)[0]
    burned = ForceModel("earth", comps + [ImpulsiveManeuver(_tdb(BURN), DV)], 500.0, eph)
    truth = propagate(x_start, ts, ts - 120.0, fm, with_stm=False)
    x_before = truth.state(ts - 120.0)[0]
    truth = propagate(x_before, ts - 120.0, te + 60.0, burned, with_stm=False)
    plan = TrackingPlan(("DSS-14", "DSS-43", "DSS-63"), np.datetime64(START, "ns") + np.timedelta64(60, "s"),
                        np.datetime64(END, "ns"), spacecraft="SC1", range_bias_sigma=0.0)
    table, _ = simulate_tracking(truth, plan, MeasurementSetup.default(), np.random.default_rng(11))
    store.write(tmp / "tracking.parquet", table)
    (tmp / "arc.toml").write_text(f"""
[run]
name = "unlogged"
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
state = {list(map(float, x_start))}
[estimation]
sigma_position = 1000.0
sigma_velocity = 0.01
srp_scale_sigma = 0.1
data_sigma = {{ range = 1.0, doppler_2way = 1e-4 }}
range_bias_sigma = 5.0
detected_maneuver_sigma = 0.05
[products]
naif_id = -901
step = 300.0
""")
    out = run_config(tmp / "arc.toml", progress=None)
    return tmp / "out" / "unlogged" / "current", out


def test_unlogged_burn_is_found_and_estimated(run):
    folder, out = run
    found = pd.read_csv(folder / "unlogged_maneuvers.csv")
    assert len(found) == 1
    burn = _tdb(BURN)
    assert found["after_tdb"].iloc[0] <= burn + 1.0 and found["epoch_tdb"].iloc[0] >= burn - 1.0
    assert found["epoch_tdb"].iloc[0] - burn < 3 * 3600.0  # found within hours of the burn
    params = pd.read_csv(folder / "parameters.csv").set_index("name")
    est = params.loc[[f"SC1.detected0.dv_{a}" for a in "xyz"]]
    err = est["estimate"].to_numpy() - DV
    assert np.all(np.abs(err) < 3 * est["sigma"].to_numpy()), (err, est["sigma"].to_numpy())
    dt = params.loc["SC1.detected0.dt"]  # placed mid-window (the burn's own second here), epoch estimated
    assert abs(_tdb("2003-06-03T14:00:30") + dt["estimate"] - _tdb(BURN)) < 3 * dt["sigma"] < 60.0
    stats = pd.read_csv(folder / "residual_statistics.csv")
    dop = stats[stats["observable"] == "doppler_2way"]["postfit_rms"].to_numpy()
    assert np.all(dop < 1.3e-4), dop  # m/s: back at the 0.1 mm/s noise
    assert "Unlogged maneuvers" in (folder / "report.html").read_text()
