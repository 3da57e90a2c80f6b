"""``odpipe calibrate`` (and the inputs of the step commands) on synthetic tables with the real Cassini
calibration files: geometry from a named trajectory, refusals that name the file and what is missing,
and fallbacks only when asked for, each logged per pass."""

import logging

import numpy as np
import pandas as pd
import pytest
import spiceypy as sp

from odpipe.cli import main
from odpipe.environment.stations import StationCatalog, topocentric
from odpipe.frames.earth import itrs_to_gcrs
from odpipe.constants import C_LIGHT
from odpipe.pipeline.geometry import add_geometry, load_trajectory
from odpipe.preprocess import store
from odpipe.products.segments import EphemerisSegment
from odpipe.products.oem import write_oem
from odpipe.products.spk import write_spk
from odpipe.pipeline.setup import tdb
from odpipe.time import tdb_to_utc
from test_media_apply import _table, target

pytestmark = pytest.mark.realdata
TRO, ION = "S18TIGE2006_032_2006_059.TRO", "S18TIGE2006_032_2006_059.ION"


def _segment():
    """The test target (a far object fixed in inertial space) as GCRS states every 300 s, covering the
    synthetic table's rows and their uplinks ~2.4 h earlier, light time included."""
    t = np.arange(tdb("2006-02-26T20:00"), tdb("2006-02-27T11:00"), 300.0)

    def gcrs(s):
        e = np.asarray(tdb_to_utc(s), "datetime64[ns]")
        return np.einsum("nij,nj->ni", itrs_to_gcrs(e), target(e))
    v = (gcrs(t + 1.0) - gcrs(t - 1.0)) / 2.0
    return EphemerisSegment(t, np.hstack([gcrs(t), v]), "earth")


@pytest.fixture(scope="module")
def files(shared_data, tmp_path_factory):
    """(tmp dir, table file without geometry, trajectory OEM)."""
    w = tmp_path_factory.mktemp("media_cli")
    store.write(w / "in.parquet", _table(60))
    oem = write_oem(w / "target.oem", [_segment()], "TARGET", "-999")
    return w, w / "in.parquet", oem


def _cal(shared_data):
    d = shared_data / "cassini"
    return ["--tro", str(d / TRO), "--ion", str(d / ION)]


def refused(argv, capsys) -> str:
    """The one-line message of a command that refuses (raised, or printed by the top-level handler)."""
    try:
        rc = main(argv)
    except ValueError as err:
        return str(err)
    assert rc not in (0, None)
    return capsys.readouterr().err


def test_calibrate_command_writes_table_report_and_plots(shared_data, files, capsys):
    w, src, oem = files
    rc = main(["calibrate", str(src), *_cal(shared_data), "--trajectory", str(oem), "-o", str(w / "out.parquet"),
               "--report", str(w / "passes.csv"), "--plots", str(w / "png")])
    assert rc == 0 and "2 passes calibrated; 60 rows corrected; 0 passes with fallbacks" in capsys.readouterr().out
    out, _ = store.read(w / "out.parquet")
    rng = out[out["observable"] == "range"]
    # DSS-25 at >= 10 deg elevation, X band: a few to ~25 m of troposphere on the two legs, cm-level ionosphere
    assert rng["tropo_m"].between(4.0, 30.0).all() and rng["iono_m"].between(0.0, 0.2).all()
    assert rng["media_source"].str.contains("S18TIGE2006_032_2006_059.ION:314").all()
    # the round-trip light time of the 1.3e12 m target, from the trajectory
    st = StationCatalog.default()["DSS-25"]
    ep = out["epoch"].to_numpy("datetime64[ns]")
    rtlt = 2 * np.linalg.norm(target(ep) - st.position_itrs(ep), axis=-1) / C_LIGHT
    np.testing.assert_allclose(out["rtlt_s"], rtlt, rtol=1e-6)
    assert sorted(p.name for p in (w / "png").iterdir()) == ["media_pass_0.png", "media_pass_1.png"]
    assert len(pd.read_csv(w / "passes.csv")) == 2
    assert not list(w.rglob("*.part"))  # no temporary file of the atomic writer is left


def test_calibrate_refuses_a_table_without_geometry(shared_data, files, capsys):
    w, src, _ = files
    msg = refused(["calibrate", str(src), *_cal(shared_data), "-o", str(w / "x.parquet")], capsys)
    assert str(src) in msg and "no geometry" in msg and "--trajectory" in msg
    assert not (w / "x.parquet").exists()


def test_calibrate_refuses_files_not_covering_the_data(shared_data, files, capsys, caplog):
    w, src, oem = files
    ionex = shared_data / "ionex" / "gpsg0150.19i"
    args = ["calibrate", str(src), "--trajectory", str(oem), "--tro", str(shared_data / "cassini" / TRO),
            "--ionex", str(ionex), "-o", str(w / "x.parquet")]
    msg = refused(args, capsys)
    assert str(ionex) in msg and "2019-01-15T00:00:00 .. 2019-01-16T00:00:00 UTC" in msg
    assert "2006-02-27T04:00:00 .. 2006-02-27T08:55:00 UTC" in msg and "--allow-fallbacks" in msg
    other = shared_data / "cassini" / "S18TIGE2006_060_2006_080.TRO"     # March cards on February data
    msg = refused(["calibrate", str(src), "--trajectory", str(oem), "--tro", str(other), "-o", str(w / "x.parquet")],
                  capsys)
    assert str(other) in msg and "2006-03-01" in msg and "2006-02-27T04:00:00" in msg
    caplog.clear()                    # the refusals above may be logged by the top-level handler
    with caplog.at_level(logging.WARNING):
        assert main(args + ["--allow-fallbacks"]) == 0
    assert any(str(ionex) in r.getMessage() and r.levelno == logging.WARNING for r in caplog.records)
    # the IONEX maps cover nothing: every row falls back to no ionosphere, logged for both passes
    out, _ = store.read(w / "x.parquet")
    assert (out["iono_m"] == 0).all()
    per_pass = [r.getMessage() for r in caplog.records if "no ionosphere calibration" in r.getMessage()]
    assert len(per_pass) == 2 and all("30 of 30 rows" in m for m in per_pass)


def test_calibrate_refuses_rows_without_correction_and_logs_fallbacks_per_pass(shared_data, files, capsys,
                                                                                caplog):
    """Geometry from the table's columns only: the uplink legs (2.4 h before reception) fall before the
    first row, where the columns say nothing, so those rows would get no correction."""
    w, src, _ = files
    tab = _table(60)
    ep = tab["epoch"].to_numpy("datetime64[ns]")
    st = StationCatalog.default()["DSS-25"]
    tab["azimuth_rx"], tab["elevation_rx"], rng = topocentric(st, target(ep), ep)
    tab["rtlt_s"] = 2 * rng / C_LIGHT
    store.write(w / "columns.parquet", tab)
    args = ["calibrate", str(w / "columns.parquet"), *_cal(shared_data), "-o", str(w / "y.parquet")]
    msg = refused(args, capsys)
    assert str(w / "columns.parquet") in msg and "no spacecraft direction" in msg and "--trajectory" in msg
    assert not (w / "y.parquet").exists()
    caplog.clear()                    # the refusal above may be logged by the top-level handler
    with caplog.at_level(logging.WARNING):
        assert main(args + ["--allow-fallbacks"]) == 0
    out, _ = store.read(w / "y.parquet")
    missing = out["media_m"].isna()
    assert 0 < missing.sum() < len(out)
    logged = [r.getMessage() for r in caplog.records
              if r.levelno == logging.WARNING and "no spacecraft direction" in r.getMessage()]
    assert len(logged) == out.loc[missing, "pass_id"].nunique()
    assert sum(int(m.split(": ")[-1].split(" of ")[0]) for m in logged) == missing.sum()


def test_trajectory_from_oem_spk_or_run_directory(files, tmp_path):
    _, src, oem = files
    table, _ = store.read(src)
    catalog = StationCatalog.default()
    seg = _segment()
    write_spk(tmp_path / "one.bsp", [seg], -999)
    run = tmp_path / "arc" / "current"
    run.mkdir(parents=True)
    (run / "trajectory.oem").write_text(oem.read_text())
    el = {name: add_geometry(table, load_trajectory(path), None, catalog)["elevation_rx"].to_numpy()
          for name, path in (("oem", oem), ("spk", tmp_path / "one.bsp"), ("run", tmp_path / "arc"))}
    assert np.isfinite(el["oem"]).all()
    # the SPK's degree-7 Hermite and the OEM's cubic Hermite of the same 300-s states agree to nrad
    np.testing.assert_allclose(el["spk"], el["oem"], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(el["run"], el["oem"])
    write_spk(tmp_path / "two.bsp", [seg], -999)
    handle = sp.spkopa(str(tmp_path / "two.bsp"))       # a second body in the same file
    sp.spkw13(handle, -998, 399, "J2000", float(seg.t_tdb[0]), float(seg.t_tdb[-1]), "second", 7, len(seg.t_tdb),
              np.ascontiguousarray(seg.states / 1e3), np.ascontiguousarray(seg.t_tdb))
    sp.spkcls(handle)
    with pytest.raises(ValueError, match=r"two\.bsp: holds bodies \[-999, -998\]: name one with --naif-id"):
        load_trajectory(tmp_path / "two.bsp")
    assert load_trajectory(tmp_path / "two.bsp", -998).body == -998
    (run / "trajectory.oem").unlink()
    with pytest.raises(ValueError, match=r"arc/current: no trajectory.oem"):
        load_trajectory(run)
    with pytest.raises(ValueError, match=r"in.parquet: not a trajectory: expected a CCSDS OEM"):
        load_trajectory(src)
    (tmp_path / "bad.bsp").write_bytes(b"DAF/SPK " + bytes(100))     # an SPK cut short
    with pytest.raises(ValueError, match=r"bad.bsp: not a readable SPK: SPICE\(FILEREADFAILED\)"):
        load_trajectory(tmp_path / "bad.bsp")


def test_compress_and_edit_refuse_input_they_cannot_take(shared_data, files, capsys, caplog):
    w, src, oem = files
    odf = shared_data / "cassini" / "S18TIGM2006_058_0005X25MV1.ODF"
    msg = refused(["compress", str(odf), "-o", str(w / "c.parquet")], capsys)
    assert str(odf) in msg and "not a Parquet file" in msg and "odpipe convert" in msg
    msg = refused(["compress", str(w / "absent.parquet"), "-o", str(w / "c.parquet")], capsys)
    assert str(w / "absent.parquet") in msg and "no such file" in msg
    msg = refused(["edit", str(src), "-o", str(w / "e.parquet")], capsys)
    assert str(src) in msg and "elevation mask" in msg and "--trajectory" in msg
    assert main(["edit", str(src), "-o", str(w / "e.parquet"), "--trajectory", str(oem)]) == 0
    edited, _ = store.read(w / "e.parquet")
    assert np.isfinite(edited["elevation_rx"]).all()
    with caplog.at_level(logging.WARNING):
        assert main(["edit", str(src), "-o", str(w / "e.parquet"), "--no-elevation-mask"]) == 0
    assert any("elevation mask not applied" in r.getMessage() for r in caplog.records)
