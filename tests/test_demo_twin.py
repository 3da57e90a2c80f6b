"""The ARTEMIS-P2 twin (issue #25 item 1): the thesis' figures as odpipe holds them, the comparison, the twin's
error budget as simulated, and its overlap and maneuver figures against the thesis and against a snapshot.

Tolerances and why:
* thesis figures: exactly the numbers printed in seed 004 §4.5, §4.6 and Table 4.4;
* twin against thesis (the 28-day twin's recorded figures, fixtures/artemis/twin_figures.csv, made by
  ``odpipe demo --twin``): short-arc radial / in-track / cross-track overlap means within a factor 3 of
  15 / 183 / 416 m (the thesis' own overlap-to-overlap scatter is 50-80 % of its means, and the twin has 3
  short-arc overlaps against the thesis' ~16), the Table 4.4 median magnitude percentage within a factor 5
  of 0.58 % (its burns are 3x the thesis' and its components ICRF, not true of date); long-arc overlap means
  within a factor 10 of 5 / 66 / 102 m (measured 8.5 / 175 / 496 m; before the growing-arc and editing fixes
  of odpipe.od.arc / odpipe.estimation.fit, long2 across SK-3 converged 114 km off and these were 30-45 km);
* snapshot: the twin's first 12 days (both station-keeping burns, at days 3.5 and 10.5, so two short arcs, two
  long arcs, one overlap of each kind and two burns in Table 4.4) refitted live must give the recorded figures
  (fixtures/artemis/twin_12d_figures.csv, made by ``benchmarks/artemis_ablation.py --days 12``, full twin; the
  test's one-thread path gives the same digits) within 20 %: the runs are seeded, so only a change of the code
  moves them, and a several-fold change cannot pass. Measured 2026-11-26 (each change once, refitted as here):
  another noise seed moves 21 of the 28 figures outside the 20 % (-81 % to +416 %), no outgassing in the truth
  (2e-9 m/s^2, ~3 % of the SRP) moves 5 outside (the long-arc cross-track overlap +21 %, Table 4.4's Z
  +21 % and +61 %); all data sigmas 10 % larger, or the stochastic sigma 10 % larger, move none by more than
  4 % (they pass; at 14 days a 10 % data-sigma change moved the long-arc cross-track overlap +45 %). A span
  without the second burn (under 10.5 days) would fit one long arc only: no overlap, no Table 4.4.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from odpipe.numerics.precision import significant
from odpipe.simulate import thesis
from odpipe.simulate.case import load

ROOT = Path(__file__).resolve().parents[1]
TWIN = ROOT / "runs" / "artemis_p2_twin.toml"
SEED = ROOT.parent / "shared" / "seeds" / "004_dcc56d124520d255.txt"
FIXTURES = ROOT / "fixtures" / "artemis"
DAYS = 12.0   # the snapshot's span (see the module docstring)


def _mean(versus: pd.DataFrame, figure: str) -> float:
    return float(str(versus.set_index("figure").loc[figure, "odpipe"]).split(" ± ")[0])


@pytest.mark.skipif(not SEED.exists(), reason="the thesis text (shared/seeds) is absent")
def test_thesis_figures_are_the_thesis():
    text = SEED.read_text()
    for arc, word in (("short", "short-arc"), ("long", "long-arc")):
        pos = re.search(rf"average {word} overlap position errors are (.*?)Cross-track", text).group(1)
        vel = re.search(rf"average {word} overlap velocity errors are (.*?)Cross-track", text).group(1)
        for kind, sentence in (("pos", pos), ("vel", vel)):
            pairs = [(float(a), float(b)) for a, b in re.findall(r"([\d.]+) \\?(?:\\pm|±) ([\d.]+)", sentence)]
            assert pairs == list(thesis.OVERLAPS[arc][kind]), (arc, kind, pairs)
    table = text[text.index("Table 4.4: Maneuver Evaluation"):]
    for stat in thesis.TABLE_4_4.index:
        row = re.search(rf"^{stat}\t(.*)$", table, re.M).group(1).split("\t")
        assert [float(v) for v in row] == list(thesis.TABLE_4_4.loc[stat]), stat


def test_comparison_puts_odpipe_beside_the_thesis():
    cols = {f"{k}_{c}_rms": [0.0, 0.0] for k in ("pos", "vel") for c in thesis.COMPONENTS}
    cols["pos_intrack_rms"] = [366.0, 10.0]          # mean, std rows (m)
    cols["vel_radial_rms"] = [0.263e-3 * 2, 1e-4]    # m/s
    summary = pd.DataFrame(cols)
    stats = thesis.TABLE_4_4 * 2.0
    v = thesis.comparison({"short": summary}, stats).set_index("figure")
    assert v.loc["short-arc position intrack (m)", "ratio"] == pytest.approx(2.0)
    assert v.loc["short-arc position intrack (m)", "thesis"] == "183 ± 146"
    assert v.loc["short-arc velocity radial (mm/s)", "ratio"] == pytest.approx(2.0)
    assert v.loc["Table 4.4 median Mag. (%)", "ratio"] == pytest.approx(2.0)
    # odpipe's figures to 3 significant figures with their trailing zeros, as the overlap tables (was '366 ± 10')
    assert v.loc["short-arc position intrack (m)", "odpipe"] == "366 ± 10.0"
    assert v.loc["short-arc velocity radial (mm/s)", "odpipe"] == "0.526 ± 0.100"
    assert v.loc["Table 4.4 median X (%)", "odpipe"] == "2.20"            # 2 x the thesis' 1.1 (was '2.2')
    assert len(v) == 6 + 16


def test_twin_carries_the_error_sources():
    case = load(TWIN)
    assert case.truth_body is not None and case.truth_body.axis_tilt_deg > 0
    assert case.unmodelled.outgassing_m_s2 > 0 and case.unmodelled.plume_fraction > 0
    assert case.media.error_wet_m > 0 and case.media.error_ion_m > 0
    assert case.orbit.z_amplitude > 0
    assert case.station_keeping.nav_sigma_m > 0
    assert not any(m["planned"] for m in case.maneuvers)                    # attitude burns: time only
    assert [n.station for n in case.networks if not n.fitted] == ["USHS"]   # USN simulated, not fitted (§4.2.2)


@pytest.fixture(scope="module")
def twin_dir(tmp_path_factory):
    """A demo folder whose ``case/`` holds the twin's first ``DAYS`` days, simulated once for this module."""
    return tmp_path_factory.mktemp("twin")


@pytest.fixture(scope="module")
def twin_truth(twin_dir):
    from odpipe.simulate import run_case

    return run_case(TWIN, twin_dir / "case", days=DAYS)


@pytest.mark.slow
def test_twin_schedule_and_burns_are_the_thesis(twin_truth):
    paths, truth, obs = twin_truth
    t = obs.table[obs.table["observable"] == "doppler_2way"]
    case = load(TWIN)
    # a 5-day short arc after the first burn (day 3.5): §4.5 "typically 5 DSN passes ... BRKS usually 10 or more"
    a = case.start + np.timedelta64(int(3.5 * 86400 + 3600), "s")
    w = t[(t["epoch"] > a) & (t["epoch"] < a + np.timedelta64(5, "D"))]
    dsn = w[w["station_rx"].str.startswith("DSS")]["pass_id"].nunique()
    bgs = w[w["station_rx"] == "BGS"]["pass_id"].nunique()
    assert 4 <= dsn <= 6 and bgs >= 9, (dsn, bgs)
    # burns "generally ... less than a m/s" (§4.2.4); Table 4.4's medians imply ~120 mm/s: the twin's are 10 mm/s-1 m/s
    sk = np.linalg.norm(truth.designed[[m["kind"] == "station-keeping" for m in truth.maneuvers]], axis=1)
    assert np.all((sk > 0.01) & (sk < 1.0)), sk
    # the plan knows the attitude burns by time only; the executed file has their delta-v
    plan = pd.read_csv(paths["maneuvers"]).set_index("name")
    assert np.all(plan.loc[["ATT-1"], ["dv1", "dv2", "dv3"]].to_numpy() == 0.0)


@pytest.mark.slow
def test_twin_recorded_figures_against_the_thesis():
    versus = pd.read_csv(FIXTURES / "twin_figures.csv")
    for c, limit in zip(thesis.COMPONENTS, (15.0, 183.0, 416.0)):
        ours = _mean(versus, f"short-arc position {c} (m)")
        assert limit / 3 < ours < limit * 3, (c, ours)
    for c, limit in zip(thesis.COMPONENTS, (5.0, 66.0, 102.0)):
        ours = _mean(versus, f"long-arc position {c} (m)")
        assert limit / 10 < ours < limit * 10, (c, ours)
    pct = _mean(versus, "Table 4.4 median Mag. (%)")
    assert 0.58 / 5 < pct < 0.58 * 5, pct


@pytest.mark.slow
def test_twin_12_days_snapshot(twin_dir, twin_truth, monkeypatch):
    from distributed import LocalCluster

    from odpipe.operations.nightly import run_batch
    from odpipe.pipeline import demo

    # fits twin_truth's files on a Dask worker thread of this process: the arcs are independent, so their figures
    # depend neither on the number of workers nor on where they run, and a worker process would pay the imports
    # and kernel loads this process has done already, beside make test's own workers (the worker processes of
    # run_batch's own cluster: tests/test_batch_faults.py, test_nightly_cluster.py); without the arcs' residual
    # plots, which no figure reads (a fifth of the fits' time)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster:
        monkeypatch.setattr(demo, "run_batch", functools.partial(run_batch, scheduler=cluster.scheduler_address))
        headline = demo.run_demo(twin_dir, 1, progress=lambda *_: None, days=DAYS, case=load(TWIN), plots=False)
    got = pd.read_csv(twin_dir / "thesis_comparison.csv")
    # the headline at the precision of the overlap tables (it showed 404.8 ± 568.2 m beside 405 and 568)
    mean, std = pd.read_csv(twin_dir / "overlap_short.csv").set_index("overlap").loc[["mean", "std"], "pos_3d_rms"]
    assert headline["short-arc overlap 3D RMS"].startswith(f"{significant(mean)} ± {significant(std)} m, ")
    want = pd.read_csv(FIXTURES / "twin_12d_figures.csv")
    for figure in want["figure"]:
        g, w = _mean(got, figure), _mean(want, figure)
        assert abs(g - w) <= 0.2 * abs(w) + 1e-9, (figure, g, w)
