"""Simulated truth for the OD tests (shared scenario builders) and checks of the simulator itself.

Scenario: the peers' cislunar HEO (perigee 6878 km, apogee at lunar distance) one day
after its 2003-06-01 perigee, Earth-centred with Moon and Sun point masses, tracked by
DSS-14/43/63 above 10 deg: two-way X-band Doppler every 60 s (0.1 mm/s) and range every
600 s (1 m, 3 m bias per pass).

Truth and filter differ in SRP as in ``heo_case``: the truth flies a Sun-pointing flat plate,
the filter a cannonball with an estimated scale (truth ``TRUE_SRP_SCALE`` = 0.93).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from heo_case import CR_AREA, EPOCH0, R0, TRUE_SRP_SCALE, TRUTH_SRP, V0  # noqa: F401 (TRUE_SRP_SCALE: for the fits)
from odpipe.dynamics.forces import EmpiricalRTN, ForceModel, ImpulsiveManeuver, PointMasses, SolarRadiationPressure
from odpipe.dynamics.propagator import propagate
from odpipe.measurements import MeasurementSetup, compute
from odpipe.simulate.observe import simulate_tracking
from odpipe.simulate.schedule import TrackingPlan
from odpipe.time import utc_to_tdb
from parsers.table import validate

PERIGEE_UTC = np.datetime64(EPOCH0)
X_PERIGEE = np.r_[R0, V0]
STATIONS = ("DSS-14", "DSS-43", "DSS-63")
DV_TRUE = np.array([0.03, -0.02, 0.03])          # |dV| = 4.7 cm/s
PERTURBATION = np.array([1000.0, -800.0, 600.0, 0.01, -0.008, 0.006])   # ~1 km, ~1 cm/s


@lru_cache(maxsize=1)
def measurement_setup() -> MeasurementSetup:
    return MeasurementSetup.default()


def force_model(scale=1.0, extra=()) -> ForceModel:
    """The filter's model: point masses and a cannonball."""
    eph = measurement_setup().ephemeris
    return ForceModel("earth", [PointMasses(["moon", "sun"]), SolarRadiationPressure(cr_area=CR_AREA, scale=scale),
                                *extra], mass=500.0, ephemeris=eph)


def truth_force_model(extra=()) -> ForceModel:
    """The truth's model: point masses and the Sun-pointing plate."""
    eph = measurement_setup().ephemeris
    return ForceModel("earth", [PointMasses(["moon", "sun"]), TRUTH_SRP, *extra], mass=500.0, ephemeris=eph)


@lru_cache(maxsize=4)
def scenario(days: float = 2.0, maneuver: bool = True, stochastic_sigma: float = 0.0, seed: int = 7) -> dict:
    """Truth trajectory, its epoch state, maneuver epoch and the simulated table (cached per arguments)."""
    start_utc = PERIGEE_UTC + np.timedelta64(1, "D")
    t_per = float(utc_to_tdb(PERIGEE_UTC)[()])
    t0 = float(utc_to_tdb(start_utc)[()])
    t1 = t0 + days * 86400.0
    x0 = propagate(X_PERIGEE, t_per, t0, truth_force_model(), with_stm=False).state(t0)[0]
    t_man = t0 + 0.8 * 86400.0
    rng = np.random.default_rng(seed)
    extra = [ImpulsiveManeuver(t_man, DV_TRUE)] if maneuver else []
    batches = None
    if stochastic_sigma:
        edges = np.arange(t0, t1, 8 * 3600.0)
        batches = np.column_stack([edges, edges + 8 * 3600.0, stochastic_sigma * rng.standard_normal((edges.size, 3))])
        batches[0, 0] = t0 - 3600.0
        batches[-1, 1] = t1 + 3600.0
        extra.append(EmpiricalRTN(batches))
    fm = truth_force_model(extra)
    x_back = propagate(x0, t0, t0 - 600.0, fm, with_stm=False).state(t0 - 600.0)[0]
    truth = propagate(x_back, t0 - 600.0, t1 + 60.0, fm, with_stm=True, params=[])
    plan = TrackingPlan(STATIONS, start_utc, start_utc + np.timedelta64(int(days * 86400) - 60, "s"),
                        range_bias_sigma=3.0, spacecraft="SC")
    table, bias = simulate_tracking(truth, plan, measurement_setup(), rng)
    return dict(t0=t0, t1=t1, x0=x0, t_man=t_man, truth=truth, table=table, bias=bias, plan=plan,
                batches=batches, rng_seed=seed)


def test_simulated_table_is_a_time_ordered_tracking_table_above_the_mask():
    sc = scenario()
    table = sc["table"]
    validate(table)
    assert np.all(np.diff(table["epoch"].to_numpy().astype(np.int64)) >= 0)
    assert set(table["observable"]) == {"doppler_2way", "range"} and set(table["station_rx"]) == set(STATIONS)
    # elevation at reception, recomputed here from the station's local vertical (not the angle model)
    setup = measurement_setup()
    t = np.asarray(utc_to_tdb(table["epoch"].to_numpy()), float)
    for st in STATIONS:
        sel = (table["station_rx"] == st).to_numpy()
        node = setup.station(st)
        r_st = node.state(t[sel])[:, :3] - setup.ephemeris.state("earth", setup.origin, t[sel])[:, :3]
        los = sc["truth"].state(t[sel])[:, :3] - r_st
        up = r_st / np.linalg.norm(r_st, axis=1, keepdims=True)   # geocentric vertical: within 0.2 deg
        el = np.arcsin(np.sum(los * up, axis=1) / np.linalg.norm(los, axis=1))
        assert el.min() > np.radians(10.0 - 0.5)


def test_simulated_noise_has_the_stated_sigma():
    sc = scenario()
    table = sc["table"]
    clean = compute(table, {"SC": sc["truth"]}, measurement_setup()).value
    z = (table["value"].to_numpy() - clean) / table["sigma"].to_numpy()
    dop = (table["observable"] == "doppler_2way").to_numpy()
    assert abs(np.std(z[dop]) - 1.0) < 0.05 and abs(np.mean(z[dop])) < 0.1
    # range: noise plus one bias per pass (3 m) -> demeaned per pass has unit spread
    rng = table[~dop].assign(z=z[~dop])
    spread = rng.groupby("pass_id")["z"].transform(lambda s: s - s.mean())
    assert 0.8 < np.std(spread) < 1.1
    means = rng.groupby("pass_id")["z"].mean()
    np.testing.assert_allclose(means.to_numpy(), sc["bias"][means.index.to_numpy()], atol=1.0)


def arc_state(sc):
    """The filter's a priori: truth perturbed by ~1 km / 1 cm/s."""
    return sc["x0"] + PERTURBATION
