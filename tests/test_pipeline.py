"""odpipe run end to end on a simulated arc: the products agree with the truth within their covariance."""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from heo_case import simulate, write_config
from odpipe.numerics.precision import significant
from odpipe.pipeline.run import run_config
from parsers import oem
from bounds import max_z

START, END = "2003-06-03T00:00:00", "2003-06-04T12:00:00"  # two days after the peers' perigee


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("pipeline")
    truth, x_start = simulate(tmp, START, END)
    guess = x_start + np.r_[500.0, -400.0, 300.0, 0.004, -0.003, 0.002]
    write_config(tmp, "sim_arc", START, END, guess, "reweight = false")
    out = run_config(tmp / "arc.toml", progress=None)
    return tmp, out, truth


def test_run_products_agree_with_truth_within_covariance(case):
    tmp, out, truth = case
    assert out["status"] == "complete" and out["converged"]
    run = Path(out["run"])
    for name in ("trajectory.oem", "trajectory.bsp", "residuals.parquet", "report.html", "manifest.json",
                 "residuals_postfit.png", "parameters.csv", "run.log"):
        assert (run / name).is_file(), name
    seg = oem.read(run / "trajectory.oem")[0]
    t = (seg.epochs - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(1, "s")
    err = seg.states - truth.state(t)
    cov_t = (seg.cov_epochs - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(1, "s")
    k = np.searchsorted(t, cov_t[len(cov_t) // 2])
    sig = np.sqrt(np.diag(seg.covariances[len(cov_t) // 2]))
    assert np.all(np.abs(err[k]) < max_z(6) * sig + 1e-3), (err[k], sig)
    assert np.max(np.linalg.norm(err[:, :3], axis=1)) < 50.0  # m, from a 700-m, 5-mm/s start error
    summary = json.loads((run / "summary.json").read_text())
    rms = [v for k_, v in summary.items() if k_.startswith("postfit RMS doppler_2way")]
    assert rms and all(0.07 < v < 0.13 for v in rms)  # mm/s, the simulated 0.1 mm/s noise


def test_unchanged_arc_is_skipped_and_failed_rerun_keeps_products(case):
    tmp, out, _ = case
    assert run_config(tmp / "arc.toml", progress=None)["status"] == "skipped"
    before = (Path(out["run"]) / "manifest.json").read_text()
    text = (tmp / "arc.toml").read_text()
    bad = tmp / "arc.toml"
    bad.write_text(text.replace('files = ["tracking.parquet"]', 'files = ["tracking.parquet", "missing.odf"]'))
    try:
        with pytest.raises(Exception):
            run_config(bad, progress=None)
    finally:
        bad.write_text(text)
    assert (Path(out["run"]) / "manifest.json").read_text() == before


def test_next_arc_starts_from_this_arcs_oem(case):
    """A nightly chain: the a priori of the next arc is this arc's OEM state; batch runs this arc first."""
    from odpipe.commands.batch import night_report, starts_from
    from odpipe.operations.nightly import ArcOutcome
    from odpipe.pipeline.config import load_config
    from odpipe.pipeline.setup import initial_state, tdb
    from odpipe.time import tdb_to_utc

    tmp, out, truth = case
    seg = oem.read(Path(out["run"]) / "trajectory.oem")[0]
    assert seg.meta["TIME_SYSTEM"] == "TDB"
    k = np.searchsorted(seg.epochs, np.datetime64("2003-06-04T00:00:00", "ns"))
    t_node = (seg.epochs[k] - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(1, "s")
    start2 = str(tdb_to_utc(np.array([t_node]))[0])  # an OEM node: read there without interpolation
    text = (tmp / "arc.toml").read_text().replace('name = "sim_arc"', 'name = "sim_arc_next"')
    text = text.replace(f'start = "{START}"', f'start = "{start2}"')
    head, _, tail = text.partition("[initial_state]")
    tail = tail.split("[estimation]", 1)[1]
    (tmp / "next.toml").write_text(head + f'[initial_state]\nepoch = "{start2}"\n'
                                   'from_oem = "out/sim_arc/current/trajectory.oem"\n[estimation]' + tail)
    cfg = load_config(tmp / "next.toml")
    t_state, x_state = initial_state(cfg)
    assert t_state == tdb(start2)
    np.testing.assert_allclose(x_state, seg.states[k], rtol=0, atol=1e-4)
    assert starts_from([tmp / "arc.toml", tmp / "next.toml"]) == {tmp / "next.toml": [tmp / "arc.toml"]}
    nxt = run_config(tmp / "next.toml", progress=None)
    assert nxt["status"] == "complete" and nxt["converged"]
    par = pd.read_csv(Path(nxt["run"]) / "parameters.csv")
    state = par[par["kind"] == "state"]
    err = state["estimate"].to_numpy() - truth.state(np.array([tdb(start2)]))[0]
    assert np.all(np.abs(err) < max_z(6) * state["sigma"].to_numpy()), (err, state["sigma"].to_numpy())
    arcs = [tmp / "arc.toml", tmp / "next.toml"]
    night_report(tmp / "night", arcs, [ArcOutcome(str(a), "complete", 1.0) for a in arcs])
    overlaps = pd.read_csv(tmp / "night" / "overlap_arcs.csv")
    assert overlaps["overlap"].iloc[0] == "sim_arc - sim_arc_next" and len(overlaps) == 3  # + mean, std
    assert overlaps["pos_3d_rms"].iloc[0] < 100.0  # m: two fits of one truth, each within tens of metres
    stats = pd.read_csv(tmp / "night" / "residual_statistics.csv")
    assert set(stats["arc"]) == {"sim_arc", "sim_arc_next"} and (tmp / "night" / "report.html").is_file()
    page = (tmp / "night" / "report.html").read_text()   # figures captioned by what they show, not file names
    assert "Position differences over each overlap: radial, in-track, cross-track and 3D RMS (m)" in page
    assert "overlap_arcs_pos" not in page
    mean, std = overlaps["pos_3d_rms"].iloc[-2:]   # the headline at the precision the tables carry
    assert f"<td>overlap 3D RMS</td><td>{significant(mean)} ± {significant(std)} m</td>" in page


def test_python_api_reopens_the_run_as_odpipe_run_wrote_it(case):
    from odpipe.api import fit_arc

    tmp, out, truth = case
    arc = fit_arc(tmp / "arc.toml")  # unchanged: skipped, the products of the run above
    assert arc.folder == Path(out["run"]) and arc.report.is_file()
    seg = oem.read(arc.folder / "trajectory.oem")[0]
    t = (seg.epochs - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(1, "s")
    assert np.abs(arc.trajectory.state(t[5:6])[0] - seg.states[5]).max() < 1e-6
    assert np.abs(arc.trajectory.state(t[5:6])[0][:3] - truth.state(t[5:6])[0][:3]).max() < 50.0  # m
    assert set(arc.statistics["station_rx"]) == set(arc.residuals["station_rx"].astype(str))
    assert arc.summary["converged"] == out["converged"] and len(arc.parameters) >= 7  # state + SRP at least
