"""Ocean loading from BLQ coefficients against the IERS HARDISP test case, and the BLQ reader on real files."""

from pathlib import Path

import numpy as np
import pytest

from odpipe.environment.ocean_loading import loading_up_west_south, ocean_loading_displacement
from odpipe.environment.stations import enu_matrix, geodetic_to_itrs
from parsers import blq
from parsers.errors import ParseError

GNSS_BLQ = Path("orekit_od/february-2016/gnss.blq")  # below the shared data folder

# ONSALA, CSR4.0, as listed in the IERS Conventions' HARDISP.F test case (amplitudes m, phases deg)
ONSALA_BLQ = """$$ Onsala, CSR4.0 (IERS HARDISP test case)
  ONSALA
  .00352 .00123 .00080 .00032 .00187 .00112 .00063 .00003 .00082 .00044 .00037
  .00144 .00035 .00035 .00008 .00053 .00049 .00018 .00009 .00012 .00005 .00006
  .00086 .00023 .00023 .00006 .00029 .00028 .00010 .00007 .00004 .00002 .00001
   -64.7  -52.0  -96.2  -55.2  -58.8 -151.4  -65.6 -138.1    8.4    5.2    2.1
    85.5  114.5   56.5  113.6   99.4   19.1   94.1  -10.4 -167.4 -170.0 -177.7
   109.5  147.0   92.7  148.8   50.5  -55.1   36.4 -170.4  -15.0    2.3    5.2
"""
# HARDISP 2009 6 25 0 0 0 24 3600: dU, dS, dW (m), hourly from 2009-06-25T00:00 UTC
HARDISP_ONSALA = np.array([
    (0.003513, -0.001893, -0.001513), (0.003248, -0.001620, -0.001012), (0.002079, -0.001068, -0.000319),
    (0.000498, -0.000374, 0.000328), (-0.000913, 0.000298, 0.000712), (-0.001639, 0.000800, 0.000695),
    (-0.001369, 0.001032, 0.000254), (-0.000084, 0.000966, -0.000510), (0.001935, 0.000654, -0.001401),
    (0.004177, 0.000208, -0.002171), (0.006027, -0.000226, -0.002591), (0.006926, -0.000510, -0.002503),
    (0.006519, -0.000548, -0.001871), (0.004749, -0.000313, -0.000786), (0.001883, 0.000147, 0.000549),
    (-0.001543, 0.000717, 0.001864), (-0.004850, 0.001247, 0.002889), (-0.007370, 0.001590, 0.003416),
    (-0.008606, 0.001637, 0.003347), (-0.008344, 0.001347, 0.002718), (-0.006702, 0.000762, 0.001686),
    (-0.004090, -0.000009, 0.000492), (-0.001113, -0.000808, -0.000600), (0.001583, -0.001469, -0.001366)])
HOURS = np.datetime64("2009-06-25T00:00:00", "ns") + np.arange(24) * np.timedelta64(3600, "s")


@pytest.fixture
def onsala(tmp_path):
    p = tmp_path / "onsala.blq"
    p.write_text(ONSALA_BLQ)
    return blq.read(p)["ONSALA"]


def test_eleven_constituents_follow_hardisp_onsala(onsala):
    """11 main tides with nodal factors vs HARDISP's 342-constituent admittance spline: the lines left out
    (a few % of each band) make the difference; measured 0.26/0.12/0.08 mm rms up/west/south, 0.46 mm max
    on a 8.6 mm radial signal (0.64 mm max without the nodal factors, 8 mm with a diurnal phase convention wrong)."""
    uws = loading_up_west_south(onsala, HOURS)
    ref = HARDISP_ONSALA[:, [0, 2, 1]]                         # up, west, south
    err = uws - ref
    assert np.sqrt(np.mean(err**2)) < 0.3e-3
    assert np.max(np.abs(err)) < 0.6e-3
    assert np.corrcoef(uws[:, 0], ref[:, 0])[0, 1] > 0.99


def test_displacement_turned_to_itrs(onsala):
    """Up, west and south land on the local vertical, -east and -north of the site."""
    lat, lon = np.radians(57.3958), np.radians(11.9264)
    r = geodetic_to_itrs(lat, lon, 0.0)
    d = ocean_loading_displacement(onsala, r, HOURS)
    enu = np.einsum("ij,nj->ni", enu_matrix(lat, lon), d)
    uws = loading_up_west_south(onsala, HOURS)
    np.testing.assert_allclose(enu, np.stack([-uws[:, 1], -uws[:, 2], uws[:, 0]], -1), atol=1e-12)


def test_reads_orekit_gnss_blq(shared_data):
    sites = blq.read(shared_data / GNSS_BLQ)
    assert len(sites) == 15 and set(sites) >= {"SHLD/C1", "SBCH/P2"}
    s = sites["SHLD/C1"]
    assert s.amplitude_m[0, 0] == 0.00558 and s.amplitude_m[2, 10] == 0.00003
    assert s.phase_deg[0, 0] == 75.9 and s.phase_deg[2, 10] == 5.8


def test_bad_coefficient_line_named(tmp_path):
    p = tmp_path / "bad.blq"
    p.write_text(ONSALA_BLQ.replace(" .00086 .00023", " .00086 x.0023"))
    with pytest.raises(ParseError, match=r"bad.blq, line 5: .*non-numeric"):
        blq.read(p)
    p.write_text(ONSALA_BLQ.rsplit("\n", 2)[0] + "\n")
    with pytest.raises(ParseError, match=r"line 2: site .ONSALA. has 5 coefficient lines"):
        blq.read(p)
