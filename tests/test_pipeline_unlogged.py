"""odpipe run on a simulated arc with an unlogged burn: the innovation test finds it, the refit estimates it.

Truth: the peers' cislunar HEO with a 6 mm/s impulsive burn nobody logged, tracked by three DSN sites
(60-s two-way Doppler at 0.1 mm/s, range every 10 min). The run must report one finding just before the
burn and, with ``estimation.detected_maneuver_sigma`` set, estimate a dV and a firing epoch within 3 sigma
of the truth; post-fit Doppler RMS back at the noise.
"""

import numpy as np
import pandas as pd
import pytest

from heo_case import simulate, tdb, write_config
from odpipe.dynamics.forces import ImpulsiveManeuver
from odpipe.pipeline.run import run_config
from bounds import max_z

START, END, BURN = "2003-06-03T00:00:00", "2003-06-04T00:00:00", "2003-06-03T14:00:30"
DV = np.array([0.004, -0.003, 0.0035])  # m/s, ICRF


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("unlogged")
    _, x_start = simulate(tmp, START, END, [ImpulsiveManeuver(tdb(BURN), DV)], seed=11)
    write_config(tmp, "unlogged", START, END, x_start, "detected_maneuver_sigma = 0.05", naif_id=-901)
    out = run_config(tmp / "arc.toml", progress=None)
    return tmp / "out" / "unlogged" / "current", out


def test_unlogged_burn_is_found_and_estimated(run):
    folder, out = run
    found = pd.read_csv(folder / "unlogged_maneuvers.csv")
    assert len(found) == 1
    burn = tdb(BURN)
    assert found["after_tdb"].iloc[0] <= burn + 1.0 and found["epoch_tdb"].iloc[0] >= burn - 1.0
    assert found["epoch_tdb"].iloc[0] - burn < 3 * 3600.0  # found within hours of the burn
    params = pd.read_csv(folder / "parameters.csv").set_index("name")
    est = params.loc[[f"SC1.detected0.dv_{a}" for a in "xyz"]]
    err = est["estimate"].to_numpy() - DV
    assert np.all(np.abs(err) < max_z(4) * est["sigma"].to_numpy()), (err, est["sigma"].to_numpy())
    dt = params.loc["SC1.detected0.dt"]  # placed mid-window (the burn's own second here), epoch estimated
    assert abs(tdb("2003-06-03T14:00:30") + dt["estimate"] - tdb(BURN)) < max_z(4) * dt["sigma"] < 60.0
    stats = pd.read_csv(folder / "residual_statistics.csv")
    dop = stats[stats["observable"] == "doppler_2way"]["postfit_rms"].to_numpy()
    assert np.all(dop < 1.3e-4), dop  # m/s: back at the 0.1 mm/s noise
    assert "Unlogged maneuvers" in (folder / "report.html").read_text()
