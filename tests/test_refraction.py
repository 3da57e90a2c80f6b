"""Elevation refraction (ITU-R P.834-7 reference atmosphere) against Orekit's EarthITU453AtmosphereRefraction
test values and the refraction table Orekit checks it with (Thomas & Joseph, Johns Hopkins APL Technical
Digest 17(3), 1996: refraction in arcminutes at sea level, within 2.1 arcmin)."""

import numpy as np
import pytest

from odpipe.measurements import MeasurementSetup, compute
from odpipe.measurements.refraction import minimal_elevation, refraction
from parsers.table import build

TABLE_DEG = [0.00, 0.25, 0.50, 0.75, 1.00, 1.25, 1.50, 1.75, 2.00, 2.25, 2.50, 2.75, 3.00, 4.50, 5.00, 6.00, 7.00,
             8.00, 9.00, 10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0, 17.0, 18.0, 19.0, 20.0, 25.0, 30.0, 35.0, 50.0,
             55.0, 60.0, 65.0, 70.0, 80.0, 90.0]
TABLE_ARCMIN = [34.5, 31.4, 28.7, 26.4, 24.3, 22.5, 20.9, 19.5, 18.3, 17.2, 16.1, 15.2, 14.4, 10.7, 9.90, 8.50,
                7.40, 6.60, 5.90, 5.30, 4.90, 4.50, 4.10, 3.80, 3.60, 3.30, 3.10, 2.90, 2.80, 2.60, 2.10, 1.70,
                1.40, 0.80, 0.70, 0.60, 0.50, 0.40, 0.20, 0.00]
KIRUNA_M = 385.8


def deg(elevation_deg, height_m):
    return np.degrees(refraction(np.radians(elevation_deg), height_m)[0])


@pytest.mark.parametrize("height_m, elevation_deg, expected_deg, tol", [
    (8848.0, 2.0, 0.11458177523385392, 1e-12),     # Everest
    (-422.0, 2.0, 0.3550620274090111, 1e-12),      # Dead Sea
    (KIRUNA_M, 2.0, 0.32, 0.01),
    (KIRUNA_M, 4.0, 0.21, 0.01),
    (KIRUNA_M, 10.0, 0.10, 0.02),
    (KIRUNA_M, 30.0, 0.02, 0.01),
    (KIRUNA_M, 90.0, 0.002, 0.001),
    (1415.821, -10.0, 1.7367073234643113, 1e-3),   # Hartebeesthoek, below the horizon: held
])
def test_orekit_values(height_m, elevation_deg, expected_deg, tol):
    assert deg(elevation_deg, height_m) == pytest.approx(expected_deg, abs=tol)


def test_minimal_elevation_and_the_sea_level_table():
    assert np.degrees(minimal_elevation(KIRUNA_M)) == pytest.approx(-0.5402509318003884, abs=1e-12)
    assert np.abs(60 * deg(np.array(TABLE_DEG), 0.0) - TABLE_ARCMIN).max() < 2.1


def test_slope_is_the_derivative_and_zero_where_held():
    e = np.radians(np.array([1.0, 5.0, 20.0, 60.0]))
    h = 1e-7
    fd = (refraction(e + h, 500.0)[0] - refraction(e - h, 500.0)[0]) / (2 * h)
    assert refraction(e, 500.0)[1] == pytest.approx(fd, rel=1e-6)
    tau, slope = refraction(np.radians([-3.0, -5.0]), 500.0)
    assert tau[0] == tau[1] and (slope == 0).all()


def test_compute_bends_elevation_rows_only_when_asked():
    from odpipe.dynamics.forces import ForceModel, PointMasses
    from odpipe.dynamics.propagator import propagate
    from odpipe.environment.ephemeris import Ephemeris
    from tests.heo_case import EPOCH0, R0, V0, tdb

    t0 = tdb(EPOCH0)
    truth = propagate(np.r_[R0, V0], t0, t0 + 7200.0, ForceModel("earth", [PointMasses(["sun", "moon"])], 500.0,
                                                                Ephemeris.open("de440")), with_stm=False)
    ep = np.datetime64(EPOCH0, "ns") + np.arange(300, 7000, 600).astype("timedelta64[s]")
    rows = build(2 * ep.size, epoch=np.r_[ep, ep], observable=np.repeat(["angle_el", "angle_az"], ep.size),
                 unit="rad", station_tx="DSS-14", station_rx="DSS-14", spacecraft="SC1", tag="receive",
                 count_time=0.0, flags=0, value=0.0, pass_id=0)
    plain = compute(rows, {"SC1": truth}, MeasurementSetup.default())
    bent = compute(rows, {"SC1": truth}, MeasurementSetup.default(elevation_refraction=True))
    el = plain.value[:ep.size]
    assert (el > np.radians(2)).sum() >= 5
    height = MeasurementSetup.default().stations["DSS-14"].geodetic()[2]
    tau, slope = refraction(el, height)
    assert bent.value[:ep.size] - el == pytest.approx(tau, abs=1e-15)
    assert bent.value[ep.size:] == pytest.approx(plain.value[ep.size:], abs=0)          # azimuth untouched
    p0, p1 = plain.partials["station:DSS-14"][:ep.size], bent.partials["station:DSS-14"][:ep.size]
    assert p1 == pytest.approx(p0 * (1 + slope)[:, None], rel=1e-12, abs=1e-20)
