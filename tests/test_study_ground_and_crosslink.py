"""Study ground_and_crosslink (Leonard 2015, sec. 8.1) and its trade study schedule_trade (secs.
8.1.2.3-8.1.2.4): an EML1 halo orbiter and a GEO satellite tracked from the ground alone, by crosslinks
alone and by both.

The thesis' figures (runs/study_ground_and_crosslink.toml [paper], read from the text of sec. 8.1.2.3) are
checked against odpipe's with the tolerance the text allows, or recorded as disagreements where odpipe
does not agree; odpipe's own figures are snapshots (relative 1e-3: the run is seeded). The default suite
fits three schedules (ground only, crosslinks only, both) and the 22-h offset pair on one shared set-up;
the other schedules need the whole run (``ODPIPE_STUDY_RUNS=1``, tests/study_runs.py).

Tolerance for agreement: a factor 2. The thesis quotes rounded figures ("about 70 m", "on the order of
10 m") and does not give the correlation time of its empirical accelerations; odpipe takes 1 day, and
with 3 h the ground-only halo figure moves to 0.44x of the thesis', outside the bound: the agreement
depends on that choice. The whole run refits every case with a thesis figure over correlation times of
3 h to 3 d and reports the spread of odpipe/thesis (``tau_spread``); the figures are stored in
fixtures/studies/ground_and_crosslink_tau.csv and the spread is checked on them."""

from pathlib import Path

import numpy as np
import pytest
from scipy.stats import chi2

from odpipe.dynamics.propagator import propagate
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.stations import itrs_to_geodetic
from odpipe.estimation.fit import _sweep, build_grid
from odpipe.frames.earth import gcrs_to_itrs_state
from odpipe.studies import ground_and_crosslink as ground
from odpipe.studies import schedule_trade
from odpipe.studies.scenarios import load_config
from odpipe.studies.study_report import spread
from odpipe.time import utc_to_tdb
from study_runs import as_recorded, run_study, stored_figures, whole_run

CFG = load_config(Path(__file__).parents[1] / "runs" / "study_ground_and_crosslink.toml")
CASES = ("ground", "ground_liaison", "liaison")   # (inf, 0), (0, 0) and (0, inf) of the thesis' Fig. 8.4/8.5
# odpipe's figures (m), recorded 2026-11-25: 3-D 3-sigma RMS over days 6-9 and at the end of the arc
RECORDED = {
    ("ground", "L1"): {"rms_sig3": 35.7961, "final_sig3": 29.6852},
    ("ground", "GEO"): {"rms_sig3": 350.567, "final_sig3": 455.538},
    ("ground_liaison", "L1"): {"rms_sig3": 20.5693, "final_sig3": 17.9532},
    ("ground_liaison", "GEO"): {"rms_sig3": 3.68463, "final_sig3": 2.89997},
    ("liaison", "L1"): {"rms_sig3": 50.2427, "final_sig3": 27.8771},
    ("liaison", "GEO"): {"rms_sig3": 8.02448, "final_sig3": 4.15985},
}


def test_schedule_of_passes_and_gaps():
    """(28,49)-type schedules: 3-h passes every pass + gap hours from epoch; inf = never, 0 = always."""
    t = np.arange(0.0, 9 * 86400.0, 100.0)
    on = ground.scheduled(t, 49.0, 3.0)
    assert on.sum() == 5 * 108                 # passes at 0, 52, 104, 156 and 208 h, 108 samples each
    assert on[t == 52 * 3600.0].all() and not on[t == 55 * 3600.0].any()
    assert not ground.scheduled(t, np.inf, 3.0).any() and ground.scheduled(t, 0.0, 3.0).all()


def test_ground_passes_offset_by_half_the_gap():
    """Sec. 8.1.2.4: LiAISON passes at 0, 25, 50 h; ground passes start halfway through each gap (14 h)."""
    import pandas as pd

    t = np.arange(0.0, 3 * 86400.0, 600.0)
    rows = pd.DataFrame({"time": np.concatenate([t, t]), "link": ["sst"] * t.size + ["dsn"] * t.size})
    sel = ground.case_rows(CFG, rows, {"liaison_gap_h": 22.0, "ground_gap_h": 22.0, "ground_offset_h": 11.0}, 0.0)
    sst, dsn = (sel.loc[sel.link == k, "time"].to_numpy() / 3600.0 for k in ("sst", "dsn"))
    assert sst.min() == 0.0 and sst.max() < 53.0 and set(np.floor(sst / 25.0)) == {0, 1, 2}
    assert dsn.min() == 11.0 and np.all((dsn - 11.0) % 25.0 < 3.0)
    assert not np.any(np.isin(np.round(sst, 6), np.round(dsn, 6)))             # never simultaneous


@pytest.mark.realdata
def test_geo_satellite_stays_over_the_thesis_longitude():
    """The GEO start state is geostationary: radius 42,164 km and the sub-satellite point of
    sec. 8.1.1.2 held within 0.1 deg over a day of the truth dynamics."""
    eph = Ephemeris.open("de440")
    t0 = float(utc_to_tdb(np.datetime64(CFG["epoch_utc"], "ns")))
    x0 = ground.geo_state(CFG, t0, eph.gm("earth"))
    assert np.linalg.norm(x0[:3]) == pytest.approx(42164.17e3, abs=1e3)
    traj = propagate(x0, t0, t0 + 86400.0, ground.force_models(CFG, eph, "truth")["GEO"], with_stm=False)
    t = t0 + np.linspace(0.0, 86400.0, 25)
    r, _ = gcrs_to_itrs_state(t, traj.state(t)[:, :3], traj.state(t)[:, 3:])
    lat, lon, _ = itrs_to_geodetic(r)
    assert np.max(np.abs(np.degrees(lon) - CFG["geo"]["lon_deg"])) < 0.1
    assert np.max(np.abs(np.degrees(lat))) < 0.3


@pytest.fixture(scope="module")
def scenario(tmp_path_factory):
    """The study on CASES (no sensitivity refits), its set-up kept for the trade study's test."""
    cfg = dict(CFG, cases={k: CFG["cases"][k] for k in CASES},
               sensitivity=dict(CFG["sensitivity"], cases=[], acc_tau_s=[], geo_apriori_vel_mps=[]))
    return ground.run(cfg, tmp_path_factory.mktemp("study_ground"), log=lambda m: None)


def _row(scenario, case, sc):
    df = scenario["table"]
    return df[(df["case"] == case) & (df["spacecraft"] == sc)].iloc[0]


def _figures(row) -> dict:
    return {"rms_sig3": row["odpipe 3s RMS d6-9"], "final_sig3": row["odpipe final 3s"],
            "below100_d": row["odpipe day 3s<100 m"]}


@pytest.mark.slow
@pytest.mark.realdata
def test_snapshot_of_three_schedules(scenario):
    """odpipe's 3-sigma figures of ground only, both and crosslinks only, relative 1e-3."""
    for (case, sc), recorded in RECORDED.items():
        got = _figures(_row(scenario, case, sc))
        for key, value in recorded.items():
            assert got[key] == pytest.approx(value, rel=1e-3), (case, sc, key)


@pytest.mark.realdata
def test_ground_and_both_against_the_thesis(scenario):
    """Agreement within a factor 2 (module docstring): ground only, halo over days 6-9 (thesis about 70 m, odpipe
    36 m: 0.51x); ground + crosslinks, final halo and GEO (thesis "on the order of" 10 m and 3 m, odpipe 18 m and
    2.9 m). And the thesis' ordering: both data types beat ground alone for each spacecraft."""
    paper = CFG["paper"]
    g_l1, g_geo = _row(scenario, "ground", "L1"), _row(scenario, "ground", "GEO")
    b_l1, b_geo = _row(scenario, "ground_liaison", "L1"), _row(scenario, "ground_liaison", "GEO")
    assert 0.5 < g_l1["odpipe 3s RMS d6-9"] / paper["ground"]["L1_rms_sig3"] < 2.0
    assert 0.5 < b_l1["odpipe final 3s"] / paper["ground_liaison"]["L1_final_sig3"] < 2.0
    assert 0.5 < b_geo["odpipe final 3s"] / paper["ground_liaison"]["GEO_final_sig3"] < 2.0
    assert b_l1["odpipe 3s RMS d6-9"] < 0.7 * g_l1["odpipe 3s RMS d6-9"]
    assert b_geo["odpipe 3s RMS d6-9"] < 0.05 * g_geo["odpipe 3s RMS d6-9"]
    assert b_geo["odpipe error RMS d6-9"] < 0.1 * g_geo["odpipe error RMS d6-9"]


@pytest.mark.realdata
def test_disagreements_with_the_thesis_as_they_are(scenario):
    """Where odpipe does NOT agree with the thesis, recorded as it is (the snapshot test holds the values):

    - GEO from Sky Valley alone: the thesis says its a priori uncertainty is not reduced (the colour of Fig. 8.4
      saturates above 150 m). odpipe shrinks the a priori 3-sigma (3-D, 5.2 km) about 15x, to 351 m over days
      6-9: still above 150 m, so the figure's colour agrees, the statement does not. Measured cause (whole run):
      Table 8.3's tight velocity a priori (1 mm/s) carried through the dynamics; with 0.1 m/s the reduction is
      2.4x, and the correlation time changes nothing. Why the thesis sees none with the same a priori is open.
    - Crosslinks only: thesis about 160 m (halo) and 24 m (GEO); odpipe about 3x tighter (50 m and 8 m)."""
    paper, apriori_3d = CFG["paper"], 3 * np.sqrt(3) * CFG["filter"]["apriori_pos_m"]
    geo = _row(scenario, "ground", "GEO")["odpipe 3s RMS d6-9"]
    assert geo > 150.0 and apriori_3d / geo == pytest.approx(14.8, rel=1e-2)
    for sc in ground.NAMES:
        ratio = _row(scenario, "liaison", sc)["odpipe 3s RMS d6-9"] / paper["liaison"][f"{sc}_rms_sig3"]
        assert ratio == pytest.approx(RECORDED[("liaison", sc)]["rms_sig3"] / paper["liaison"][f"{sc}_rms_sig3"],
                                      rel=1e-3)
        assert ratio < 0.5


@pytest.mark.realdata
def test_geo_from_the_ground_alone_by_axis(scenario):
    """Where the GEO satellite's ground-only uncertainty goes (3-sigma RMS over days 6-9 along the truth's R/T/N,
    recorded): the range from Sky Valley pins the radial axis (29.1 m), the transverse and normal axes keep
    152 m and 315 m of the 3,000-m a priori per axis. Every axis is reduced, the normal one least."""
    res = scenario["results"]["ground"]
    rtn = ground.rtn_sig3(res["solution"], scenario["sim"]["truth"], "GEO", scenario["sim"]["t0"], CFG["window_days"])
    assert list(rtn) == [as_recorded("29.1"), as_recorded("152.2"), as_recorded("314.5")]
    assert np.sqrt(np.sum(rtn**2)) == pytest.approx(RECORDED[("ground", "GEO")]["rms_sig3"], rel=1e-3)  # trace kept


@pytest.mark.realdata
@pytest.mark.parametrize("case", CASES)
def test_truth_within_the_reported_covariance(scenario, case):
    """Filtered errors over days 6-9 and the smoothed epoch states and biases agree with their covariance."""
    res = scenario["results"][case]
    sol, reg, m = res["solution"], res["registry"], res["metrics"]
    for sc in ground.NAMES:
        assert m[sc]["nees"] < 3.0                       # e'P^-1e/3 averaged: errors < 1.7 sigma RMS
        assert m[sc]["err"][-1] < m[sc]["sig3"][-1]
        i = reg.slice("state", sc)
        e = sol.smoothed_x[0, i] - scenario["x0"][sc]
        assert e @ np.linalg.solve(sol.smoothed_P[0, i, i], e) < chi2.ppf(0.999, 6)
    observed = ground.observed_biases(CFG, res["rows"])
    assert len(observed) == {"ground_liaison": 5, "ground": 4, "liaison": 1}[case]   # 3 DSN, Sky Valley, crosslink
    for name in observed:
        k = reg.index(name)
        assert abs(sol.smoothed_x[0, k] - res["rows"].attrs["bias"][name]) < 3.0 * np.sqrt(sol.smoothed_P[0, k, k])


@pytest.mark.realdata
def test_first_pass_flies_the_shared_apriori_segments(scenario):
    """Every fit's first sweep takes all its segments from the a priori ones flown once per set-up (it flies none),
    and they are what a problem of its own would fly, to the last bit."""
    sim = scenario["sim"]
    t0, t1 = sim["t0"], sim["t1"]
    reg = ground.registry(CFG, sim["guess"])
    grid, steps = build_grid(reg, t0, t1, CFG["filter"]["block_s"])
    prob = ground._problem(CFG, sim["setup"], sim["rows"].iloc[:0], reg, sim["fm"], t0, t1,
                           ground.apriori_segments(CFG, sim))
    _sweep(prob, grid, steps, np.zeros(grid.size, int), reg.apriori, {})
    assert prob.n_propagations == 0 and len(prob._segments) == len(sim["apriori_segments"]) // 2 == 72
    own = ground._problem(CFG, sim["setup"], sim["rows"].iloc[:0], reg, sim["fm"], t0, t1)
    seg = prob._segments[40]
    x = reg.apriori.copy()                               # the reference at the start of segment 40
    x[np.r_[prob._state["L1"], prob._state["GEO"], prob._key_idx]] = np.concatenate(
        [seg.trajs[sc].x_start for sc in ground.NAMES] + [seg.key])
    _, flown, _ = own.trajectories(seg.a, x)
    t = np.linspace(seg.a - 100.0, seg.b, 7)
    for sc in ground.NAMES:
        for what in ("state", "stm", "sensitivity"):
            assert np.array_equal(getattr(flown[sc], what)(t), getattr(seg.trajs[sc], what)(t)), (sc, what)


@pytest.mark.realdata
def test_schedule_trade_corners_and_offset(scenario, tmp_path):
    """Fig. 8.4 corners and Fig. 8.9 at a 22-h gap, on the same set-up (its fits shared): both data types beat
    either alone for both spacecraft; offsetting the ground passes by half the gap changes the 3-sigma by
    < 25 % (thesis: "neither satellite's uncertainty or accuracy is impacted significantly")."""
    cfg = load_config(Path(__file__).parents[1] / "runs" / "study_schedule_trade.toml")
    setup_keys = set(CFG) - {"scenario", "cases", "paper", "report", "sensitivity"}
    assert {k: cfg[k] for k in setup_keys} == {k: CFG[k] for k in setup_keys}     # the set-up is the same
    cfg = dict(cfg, mesh={"gaps_h": [0.0, np.inf]}, offset={"gaps_h": [22.0]})
    res = schedule_trade.run(cfg, tmp_path, log=lambda m: None, sim=scenario["sim"])
    mesh = res["mesh"].set_index(["liaison_gap_h", "ground_gap_h"])
    for sc in ground.NAMES:
        both = mesh.loc[(0.0, 0.0), f"{sc} rms_sig3"]
        assert both < mesh.loc[(0.0, np.inf), f"{sc} rms_sig3"] and both < mesh.loc[(np.inf, 0.0), f"{sc} rms_sig3"]
        assert both == pytest.approx(RECORDED[("ground_liaison", sc)]["rms_sig3"], rel=1e-3)
    assert np.all(np.abs(res["ratio"].to_numpy() - 1.0) < 0.25)
    for name in ("report.md", "mesh.png", "offset.png", "mesh.csv", "offset_ratio.csv"):
        assert (tmp_path / name).stat().st_size > 0


# odpipe's figures of the whole runs as docs/validation.md records them (seeded): case -> (L1, GEO) 3-D 3-sigma
# RMS over days 6-9 (m), or the day after which it stays below 100 m
WHOLE_RMS = {"liaison_2_per_day_ground_69": ("50.0", "9.3"), "sparse": ("76", "21")}
WHOLE_BELOW100 = {"ground_liaison_72": ("3.6", "3.1")}


@whole_run
@pytest.mark.realdata
def test_whole_run_other_schedules_against_the_thesis():
    """The schedules the default suite does not fit. Agreement within a factor 2 (module docstring): LiAISON twice a
    day + ground every 3 days (thesis about 50/10 m), the sparse (28, 49) region (about 110/35 m), (72, 0) below
    100 m from day 3/3; snapshots to the recorded digits. The Table 8.3 accelerations tripled bring crosslinks
    only to 125/18.6 m (thesis 160/24): the disagreement above is the noise model's choice."""
    table = run_study("study_ground_and_crosslink")["table"]
    row = {(r["case"], r["spacecraft"]): r for _, r in table.iterrows()}
    paper = CFG["paper"]
    for case, recorded in WHOLE_RMS.items():
        for sc, text in zip(ground.NAMES, recorded):
            got = row[(case, sc)]["odpipe 3s RMS d6-9"]
            assert got == as_recorded(text) and 0.5 < got / paper[case][f"{sc}_rms_sig3"] < 2.0, (case, sc)
    for case, recorded in WHOLE_BELOW100.items():
        for sc, text in zip(ground.NAMES, recorded):
            got = row[(case, sc)]["odpipe day 3s<100 m"]
            assert got == as_recorded(text) and 0.5 < got / paper[case][f"{sc}_below100_d"] < 2.0, (case, sc)
    for sc, text in zip(ground.NAMES, ("125", "18.6")):
        assert row[("liaison (acc x3)", sc)]["odpipe 3s RMS d6-9"] == as_recorded(text)


@whole_run
@pytest.mark.realdata
def test_whole_run_schedule_trade():
    """The Fig. 8.4 mesh and the Fig. 8.9 offset study, recorded figures: GEO needs the crosslinks (351-714 m from
    ground alone, 3.7-73 m with crosslink gaps up to 28 h, 134 and 330 m with crosslinks alone every 52 or
    75 h); crosslinks once a day alone keep the halo at 148 m; offsetting the ground
    passes changes the 3-sigma by 0.88-1.27x at gaps of 6-60 h (thesis: not significantly), but 0.29x for the
    halo at 72 h, where the offset puts a ground pass inside the day 6-9 window; the diagonal's local peaks (the
    thesis' resonances) at 22 h for the halo (60 m against 45 m at 18 h and 53 m at 26 h) and 44 h for GEO
    (35 m against 19 and 28 m)."""
    res = run_study("study_schedule_trade")
    mesh = res["mesh"].set_index(["liaison_gap_h", "ground_gap_h"])
    ground_only = mesh.xs(np.inf, level="liaison_gap_h")["GEO rms_sig3"]
    daily = mesh.loc[[k for k in mesh.index if k[0] <= 28.0], "GEO rms_sig3"]     # crosslink gaps up to 28 h
    assert (ground_only.min(), ground_only.max()) == (as_recorded("351"), as_recorded("714"))
    assert (daily.min(), daily.max()) == (as_recorded("3.7"), as_recorded("72.9"))
    assert [mesh.loc[(g, np.inf), "GEO rms_sig3"] for g in (49.0, 72.0)] == [as_recorded("134"), as_recorded("330")]
    assert mesh.loc[(22.0, np.inf), "L1 rms_sig3"] == as_recorded("148")
    ratio = res["ratio"]
    mid = ratio.loc[(ratio.index >= 6) & (ratio.index <= 60)].to_numpy()
    assert (mid.min(), mid.max()) == (as_recorded("0.88"), as_recorded("1.27"))
    assert ratio.loc[72.0, "L1 rms_sig3"] == as_recorded("0.29")
    diagonal = res["offset"][res["offset"].ground_offset_h == 0].set_index("liaison_gap_h")
    for sc, peak, sides in (("L1", 22.0, (18.0, 26.0)), ("GEO", 44.0, (36.0, 48.0))):
        values = diagonal[f"{sc} rms_sig3"]
        assert values[peak] > max(values[s] for s in sides)
    assert [diagonal["L1 rms_sig3"][g] for g in (18.0, 22.0, 26.0)] == [as_recorded(t) for t in ("45", "60", "53")]
    assert [diagonal["GEO rms_sig3"][g] for g in (36.0, 44.0, 48.0)] == [as_recorded(t) for t in ("19", "35", "28")]


@whole_run
@pytest.mark.realdata
def test_whole_run_geo_ground_only_and_the_correlation_time():
    """Why GEO's uncertainty shrinks from Sky Valley alone, one filter choice changed at a time (recorded): with
    Table 8.3's a priori (1 km, 1 mm/s) 351 m, 15x below the a priori; with a 1-cm/s a priori velocity 1,327 m
    (3.9x), with 0.1 m/s 2,189 m (2.4x; the normal axis keeps 2,130 of its 3,000 m): the 1-mm/s velocity a priori, carried through the
    dynamics, is what makes the ground-only fit shrink it. The correlation time does not matter for GEO (3 h to
    3 d: 350-351 m) and little for the halo, ground only: 30.8, 34.9, 35.8 and 34.2 m at 3 h, 12 h, 1 d and
    3 d (0.44-0.51x the thesis' 70 m): about half the thesis' whatever the choice, and the factor-2 bound
    passes or fails on it (3 h falls outside)."""
    res = run_study("study_ground_and_crosslink")
    geo = res["geo_ground_only"].set_index("filter")["GEO 3s RMS d6-9"]
    assert geo["Table 8.3 (1 km, 1 mm/s, tau 1 d)"] == as_recorded("351")
    assert geo["a priori velocity 0.01 m/s"] == as_recorded("1327")
    assert geo["a priori velocity 0.1 m/s"] == as_recorded("2189")
    assert geo["tau 3 h"] == as_recorded("351")
    tau = res["tau_cases"]
    halo = tau[(tau.case == "ground") & (tau.spacecraft == "L1") & (tau.figure == "3s RMS d6-9")].set_index("tau h")
    assert [halo.loc[h, "odpipe"] for h in (3.0, 12.0, 24.0, 72.0)] == [as_recorded(t) for t in
                                                                     ("30.8", "34.9", "35.8", "34.2")]
    assert halo.loc[3.0, "odpipe/thesis"] < 0.5 < halo.loc[24.0, "odpipe/thesis"]
    assert [geo[f"tau {h} h"] for h in (12, 72)] == [as_recorded("351"), as_recorded("350")]


# odpipe's thesis figures per correlation time of the empirical accelerations (the thesis gives none), every case
# with a thesis figure, as fixtures/studies/ground_and_crosslink_tau.csv records them from a whole run
TAU = stored_figures("ground_and_crosslink_tau")
PAPER_KEY = {"3s RMS d6-9": "rms_sig3", "final 3s": "final_sig3", "day 3s<100 m": "below100_d"}


def _tau_ratios() -> dict:
    """(case, spacecraft, figure) -> {tau h: odpipe/thesis} of the stored figures."""
    out = {}
    for r in TAU.itertuples():
        thesis = CFG["paper"][r.case][f"{r.spacecraft}_{PAPER_KEY[r.figure]}"]
        out.setdefault((r.case, r.spacecraft, r.figure), {})[float(r.tau_h)] = float(r.odpipe) / thesis
    return out


@whole_run
@pytest.mark.realdata
def test_whole_run_correlation_time_figures_as_stored():
    """The whole run's figures per correlation time equal the stored ones to their recorded digits."""
    tau = run_study("study_ground_and_crosslink")["tau_cases"]
    got = {(r["case"], r["spacecraft"], r["figure"], r["tau h"]): r["odpipe"] for _, r in tau.iterrows()}
    for r in TAU.itertuples():
        assert got[(r.case, r.spacecraft, r.figure, float(r.tau_h))] == as_recorded(r.odpipe), r


@pytest.mark.slow
@pytest.mark.realdata
def test_crosslinks_only_at_a_3_h_correlation_time_as_stored(scenario):
    """A fast check on the stored spread: crosslinks only refitted with a 3-h correlation time on the default
    suite's set-up gives the stored figures (relative 1e-3, the snapshots' tolerance: the run is seeded)."""
    cfg_tau = dict(CFG, filter=dict(CFG["filter"], acc_tau_s=3 * 3600.0))
    m = ground.fit_schedule(CFG, scenario["sim"], CFG["cases"]["liaison"], cfg_tau)["metrics"]
    stored = {r.spacecraft: float(r.odpipe) for r in TAU.itertuples() if r.case == "liaison" and float(r.tau_h) == 3.0}
    for sc in ground.NAMES:
        assert m[sc]["rms_sig3"] == pytest.approx(stored[sc], rel=1e-3), sc


def test_stored_correlation_time_spread_against_the_thesis():
    """The thesis does not give its empirical accelerations' correlation time; the stored figures at 3 h, 12 h, 1 d
    and 3 d (each schedule at all four since 2026-11-26) say which figures depend on it (odpipe/thesis,
    min / median / max):

    - none moves more than 1.5x over the range: most with the halo, crosslinks only (1.43-1.50x), ground +
      crosslinks' final halo (1.43x) and (9, 69)'s halo (1.38x); the GEO figures 1.0-1.3x, the days below 100 m
      1.0-1.2x. The 3-h correlation time gives the smallest uncertainties;
    - crosslinks only is 2.5-4.5x tighter than the thesis whatever the choice (halo 0.22 / 0.29 / 0.31x of 160 m,
      GEO 0.26 / 0.31 / 0.34x of 24 m; twice a day: GEO 0.31 / 0.37 / 0.40x of 30 m, the halo 44-66 m under the
      thesis' "< 200 m"): that disagreement is not the correlation time's;
    - every other schedule stays within the factor 2 at every correlation time: ground + crosslinks' final halo
      1.26 / 1.73 / 1.80x of "on the order of 10 m", GEO 0.84 / 0.94 / 0.97x; (9, 69) 0.72-1.00x; sparse
      0.55-1.09x; (0, 72) and (72, 0) days below 100 m 1.05-1.79x; the ground-only halo falls outside it at 3 h
      (0.44x), as recorded before. Tolerance: the factor 2 of the module docstring."""
    ratios = _tau_ratios()
    spreads = {key: spread(list(by_tau.values())) for key, by_tau in ratios.items()}
    assert {len(by_tau) for by_tau in ratios.values()} == {4} and len(ratios) == 17
    for key, s in spreads.items():
        assert s["ratio max"] / s["ratio min"] < 1.6, key
    for case in ("liaison", "liaison_2_per_day"):
        assert spreads[(case, "GEO", "3s RMS d6-9")]["ratio max"] < 0.5, case
    assert spreads[("liaison", "L1", "3s RMS d6-9")]["ratio max"] < 0.5
    assert spreads[("liaison_2_per_day", "L1", "3s RMS d6-9")]["ratio max"] < 1.0      # thesis: "< 200 m"
    for key in [k for k in spreads if k[0] not in ("ground", "liaison", "liaison_2_per_day")]:
        assert 0.5 < spreads[key]["ratio min"] and spreads[key]["ratio max"] < 2.0, key
    halo_ground = ratios[("ground", "L1", "3s RMS d6-9")]
    assert halo_ground[3.0] < 0.5 < halo_ground[24.0]


def test_uncertainty_plot_legend_covers_no_curve(monkeypatch, tmp_path):
    """uncertainty.png's legend of the nine schedules sat in the GEO panel over the ground-only curves (300-500 m,
    days 3-9); with more than 4 curves it has a column of its own, inside the figure and clear of every panel."""
    import numpy as np

    from odpipe.studies import study_report

    saved = []
    monkeypatch.setattr(study_report, "save_figure", lambda path, fig, **kw: saved.append(fig))
    t = np.linspace(0.0, 9.0, 50)
    curves = [(name, 5000.0 * np.exp(-t * (i + 1) / 5.0) + 10.0, {}) for i, name in enumerate(CFG["cases"])]
    assert len(curves) > 4
    study_report.plot_convergence(tmp_path, "uncertainty", [{"title": sc, "t_days": t, "curves": curves}
                                                            for sc in ground.NAMES], "m")
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = saved[0]
    renderer = FigureCanvasAgg(fig).get_renderer()   # the figure is closed once saved
    legend = fig.axes[1].get_legend().get_window_extent(renderer)
    assert not any(legend.overlaps(ax.get_window_extent(renderer)) for ax in fig.axes)
    page = fig.bbox
    assert page.x0 <= legend.x0 and legend.x1 <= page.x1 and page.y0 <= legend.y0 and legend.y1 <= page.y1


def test_log_axis_labels_are_plain_numbers(monkeypatch, tmp_path):
    """schedule_trade's GEO offset panel (1.6-45 m, about a decade) labelled its ticks 2×10⁰ ... 4×10¹; they read
    2, 3, 4, 6, 10, 20, 30, 40, on the ticks matplotlib labels."""
    import numpy as np

    from odpipe.studies import study_report

    saved = []
    monkeypatch.setattr(study_report, "save_figure", lambda path, fig, **kw: saved.append(fig))
    t = np.arange(0.0, 80.0, 8.0)
    study_report.plot_convergence(tmp_path, "offset", [{"title": "GEO", "t_days": t,
                                                        "curves": [("a", np.geomspace(1.6, 45.0, t.size), {})]}], "m")
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = saved[0]
    FigureCanvasAgg(fig).draw()
    ax = fig.axes[0]
    shown = [t.get_text() for t in ax.get_yticklabels(minor=False) + ax.get_yticklabels(minor=True) if t.get_text()]
    assert {"2", "10", "40"} <= set(shown) and all(s.replace(".", "").isdigit() for s in shown), shown
