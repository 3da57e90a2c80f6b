"""The simulated run case of the pipeline tests: the peers' cislunar HEO tracked by three DSN sites.

``simulate(tmp, start, end, extra_components=(), seed=7)`` integrates the truth from the peers'
perigee state (shared/peers/bench/common.py) with Sun and Moon point masses and solar pressure on
a Sun-pointing plate (``SAIL``), simulates 60-s two-way Doppler (0.1 mm/s) and range
(1 m) with :mod:`odpipe.simulate.observe`, writes ``tracking.parquet`` and returns (truth, x_start);
``write_config(tmp, name, start, end, state, estimation_extra="", naif_id=-900)`` writes ``arc.toml``
for :func:`odpipe.pipeline.run.run_config`, whose filter flies a cannonball of ``CR_AREA`` with an
estimated scale.

The plate's own area and reflectivities, through the plate code path, make the truth differ from
the filter's model. At normal incidence a plate's force lies along the Sun line with Cr*A =
A (1 + rho_s + 2 rho_d / 3) (Montenbruck & Gill 2000, eq. 3.72): the scale the filter must find,
``TRUE_SRP_SCALE`` = 0.93, comes from that formula, not from the filter's code.
"""

from __future__ import annotations

import numpy as np

from odpipe.dynamics.forces import ForceModel, Plate, PointMasses, SolarRadiationPressure
from odpipe.dynamics.propagator import propagate
from odpipe.environment.ephemeris import Ephemeris
from odpipe.measurements import MeasurementSetup
from odpipe.simulate.observe import simulate_tracking
from odpipe.simulate.schedule import TrackingPlan
from odpipe.preprocess import store
from odpipe.time import utc_to_tdb

R0 = np.array([6252.878075666748, -360.9143112901398, 2842.206999982947]) * 1e3
V0 = np.array([-0.559937727219993, 10.347539903919273, 2.5458376452827824]) * 1e3
EPOCH0 = "2003-06-01T00:00:00"
CR_AREA = 1.3 * 5.0                                # m^2, the filter's cannonball
SAIL = Plate("sun", 4.5, rho_s=0.25, rho_d=0.15)   # m^2: the truth's Sun-pointing plate
TRUE_SRP_SCALE = SAIL.area * (1.0 + SAIL.rho_s + 2.0 * SAIL.rho_d / 3.0) / CR_AREA
TRUTH_SRP = SolarRadiationPressure(surfaces=[SAIL])


def tdb(iso: str) -> float:
    return float(utc_to_tdb(np.datetime64(iso, "ns")))


def simulate(tmp, start: str, end: str, extra_components=(), seed: int = 7):
    """Truth (values only) from ``start`` - 120 s to ``end`` + 60 s, and the truth state at ``start``."""
    eph = Ephemeris.open("de440")
    comps = [PointMasses(["sun", "moon"]), TRUTH_SRP]
    fm = ForceModel("earth", comps, 500.0, eph)
    t0, ts, te = tdb(EPOCH0), tdb(start), tdb(end)
    x_start = propagate(np.r_[R0, V0], t0, ts, fm, with_stm=False).state(ts)[0]
    x_before = propagate(x_start, ts, ts - 120.0, fm, with_stm=False).state(ts - 120.0)[0]
    flown = ForceModel("earth", comps + list(extra_components), 500.0, eph)
    truth = propagate(x_before, ts - 120.0, te + 60.0, flown, with_stm=False)
    plan = TrackingPlan(("DSS-14", "DSS-43", "DSS-63"), np.datetime64(start, "ns") + np.timedelta64(60, "s"),
                        np.datetime64(end, "ns"), spacecraft="SC1", range_bias_sigma=0.0)
    table, _ = simulate_tracking(truth, plan, MeasurementSetup.default(), np.random.default_rng(seed))
    store.write(tmp / "tracking.parquet", table)
    return truth, x_start


def write_config(tmp, name: str, start: str, end: str, state, estimation_extra: str = "", naif_id: int = -900):
    (tmp / "arc.toml").write_text(f"""
[run]
name = "{name}"
output = "out"
[arc]
spacecraft = "SC1"
start = "{start}"
end = "{end}"
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
cr_area = {CR_AREA}
[initial_state]
epoch = "{start}"
state = {list(map(float, state))}
[estimation]
sigma_position = 1000.0
sigma_velocity = 0.01
srp_scale_sigma = 0.1
data_sigma = {{ range = 1.0, doppler_2way = 1e-4 }}
range_bias_sigma = 5.0
{estimation_extra}
[products]
naif_id = {naif_id}
step = 300.0
""")
    return tmp / "arc.toml"
