"""Modified Saastamoinen troposphere (odpipe.media.modified_saastamoinen) against Orekit's published values.

Outside values: Orekit's ModifiedSaastamoinenModelTest (CS-SI/Orekit, src/test/java/org/orekit/models/
earth/troposphere/): compareExpectedValues (1013.25 hPa, 18.01 degC, 50 % at 0 m with the Wang (1988)
vapour law, delays at heights 0..5000 m and elevations 10..90 deg) and testDelay / testDelayHighElevation
(its standard atmosphere, 20 degC with CIPM-2007, at 37.5 deg N, 824 m, elevations 5 and 60 deg).
"""

import numpy as np
import pytest

from odpipe.media import modified_saastamoinen as ms
from odpipe.media.model import MediaModel
from odpipe.media.saastamoinen import carried_up

# compareExpectedValues: (height m, elevation deg) -> delay m
XU_18C = {(0.0, 10.0): 13.517414068807756, (0.0, 45.0): 3.408088733958258, (0.0, 90.0): 2.4109238764096896,
          (500.0, 10.0): 12.531363728988735, (500.0, 90.0): 2.2359689784370986,
          (750.0, 30.0): 4.303522687504001}


@pytest.mark.parametrize("key", sorted(XU_18C))
def test_delay_matches_orekits_table_at_18_degrees(key):
    h, el = key
    p, t, rh = carried_up(101325.0, 273.15 + 18.01, 0.5, h)
    assert ms.slant_delay(np.radians(el), h, p, t, rh * ms.wang_saturation(t)) == pytest.approx(XU_18C[key], abs=1e-6)


def test_standard_atmosphere_delay_matches_orekit():
    # testDelay (5 deg): zenith hydrostatic 2.09133 m, zenith wet 0.049441 m, total 21.14477 m;
    # testDelayHighElevation (60 deg): total 2.47223 m
    p, t, e = ms.orekit_standard_atmosphere(824.0)
    assert 0.002277 * p * 1e-2 == pytest.approx(2.09133, abs=1e-5)
    assert 0.002277 * (1255.0 / t + 0.05) * e * 1e-2 == pytest.approx(0.049441, abs=1e-6)
    assert ms.standard_slant_delay(np.radians(5.0), 824.0) == pytest.approx(21.14477, abs=1e-5)
    assert ms.standard_slant_delay(np.radians(60.0), 824.0) == pytest.approx(2.47223, abs=1e-5)


def test_clipping_conventions():
    # below the lowest elevation and outside 0..5000 m the model holds its edge values
    assert ms.standard_slant_delay(0.001, 0.0) == pytest.approx(ms.standard_slant_delay(ms.MIN_ELEVATION, 0.0))
    assert ms.standard_slant_delay(0.3, -200.0) == pytest.approx(ms.standard_slant_delay(0.3, 0.0))
    assert ms.standard_slant_delay(0.3, 6000.0) == pytest.approx(ms.standard_slant_delay(0.3, 5000.0))


def test_media_model_selects_the_standard_troposphere():
    t = np.array(["2016-02-14T03:17:37"], dtype="datetime64[ns]")
    el, lat, h = np.radians([20.0]), np.radians(-29.0), 245.0
    d, label = MediaModel(standard_troposphere="modified-saastamoinen").troposphere("YARL", t, el, lat, h)
    assert d[0] == pytest.approx(ms.standard_slant_delay(el, h)[0]) and "modified Saastamoinen" in label[0]
    d0, label0 = MediaModel().troposphere("YARL", t, el, lat, h)
    assert label0[0] == "standard-atmosphere" and abs(d0[0] - d[0]) < 0.2    # two models of one atmosphere, 20 deg
    with pytest.raises(ValueError, match="standard troposphere"):
        MediaModel(standard_troposphere="hopfield")
