"""Drag with NRLMSISE-00: the kernel's density against the model at the same geodetic point (placed with
odpipe's IERS Earth rotation), and the acceleration partials against central differences."""

import numpy as np
import pytest

from odpipe.dynamics.drag import R_EQUATOR, _ap_history_rows, _space_weather_rows, nrlmsise_density
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
    rho, _ = nrlmsise_density(t, r, *_space_weather_rows(drag, t - 3600.0, t + 3600.0),
                              *_ap_history_rows(drag, t - 3600.0, t + 3600.0))
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


# the 3-hourly Ap of Orekit's CSSI excerpt (fixtures/cssi, its duplicated 2020-02-21 line left out), read by
# eye from the file: 02-19 7 48 27 27 7 4 4 22; 02-20 7 15 7 4 7 4 7 18; 02-21 27 15 15 15 7 15 7 5 (daily 13).
# At 2020-02-21T19:30 UTC (the interval 18-21 h): the day's Ap 13; the interval's and three before: 7, 15, 7, 15;
# the eight 12-33 h before (02-20 15 h .. 02-21 06 h): 4 7 4 7 18 27 15 15 -> 12.125; 36-57 h before
# (02-19 09 h .. 02-20 06 h): 27 7 4 4 22 7 15 7 -> 11.625
CSSI_HISTORY_UTC = np.datetime64("2020-02-21T19:30:00", "ns")
CSSI_HISTORY = [13.0, 7.0, 15.0, 7.0, 15.0, 12.125, 11.625]


@pytest.fixture()
def cssi(tmp_path):
    from pathlib import Path

    from odpipe.environment.atmosphere.space_weather import DailyRecords
    from parsers.spaceweather import read_cssi

    lines = (Path(__file__).parent.parent / "fixtures" / "cssi" / "SpaceWeather-All-v1.2_reduced.txt").read_text()
    lines = lines.split("\n")
    path = tmp_path / "cssi.txt"
    path.write_text("\n".join(lines[:22] + lines[23:]))
    return DailyRecords(read_cssi(path))


def test_cssi_ap_history_is_the_files_3_hourly_values(cssi):
    t = float(utc_to_tdb(CSSI_HISTORY_UTC))
    assert cssi.ap_history(t)[0].tolist() == CSSI_HISTORY
    # 57 h before 2020-02-21T08:00 is before the file's first day
    with pytest.raises(ValueError, match="cssi.txt"):
        cssi.ap_history(float(utc_to_tdb(np.datetime64("2020-02-21T08:00:00", "ns"))))


def test_msafe_ap_history_is_seven_copies_of_its_ap(weather):
    t = float(utc_to_tdb(UTC))
    assert weather.ap_history(t)[0].tolist() == [weather.nrlmsise_inputs(t)[0, 2]] * 7


def test_mass_density_with_the_published_ap_array_case():
    from odpipe.environment.atmosphere.nrlmsise00 import mass_density

    # the model distribution's test cases 1 (daily Ap 4) and 16 (Ap array, all seven 100, switch 9 = -1):
    # 400 km, doy 172, 29000 s, 60 N, 70 W, 16 h, F10.7 = F10.7A = 150; printed mass density (g/cm^3,
    # anomalous O left out) and anomalous O (cm^-3), the drag density adding the latter at 16 u
    x = np.array([172.0, 29000.0, 60.0, -70.0, 16.0, 150.0, 150.0, 4.0])
    amu_g = 1.66e-24
    for aph, printed, anomalous in ((np.full(7, np.nan), 4.074714e-15, 2.667273e4),
                                    (np.full(7, 100.0), 5.881940e-15, 2.667273e4)):
        expect = (printed + 16 * amu_g * anomalous) * 1e3
        assert mass_density(x, 400.0, aph) == pytest.approx(expect, rel=1e-6)


def test_kernel_density_with_the_cssi_ap_history(cssi):
    t = float(utc_to_tdb(CSSI_HISTORY_UTC))   # day 52, 70200 s UT
    r_itrs = (R_EQUATOR + 300e3) * np.array([1.0, 0.0, 0.0])
    r = itrs_to_gcrs(np.array([t]))[0] @ r_itrs
    drag = AtmosphericDrag(2.0, 1.0, atmosphere="nrlmsise00", space_weather=cssi, ap_history=True)
    rho, _ = nrlmsise_density(t, r, *_space_weather_rows(drag, t - 3600.0, t + 3600.0),
                              *_ap_history_rows(drag, t - 3600.0, t + 3600.0))
    f107, f107a, ap = cssi.nrlmsise_inputs(t)[0]
    switches = np.ones(24)
    switches[9] = -1.0
    d, _ = gtd7(52, 70200.0, 300.0, 0.0, 0.0, 70200.0 / 3600.0, f107a, f107, ap, ap_history=CSSI_HISTORY,
                switches=switches)
    daily, _ = gtd7(52, 70200.0, 300.0, 0.0, 0.0, 70200.0 / 3600.0, f107a, f107, ap)
    expect = d[5] + 16 * 1.66e-27 * d[8]
    assert rho == pytest.approx(expect, rel=2e-3)     # as above: the kernel's 0.01-h local-time shift
    assert abs(expect / (daily[5] + 16 * 1.66e-27 * daily[8]) - 1.0) > 1e-2   # and the history matters here
