"""``odpipe calibrate`` end to end on a synthetic table with the real Cassini calibration files."""

import pandas as pd
import pytest

from odpipe.cli import main
from odpipe.environment.stations import StationCatalog, topocentric
from test_media_apply import _table, target


@pytest.mark.realdata
def test_calibrate_command_writes_table_report_and_plots(shared_data, tmp_path, capsys):
    tab = _table(60)
    ep = tab["epoch"].to_numpy().astype("datetime64[ns]")
    az, el, _ = topocentric(StationCatalog.default()["DSS-25"], target(ep), ep)
    tab["elevation_rx"], tab["azimuth_rx"] = el, az
    src = tmp_path / "in.parquet"
    tab.to_parquet(src)
    d = shared_data / "cassini"
    rc = main(["calibrate", str(src), "--tro", str(d / "S18TIGE2006_032_2006_059.TRO"),
               "--ion", str(d / "S18TIGE2006_032_2006_059.ION"), "-o", str(tmp_path / "out.parquet"),
               "--report", str(tmp_path / "passes.csv"), "--plots", str(tmp_path / "png")])
    assert rc == 0 and "2 passes calibrated" in capsys.readouterr().out
    out = pd.read_parquet(tmp_path / "out.parquet")
    rng = out[out["observable"] == "range"]
    # DSS-25 at >= 10 deg elevation, X band: a few to ~25 m of troposphere on the two legs, cm-level ionosphere
    assert rng["tropo_m"].between(4.0, 30.0).all() and rng["iono_m"].between(0.0, 0.2).all()
    assert rng["media_source"].str.contains("S18TIGE2006_032_2006_059.ION:314").all()
    assert sorted(p.name for p in (tmp_path / "png").iterdir()) == ["media_pass_0.png", "media_pass_1.png"]
    assert len(pd.read_csv(tmp_path / "passes.csv")) == 2
    assert not list(tmp_path.rglob("*.part"))  # no temporary file of the atomic writer is left
