"""Drag with NRLMSISE-00: the kernel's density against the model at the same geodetic point (placed with
odpipe's IERS Earth rotation), and the acceleration partials against central differences."""

import numpy as np
import pytest

from odpipe.dynamics.drag import R_EQUATOR, _space_weather_rows, nrlmsise_density
from odpipe.dynamics.forces import AtmosphericDrag, ForceModel, compile_model
from odpipe.dynamics.rhs import acceleration
from odpipe.environment.atmosphere.nrlmsise00 import gtd7
from odpipe.environment.atmosphere.space_weather import MonthlyForecast
from odpipe.environment.ephemeris import Ephemeris
from odpipe.frames.earth import itrs_to_gcrs
from odpipe.time import utc_to_tdb
from parsers.spaceweather import read_msafe

UTC = np.datetime64("2010-11-02T12:00:00", "ns")  # day 306, 43200 s UT


@pytest.fixture(scope="module")
def weather(shared_data):
    return MonthlyForecast(read_msafe(shared_data / "orekit_od" / "W3B" / "Oct2010F10.txt"))


@pytest.mark.parametrize("h_km, lon_deg", [(210.0, 30.0), (400.0, -100.0), (900.0, 170.0)])
def test_kernel_density_is_the_model_at_the_geodetic_point(weather, h_km, lon_deg):
    t = float(utc_to_tdb(UTC))
    lon = np.radians(lon_deg)
    r_itrs = (R_EQUATOR + h_km * 1e3) * np.array([np.cos(lon), np.sin(lon), 0.0])   # equator: geodetic = geocentric
    r = itrs_to_gcrs(np.array([t]))[0] @ r_itrs
    drag = AtmosphericDrag(2.0, 1.0, atmosphere="nrlmsise00", space_weather=weather)
    rho, _ = nrlmsise_density(t, r, *_space_weather_rows(drag, t - 3600.0, t + 3600.0))
    f107, f107a, ap = weather.nrlmsise_inputs(t)[0]
    d, _ = gtd7(306, 43200.0, h_km, 0.0, lon_deg, 12.0 + lon_deg / 15.0, f107a, f107, ap)
    expect = d[5] + 16 * 1.66e-27 * d[8]            # with anomalous oxygen (the model's GTD7D)
    # the kernel's longitude ignores precession-nutation (0.15 deg in 2010) and its latitude the
    # 0.2-arcsecond polar motion: a 0.01-h local-time shift
    assert rho == pytest.approx(expect, rel=2e-3)


def test_partials_vs_central_differences(weather):
    eph = Ephemeris.open("de440")
    t0 = float(utc_to_tdb(UTC))
    x = np.array([4.1e6, 4.9e6, 2.2e6, -5.8e3, 3.1e3, 3.9e3])   # about 400 km
    drag = AtmosphericDrag(2.5, 2.0, atmosphere="nrlmsise00", space_weather=weather)
    model = compile_model(ForceModel("earth", [drag], mass=1000.0, ephemeris=eph, central_gm=0.0),
                          t0, t0 + 3600.0, ["cd"], True)

    def accel(xx):
        acc, gr, gv, dp = np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((1, 3))
        acceleration(t0 + 600.0, xx[:3].copy(), xx[3:].copy(), model, acc, gr, gv, dp)
        return acc, gr, gv, dp

    acc, gr, gv, dp = accel(x)
    assert 1e-8 < np.linalg.norm(acc) < 1e-5 and np.dot(acc, x[3:]) < 0
    np.testing.assert_allclose(dp[0], acc / 2.5, rtol=1e-12)
    for j in range(3):
        e = np.zeros(6)
        e[3 + j] = 0.1
        fd = (accel(x + e)[0] - accel(x - e)[0]) / 0.2
        np.testing.assert_allclose(gv[:, j], fd, rtol=0, atol=1e-6 * np.abs(gv).max())
    # the density gradient is vertical only: along the radius, the partial is the central difference
    u = x[:3] / np.linalg.norm(x[:3])
    e = np.concatenate([u * 10.0, np.zeros(3)])
    fd = (accel(x + e)[0] - accel(x - e)[0]) / 20.0
    np.testing.assert_allclose(gr @ u, fd, rtol=0, atol=1e-3 * np.abs(fd).max())


@pytest.mark.parametrize("new, message", [
    ('atmosphere = "nrlmsise00"\n', r'\[dynamics.drag.space_weather\] atmosphere = "nrlmsise00" needs'),
    ('atmosphere = "dtm"\n', r"\[dynamics.drag.atmosphere\]"),
    ('atmosphere = "nrlmsise00"\nspace_weather = "none.txt"\n', r"\[dynamics.drag.space_weather\]"),
])
def test_drag_keys_name_the_key(tmp_path, new, message):
    from odpipe.operations.schema import ConfigError
    from odpipe.pipeline.config import load_config

    path = tmp_path / "run.toml"
    text = """[run]\nname = "x"\n[arc]\nspacecraft = "S"\nstart = "2010-11-02T00:00:00"\nend = "2010-11-02T01:00:00"
[dynamics]\ncenter = "earth"\n[dynamics.drag]\ncd = 2.0\narea = 1.0\n"""
    path.write_text(text + new)
    with pytest.raises(ConfigError, match=message):
        load_config(path)
