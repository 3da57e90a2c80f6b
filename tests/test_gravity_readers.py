"""Gravity-field readers against published coefficients and across formats."""

import numpy as np
import pytest

from odpipe.environment.gravity import read_gravity
from parsers import ParseError

pytestmark = pytest.mark.realdata

YEAR_S = 365.25 * 86400.0


def test_egm96_cof_published_values(shared_data):
    g = read_gravity(shared_data / "gravity/gmat/EGM96.cof")
    # EGM96 (Lemoine et al. 1998, NASA/TP-1998-206861): normalized C20, C22, S22, GM, a.
    assert g.max_degree == 360
    assert g.C[2, 0] == -4.84165371736e-4
    assert g.C[2, 2] == 2.43914352398e-6 and g.S[2, 2] == -1.40016683654e-6
    assert g.gm == 3.986004415e14 and g.radius == 6378136.3


def test_egm_format_matches_cof_of_same_model(shared_data):
    cof = read_gravity(shared_data / "gravity/gmat/EGM96.cof").truncated(21)
    egm = read_gravity(shared_data / "gravity/orekit/EGM96-truncated-21x21")
    gz = read_gravity(shared_data / "gravity/orekit/egm96_to5.ascii.gz")
    np.testing.assert_allclose(egm.C, cof.C, rtol=0, atol=1e-20)
    np.testing.assert_allclose(egm.S, cof.S, rtol=0, atol=1e-20)
    present = np.ones((6, 6), bool)
    present[5, 3] = False  # the (5, 3) record is absent from that file: read as zero
    np.testing.assert_array_equal(gz.C[present], egm.C[:6, :6][present])
    assert gz.C[5, 3] == 0.0


def test_jgm3_j2_and_gzip(shared_data):
    g = read_gravity(shared_data / "gravity/gmat/JGM3.cof")
    # JGM-3 (Tapley et al. 1996; Vallado, Fundamentals of Astrodynamics, App. D): J2 = 1.0826269e-3.
    assert g.jn(2) == pytest.approx(1.0826269e-3, rel=3e-7)
    gz = read_gravity(shared_data / "gravity/nyx/JGM3.cof.gz")
    np.testing.assert_array_equal(gz.C, g.C)
    np.testing.assert_array_equal(gz.S, g.S)


def test_lunar_fields(shared_data):
    lp = read_gravity(shared_data / "gravity/gmat/LP165P.cof")
    # LP165P (Konopliv et al. 2001): GM 4902.801056 km^3/s^2, R 1738 km, J2 ~ 2.0323e-4, C22 ~ 2.24e-5.
    assert lp.max_degree == 165 and lp.gm == 4.902801056e12 and lp.radius == 1.738e6
    assert lp.jn(2) == pytest.approx(2.0323e-4, rel=2e-4)
    c22_unnorm = lp.C[2, 2] * np.sqrt(5 * 2 / 24)
    assert c22_unnorm == pytest.approx(2.24e-5, rel=3e-3)
    for name in ("tudat/lpe200.txt", "tudat/glgm3150.txt", "orekit/GrazLGM300c.truncated"):
        g = read_gravity(shared_data / "gravity" / name)
        assert g.jn(2) == pytest.approx(lp.jn(2), rel=1e-3), name
    assert read_gravity(shared_data / "gravity/tudat/lpe200.txt").max_degree == 200


def test_icgem_fortran_d_exponents(shared_data):
    g = read_gravity(shared_data / "gravity/brahe/GGM05S.gfc")
    assert g.max_degree == 180 and g.tide_system == "zero_tide"
    assert g.C[2, 0] == -4.841694573200e-4  # 'D' exponent in the file
    ggm02 = read_gravity(shared_data / "gravity/tudat/ggm02c.txt")
    assert ggm02.max_degree == 200
    assert abs(ggm02.C[2, 0] - g.C[2, 0]) < 1e-10  # two GRACE fields agree on C20


def test_icgem_time_variable_terms(shared_data):
    path = shared_data / "gravity/orekit/eigen-6s-truncated"
    with pytest.raises(ParseError, match="give an epoch"):
        read_gravity(path)
    # gfct t0 = 2005-01-01; periodic terms have 1 and 0.5 year periods, so one
    # year later only the trend (trnd record of C20 in the file) has changed.
    t0 = (np.datetime64("2005-01-01") - np.datetime64("2000-01-01T12:00")) / np.timedelta64(1, "s")
    a = read_gravity(path, epoch=t0)
    b = read_gravity(path, epoch=t0 + YEAR_S)
    assert b.C[2, 0] - a.C[2, 0] == pytest.approx(-1.26059939709e-11, rel=1e-6)
    # at t0 the sin terms vanish and the cos terms add fully: gfct + acos(1y) + acos(0.5y)
    assert a.C[2, 0] == pytest.approx(-4.84165299820e-04 + 4.10019292536e-11 + 3.33920225943e-11,
                                      rel=0, abs=1e-22)
    v2 = read_gravity(shared_data / "gravity/orekit/EIGEN-6S4-v2-truncated", epoch=t0)
    assert v2.max_degree == 3 and v2.C[2, 0] == pytest.approx(-4.8416530e-4, rel=1e-6)


@pytest.mark.parametrize("name,line", [("corrupted-1-egm96_to5", 1), ("corrupted-3-egm96_to5", 1)])
def test_corrupted_files_name_file_and_line(shared_data, name, line):
    with pytest.raises(ParseError) as err:
        read_gravity(shared_data / "gravity/orekit" / name)
    assert err.value.line == line and name in str(err.value)


def test_corrupted_value_is_located(tmp_path, shared_data):
    lines = (shared_data / "gravity/orekit/corrupted-3-egm96_to5").read_text().splitlines()
    bad = tmp_path / "egm_bad"
    bad.write_text("\n".join(lines[1:]) + "\n")  # drop the S20 defect, keep 'corrupted-data'
    with pytest.raises(ParseError, match="not a number") as err:
        read_gravity(bad)
    assert err.value.line == len(lines) - 1


def test_shadr_table_from_spec(tmp_path, shared_data):
    ref = read_gravity(shared_data / "gravity/tudat/lpe200.txt").truncated(4)
    rows = ["1738.0, 4902.800238, 0.0, 4, 4, 1, 0.0, 0.0"]
    for n in range(2, 5):
        for m in range(n + 1):
            rows.append(f"{n:5d},{m:5d},{ref.C[n, m]:23.16E},{ref.S[n, m]:23.16E},0.0,0.0")
    path = tmp_path / "field.tab"
    path.write_text("\n".join(rows) + "\n")
    g = read_gravity(path)
    assert g.gm == pytest.approx(ref.gm, rel=1e-15) and g.radius == ref.radius
    np.testing.assert_array_equal(g.C, ref.C)


def test_a_field_read_again_is_the_same_until_its_file_changes(tmp_path, shared_data):
    """read_gravity keeps what it read: the same object again (one parse per batch worker), the epoch
    ignored for a format without time-variable terms; a rewritten file is read again."""
    lpe = shared_data / "gravity/tudat/lpe200.txt"
    assert read_gravity(lpe, epoch=0.0) is read_gravity(lpe, epoch=YEAR_S)
    path = tmp_path / "field.txt"
    path.write_text("4.9028e12 1738000.0\n2 0 -9.0e-5 0.0\n")
    first = read_gravity(path)
    path.write_text("4.9028e12 1738000.0\n2 0 -9.1e-5 0.0\n3 0 1.0e-5 0.0\n")
    second = read_gravity(path)
    assert first.C[2, 0] == -9.0e-5 and second.C[2, 0] == -9.1e-5 and second.max_degree == 3
    icgem = shared_data / "gravity/orekit/eigen-6s-truncated"
    a, b = read_gravity(icgem, epoch=0.0), read_gravity(icgem, epoch=YEAR_S)
    assert a is not b and a.C[2, 0] != b.C[2, 0]
