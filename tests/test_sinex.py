"""SINEX reader: SLRF2014 positions/velocities and the ILRS eccentricities of Orekit's LAGEOS-2 case, against
their raw text, the files' own approximate coordinates and Orekit's station set-up."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from odpipe.environment.stations import StationCatalog, itrs_to_geodetic
from parsers import formats, sinex
from parsers.errors import ParseError

SLRF = Path("orekit_od/Lageos2/SLRF2014_POS+VEL_2030.0_200428.snx")
ECC = Path("orekit_od/Lageos2/ecc_une.snx")
AT = "2016-02-13T16:00"   # the orbit epoch of Orekit's od_test_Lageos2.in


@pytest.fixture(scope="module")
def slrf(shared_data):
    return sinex.read(shared_data / SLRF)


@pytest.mark.realdata
def test_blocks_and_a_station_from_the_raw_text(shared_data, slrf):
    assert formats.detect(shared_data / SLRF) == "parsers.sinex" == formats.detect(shared_data / ECC)
    assert len(slrf.report) == 0 and slrf.header.startswith("%=SNX 2.01 JCT")
    assert {k: len(v) for k, v in slrf.blocks.items()} == \
        {"SITE/ID": 475, "SOLUTION/EPOCHS": 223, "SOLUTION/ESTIMATE": 1338}   # header: 01338 estimates
    st = slrf.stations(AT).set_index("code")
    r = st.loc["7090"]
    # lines 1028-1033: STAX 7090 A 1 10:001:00000 m 2 -.238900753398029E+07 0.51901E-03, STAY ..., VELZ ...
    assert (r["x_m"], r["y_m"], r["z_m"]) == (-2389007.53398029, 5043329.44749889, -3078524.22322662)
    assert (r["vx_m_per_yr"], r["vy_m_per_yr"], r["vz_m_per_yr"]) == \
        (-0.0468389138240797, 0.00839461295243685, 0.0509471988578335)
    assert r["sigma_x_m"] == 0.00051901 and r["ref_epoch"] == np.datetime64("2010-01-01", "ns")
    # SOLUTION/EPOCHS 7090 A 1 C 83:011:58876 30:000:00000 99:007:13417; SITE/ID: Yarragadee MOBLAS-5, 50107M001
    assert r["start"] == np.datetime64("1983-01-11T16:21:16", "ns") and r["domes"] == "50107M001"
    assert r["description"] == "Yarragadee MOBLAS-5"
    assert set(["7090", "7119", "7825", "7941"]) <= set(st.index)


@pytest.mark.realdata
def test_solution_chosen_by_data_span(slrf):
    # 1868 (Komsomolsk) has solution 1 for 95:024..03:157 and solution 2 from 03:279 on
    assert slrf.stations("2000-01-01").set_index("code").loc["1868", "soln"] == "1"
    assert slrf.stations(AT).set_index("code").loc["1868", "soln"] == "2"
    assert "1868" not in set(slrf.stations("2003-08-01")["code"])           # between the two spans
    assert len(slrf.stations()) == 223                                       # every site x solution


@pytest.mark.realdata
def test_positions_agree_with_the_approximate_coordinates_and_orekit(slrf):
    st = slrf.stations(AT).set_index("code")
    site = slrf.block("SITE/ID").drop_duplicates("code").set_index("code")
    for code in ("7090", "7825", "7941"):  # (7119's approximate latitude is 124 m north of its marker)
        lat, lon, h = itrs_to_geodetic(st.loc[code, ["x_m", "y_m", "z_m"]].to_numpy(float))
        # SITE/ID approximate longitude (0..360 east) and latitude are given to 0.1 arcsec (3 m)
        assert np.degrees(lat) == pytest.approx(site.loc[code, "lat_deg"], abs=0.1 / 3600 + 1e-9)
        assert np.degrees(lon) % 360 == pytest.approx(site.loc[code, "lon_deg"], abs=0.2 / 3600)
        assert h == pytest.approx(site.loc[code, "height_m"], abs=15.0)
    # Orekit's od_test_Lageos2.in places 7825 (Mount Stromlo) at -35.316140, 149.009881 deg, 804.975 m (WGS84):
    # the SLRF2014 marker at its 2010.0 reference epoch, to the 1e-6 deg and 1 mm it writes
    lat, lon, h = itrs_to_geodetic(st.loc["7825", ["x_m", "y_m", "z_m"]].to_numpy(float))
    assert np.degrees(lat) == pytest.approx(-35.316140, abs=1e-6)
    assert np.degrees(lon) == pytest.approx(149.009881, abs=1e-6)
    assert h == pytest.approx(804.975, abs=1e-3)


@pytest.mark.realdata
def test_eccentricities_from_the_raw_text(shared_data):
    ecc = sinex.read(shared_data / ECC)
    assert len(ecc.report) == 0 and len(ecc.block("SITE/ECCENTRICITY")) == 549
    # 7090  A    1 L 14:080:00000 00:000:00000 UNE   3.1827  -0.0064   0.0194        70900513
    e = ecc.eccentricity("7090", AT)
    assert (e["up_m"], e["north_m"], e["east_m"], e["line"]) == (3.1827, -0.0064, 0.0194, 905)
    assert e["start"] == np.datetime64("2014-03-21", "ns") and pd.isna(e["end"])
    # earlier survey: 07:151:00000 10:195:86399 UNE 3.1823 -0.0062 0.0190
    assert ecc.eccentricity("7090", "2009-01-01")["up_m"] == 3.1823
    # columns running together: 7322 A 1 L 95:305:00000 96:091:86399 UNE  -4.1810 -51.5480-118.8670
    e = ecc.eccentricity("7322", "1995-12-01")
    assert (e["up_m"], e["north_m"], e["east_m"]) == (-4.1810, -51.5480, -118.8670)
    assert ecc.eccentricity("7090", "1970-01-01") is None


@pytest.mark.realdata
def test_catalog_with_sinex_moves_markers_by_their_eccentricity(shared_data):
    cat = StationCatalog.default().with_sinex(shared_data / SLRF, AT, eccentricities=shared_data / ECC)
    bare = StationCatalog.default().with_sinex(shared_data / SLRF, AT)
    assert "DSS-14" in cat and cat["7090"].epoch_year == 2010.0
    lat0, lon0, h0 = itrs_to_geodetic(bare["7090"].r_itrs)
    lat1, lon1, h1 = itrs_to_geodetic(cat["7090"].r_itrs)
    assert h1 - h0 == pytest.approx(3.1827, abs=1e-6)                        # up
    assert (lat1 - lat0) * 6_378_137 == pytest.approx(-0.0064, abs=2e-4)     # north, m (sphere to 1e-3 relative)
    t = np.array([np.datetime64("2016-02-13T16:00", "ns")])
    years = 6.0 + (31 + 12 + 16 / 24) / 365                                  # 2010.0 -> 2016-02-13T16:00
    moved = bare["7090"].position_itrs(t)[0] - bare["7090"].r_itrs
    assert moved == pytest.approx(years * np.array([-0.0468389138240797, 0.00839461295243685, 0.0509471988578335]),
                                  abs=1e-4)


def _copy(shared_data, tmp_path, name, line_no, new_text=None, cut=None):
    lines = (shared_data / name).read_text(encoding="latin-1").splitlines()
    if new_text is not None:
        lines[line_no - 1] = new_text
    if cut is not None:
        lines = lines[:cut]
    p = tmp_path / "bad.snx"
    p.write_text("\n".join(lines) + "\n", encoding="latin-1")
    return p


@pytest.mark.realdata
def test_corrupted_copies_name_file_and_line(shared_data, tmp_path):
    good = (shared_data / SLRF).read_text(encoding="latin-1").split("\n")[1027]
    bad = _copy(shared_data, tmp_path, SLRF, 1028, good.replace("-.238900753398029E+07", "-.2389007533x8029E+07"))
    with pytest.raises(ParseError, match=r"line 1028, record SOLUTION/ESTIMATE: .*value \(columns 47-68\).*number"):
        sinex.read(bad)
    d = sinex.read(bad, errors="report")
    assert [e.line for e in d.report] == [1028] and len(d.block("SOLUTION/ESTIMATE")) == 1337
    bad = _copy(shared_data, tmp_path, SLRF, 1028, good.replace("10:001:00000", "10:0x1:00000"))
    with pytest.raises(ParseError, match=r"line 1028.*ref_epoch.*YY:DDD:SSSSS"):
        sinex.read(bad)
    with pytest.raises(ParseError, match=r"line 1200: no %ENDSNX line: the file is truncated"):
        sinex.read(_copy(shared_data, tmp_path, SLRF, 0, cut=1200))
    with pytest.raises(ParseError, match=r"line 1: not a SINEX file"):
        sinex.read(_copy(shared_data, tmp_path, SLRF, 1, "%=XYZ"))
    with pytest.raises(ParseError, match=r"line 2162: -SOLUTION/ESTIMATE closes no open block"):
        sinex.read(_copy(shared_data, tmp_path, SLRF, 822, "*+SOLUTION/ESTIMATE"))


@pytest.mark.realdata
def test_inspect_describes_a_sinex_file(shared_data, capsys):
    from odpipe.cli import main

    assert main(["inspect", str(shared_data / SLRF)]) == 0
    out = capsys.readouterr().out
    assert "format: parsers.sinex" in out and "SOLUTION/ESTIMATE: 1338 lines" in out and "unreadable lines: 0" in out
