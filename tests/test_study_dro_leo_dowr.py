"""Scenario 3 (Li et al., DRO-LEO dual one-way ranging): the problem's rows against the one-way
pseudoranges of eq. 2 computed directly, its partials against finite differences, and a reduced
run against the paper (clock accuracy of the DOWR mode, DOWR better than one-way ranging)."""

from pathlib import Path

import numpy as np
import pytest

from odpipe.studies.scenarios import load_config
from odpipe.dynamics.forces import AtmosphericDrag, ForceModel, PointMasses, SolarRadiationPressure
from odpipe.dynamics.propagator import propagate
from odpipe.estimation.registry import ParameterRegistry
from odpipe.studies import dro_leo_dowr as dowr
from odpipe.measurements import MeasurementSetup
from odpipe.constants import C_LIGHT
from odpipe.measurements.crosslink import ClockModel, one_way_pseudorange
from odpipe.measurements.lighttime import solve_path
from odpipe.measurements.nodes import SpacecraftNode
from odpipe.time import utc_to_tdb
from study_runs import as_recorded, run_study, stored_figures, whole_run

ROOT = Path(__file__).resolve().parents[1]
CFG = load_config(ROOT / "runs/study_dro_leo_dowr.toml")
EPOCH = np.datetime64(CFG["epoch_utc"], "ns")
T0 = float(utc_to_tdb(EPOCH))


@pytest.fixture(scope="module")
def meas():
    return MeasurementSetup.default()


def _states(eph):
    le = CFG["leo_elements"]
    return {"DRO": np.asarray(CFG["dro_state_km"], float) * 1e3,
            "LEO": dowr.circular_state(eph.gm("earth"), le["a_km"] * 1e3,
                                       *np.radians([le["inc_deg"], le["raan_deg"], le["u_deg"]]))}


def _models(eph):
    fm = {sc: ForceModel("earth", [PointMasses(["sun", "moon"]), SolarRadiationPressure(cr_area=2.6)],
                         mass=1000.0, ephemeris=eph) for sc in dowr.NAMES}
    fm["LEO"].components.append(AtmosphericDrag(2.5, 2.0))
    return fm


def _problem(meas, x, clock):
    """Rows at 3 epochs of each kind in the first hour, registry [states, c*a0..a2, delay, LEO cd]."""
    reg = ParameterRegistry()
    for sc in dowr.NAMES:
        reg.add_state(sc, x[sc], 1e3, 0.1)
    for k, v in zip(dowr.CLOCK_KEYS, (clock.a0, clock.a1, clock.a2)):
        reg.add(f"DRO.clock.{k}", "clock", C_LIGHT * v, 1.0, owner="DRO.clock", clock=k)
    reg.add("delay", "bias", 2.0, 1.0, observables=("dowr_sum", dowr.ONE_WAY))
    reg.add("LEO.cd", "dynamic", 2.5, 0.1, owner="LEO", model="cd")
    epochs = EPOCH + (np.array([600, 600, 900, 900, 1200, 1200, 1500, 1800, 2100]) * 1e9).astype("timedelta64[ns]")
    obs = ["dowr_sum", "dowr_diff"] * 3 + [dowr.ONE_WAY] * 3
    rows = dowr._rows(epochs, obs)
    times = np.asarray(utc_to_tdb(epochs), float)
    prob = dowr.DowrProblem(reg, rows, times, _models(meas.ephemeris), meas, T0, T0 + 3600.0, lookback=10.0,
                            clock_sc="DRO", clock_ref=T0)
    return prob, reg, times


def test_rows_are_li_eq2_pseudoranges_and_partials_match_differences(meas):
    eph = meas.ephemeris
    x = _states(eph)
    clock = ClockModel(1e-6, 5e-9, 5e-12 / 86400, T0)
    prob, reg, times = _problem(meas, x, clock)
    x0 = reg.apriori
    computed, H = prob.predict(T0, x0, np.arange(times.size))
    # direct: the two one-way pseudoranges of eq. 2 at each reception epoch, delay 2 m on each
    trajs = {sc: propagate(x[sc], T0, T0 + 3600.0, fm, with_stm=False) for sc, fm in _models(eph).items()}
    dro, leo = (SpacecraftNode(trajs[sc], eph, "ssb", sc) for sc in dowr.NAMES)
    paths = (solve_path([leo, dro], times, ephemeris=eph, shapiro_bodies=("sun", "earth")),
             solve_path([dro, leo], times, ephemeris=eph, shapiro_bodies=("sun", "earth")))
    r_dl, r_ld = (one_way_pseudorange(p, *c).value + 2.0 for p, c in zip(paths, ((ClockModel(), clock),
                                                                                (clock, ClockModel()))))
    obs = prob.rows["observable"].to_numpy()
    expect = np.where(obs == "dowr_sum", 0.5 * (r_dl + r_ld), np.where(obs == "dowr_diff", 0.5 * (r_dl - r_ld), r_ld))
    np.testing.assert_allclose(computed, expect, rtol=0, atol=2e-3)   # the two integrations differ by < 1 mm
    # eq. 3: the sum keeps the geometry (~400,000 km); eq. 5: with the geometric part (the motion
    # during the light time, tens of km) removed, the difference is c (offset(t) - rate tau / 2)
    r_dl0, r_ld0 = (one_way_pseudorange(p, ClockModel(), ClockModel()).value for p in paths)
    tau = computed[0:6:2] / C_LIGHT
    assert np.all(tau > 1.0)
    eq5 = C_LIGHT * (clock.offset(times[1:6:2]) - clock.rate(times[1:6:2]) * tau / 2)
    np.testing.assert_allclose((computed - 0.5 * (r_dl0 - r_ld0))[1:6:2], eq5, rtol=0, atol=2e-3)
    # partials: finite differences through rebuilt references (steps well above the ~mm integration noise)
    # (Cd moves the LEO by 1.5 cm per unit at the last row, against ~0.3 mm of integration noise:
    # checked there only, which shows that the reference flies the estimated Cd)
    for name, step, rtol, floor in (("DRO.x", 10.0, 1e-4, 1e-3), ("LEO.vy", 0.1, 1e-4, 1e-3),
                                    ("DRO.clock.a0", 1.0, 1e-4, 1e-3), ("DRO.clock.a1", 1e-4, 1e-4, 1e-3),
                                    ("delay", 1.0, 1e-4, 1e-3), ("LEO.cd", 1.0, 0.05, 0.5)):
        i = reg.index(name)
        vals = []
        for s in (step, -step):
            xs = x0.copy()
            xs[i] += s
            vals.append(prob.predict(T0, xs, np.arange(times.size))[0])
        fd = (vals[0] - vals[1]) / (2 * step)
        big = np.abs(fd) > floor * np.abs(fd).max()
        np.testing.assert_allclose(H[big, i], fd[big], rtol=rtol, err_msg=name)
    assert np.all(H[1:6:2, reg.index("delay")] == 0.0)   # D_sub = 0: the delay is not in the difference
    assert np.abs(H[0:6:2, reg.index("DRO.clock.a0")]).max() < 1e-12  # the sum cancels the clock offset (eq. 3)


@pytest.mark.realdata
def test_reduced_run_dowr_clock_and_mode_ordering(shared_data, tmp_path):
    """Three days, the true dynamics (Model-A, fields cut to degree 20 for speed), DOWR (Simu. 6) against
    one-way ranging (the Simu. 8 link plan): Table 13's ordering (one-way 7x worse on the clock and
    20-240x on the DRO position), the LEO converging first (Simu. 6: 2 days), the clock below 100 ns
    (sec. 5.4.3). (Table 13's 40-day figures themselves need the full run: runs/study_dro_leo_dowr.toml.)"""
    cfg = dict(CFG, arc_days=3.0, last_days=1.0, stage_days=[0.5], max_iter=4, final_iter=2,
               earth_gravity=str(shared_data / "gravity/tudat/ggm02c.txt"),
               moon_gravity=str(shared_data / "gravity/gmat/LP165P.cof"))
    cfg["model"] = dict(CFG["model"], truth=dict(CFG["model"]["truth"], earth_degree={"DRO": 4, "LEO": 20},
                                                   moon_degree={"DRO": 8}))
    cfg["model"]["A"] = cfg["model"]["truth"]
    sims = {s["name"]: s for s in CFG["simulation"]}
    cfg["simulation"] = [sims["Simu. 6"], dict(sims["Simu. 8"], model="A", snc_mps2=sims["Simu. 6"]["snc_mps2"])]
    res = dowr.run(cfg, tmp_path, log=lambda m: None)["results"]
    d, o = res["Simu. 6"], res["Simu. 8"]
    assert d["clock_ns"] < 100.0 and o["clock_ns"] > 5 * d["clock_ns"]
    assert o["DRO"]["pos"] > 5 * d["DRO"]["pos"]
    assert d["LEO"]["converge_days"] is not None and d["LEO"]["converge_days"] < 2.0
    assert d["LEO"]["pos"] < 0.2 * d["DRO"]["pos"]
    assert (tmp_path / "report.md").read_text().count("Simu.") >= 4


# Table 13 as odpipe computes it for the shipped configurations (docs/validation.md, session 6; the runs are
# seeded): simulation -> (DRO pos m, LEO pos m, clock ns), each to the digits recorded there
TABLE13 = {"Simu. 1": ("12.2", "133", "10.3"), "Simu. 2": ("7.85", "13.6", "10.3"), "Simu. 3": ("7.26", "11.9", "10.3"),
           "Simu. 4": ("59.0", "100", "10.3"), "Simu. 5": ("186", "5709", "10.5"), "Simu. 6": ("0.27", "0.40", "10.3"),
           "Simu. 7": ("54.6", "68.0", "10.3"), "Simu. 8": ("67.2", "17.9", "54.0"), "Simu. 9": ("9.8", "16.6", "9.8")}


def _table13():
    results = {}
    for config in ("study_dro_leo_dowr", "study_dro_leo_dowr_integrators"):
        results.update(run_study(config)["results"])
    return results


@whole_run
def test_whole_run_table13_snapshot():
    """odpipe's Table 13 (DRO and LEO 3-D position RMS over the last 8 days, DRO clock accuracy) to the digits
    docs/validation.md records: a several-fold change cannot pass."""
    results = _table13()
    for name, (dro, leo, clock) in TABLE13.items():
        acc = results[name]
        for got, want in ((acc["DRO"]["pos"], dro), (acc["LEO"]["pos"], leo), (acc["clock_ns"], clock)):
            assert got == as_recorded(want), name


@whole_run
def test_whole_run_table13_against_the_paper():
    """Simulations 2, 3, 6 and 8 (DOWR with Model-B and the true model, the 30-s integrator, one-way ranging):
    every position and clock figure within a factor 2 of the paper's (odpipe 0.52-1.57x). Tolerance: the paper
    leaves the LEO time error's correlation time, the clock offset, the delay, the sampling and the initial
    errors open, and runs one EKF pass where odpipe iterates a filter-smoother. The others do not agree and
    are recorded by the snapshot: Simu. 4 and 5 (coarse fixed steps) LEO 4-8x worse, Simu. 9 DRO 7.5x better
    (the pass alternation is not given), Simu. 1 LEO 2.6x worse, Simu. 7 LEO 3x better."""
    results = _table13()
    sims = {s["name"]: s for s in load_config(ROOT / "runs/study_dro_leo_dowr.toml")["simulation"]
            + load_config(ROOT / "runs/study_dro_leo_dowr_integrators.toml")["simulation"]}
    for name in ("Simu. 2", "Simu. 3", "Simu. 6", "Simu. 8"):
        acc, paper = results[name], sims[name]["paper"]
        for got, want in ((acc["DRO"]["pos"], paper["DRO"]["pos_m"]), (acc["LEO"]["pos"], paper["LEO"]["pos_m"]),
                          (acc["clock_ns"], paper["clock_ns"])):
            assert 0.5 < got / want < 2.0, name
    # the paper's orderings: DOWR beats one-way ranging on the DRO, the true model beats Model-B
    assert results["Simu. 8"]["DRO"]["pos"] > 5 * results["Simu. 2"]["DRO"]["pos"]
    assert results["Simu. 2"]["DRO"]["pos"] > 10 * results["Simu. 6"]["DRO"]["pos"]


def test_pass_plan_phase_and_dowr_in_a_one_way_pass_s_place(meas, monkeypatch):
    """Simu. 9's plan (sec. 2.2 (3)): one-way 1 h every 12 h, DOWR 1 h every 120 h from ``first_h``. A DOWR pass at
    a one-way pass's start takes its place (no one-way rows at those epochs); one from 6 h falls between two."""
    cfg = dict(CFG, arc_days=10.0)
    hours = (dowr.pass_epochs(cfg, 120.0, 24.0) - EPOCH) / np.timedelta64(1, "s") / 3600.0
    assert hours.size == 2 * 60 and hours[0] == 24.0 + 1 / 60 and hours[60] == 144.0 + 1 / 60   # 1-min samples
    assert dowr.pass_epochs(cfg, 12.0).size == 20 * 60                                          # 0, 12, ..., 228 h

    class Fixed:                        # far apart, the link clear of the Earth at every epoch
        def __init__(self, x):
            self.x = x

        def state(self, t):
            return np.tile([self.x, 0, 0, 0, 0, 0], (np.size(t), 1)).astype(float)

    def noise_free(rows, truth, setup):
        return type("Ev", (), {"value": np.full(len(rows), 3.9e8), "status": np.full(len(rows), "", object)})()

    monkeypatch.setattr(dowr, "compute", noise_free)
    clocks = dowr.ClockTruth(CFG["clock"], T0, T0 + 10 * 86400.0, np.random.default_rng(1))
    for first, n_oneway in ((24.0, 18 * 60), (6.0, 20 * 60)):
        plan = [{"type": "oneway", "every_h": 12.0}, {"type": "dowr", "every_h": 120.0, "first_h": first}]
        rows, _ = dowr.simulate(cfg, meas, {"DRO": Fixed(4e8), "LEO": Fixed(7e6)}, clocks, plan,
                                np.random.default_rng(2))
        counts = rows["observable"].value_counts()
        assert counts[dowr.ONE_WAY] == n_oneway and counts["dowr_sum"] == counts["dowr_diff"] == 2 * 60, first


def test_variant_spread_is_min_median_max_over_the_variants():
    sims = [{"name": f"v{i}", "variant_of": "Simu. 9",
             "paper": {"clock_ns": 40.0, "DRO": {"pos_m": 80.0}, "LEO": {"pos_m": 20.0}}} for i in range(3)]
    sims.append({"name": "alone", "paper": sims[0]["paper"]})
    results = {f"v{i}": {"DRO": {"pos": p}, "LEO": {"pos": 10.0}, "clock_ns": 40.0 * (i + 1)}
               for i, p in enumerate((40.0, 160.0, 80.0))}
    table = dowr.variant_spread(sims, results).set_index("figure")
    assert list(table["variants"]) == [3, 3, 3]
    assert table.loc["DRO pos [m]", ["odpipe min", "odpipe median", "odpipe max"]].tolist() == [40.0, 80.0, 160.0]
    assert table.loc["DRO pos [m]", ["ratio min", "ratio median", "ratio max"]].tolist() == [0.5, 1.0, 2.0]
    assert table.loc["clock [ns]", "ratio max"] == 3.0 and table.loc["LEO pos [m]", "ratio median"] == 0.5


# Simu. 9 over the DOWR pass's phase in its 120-h cycle (runs/study_dro_leo_dowr_alternation.toml), as
# fixtures/studies/dro_leo_dowr_alternation.csv records the variants run: first_h -> figures (text)
ALTERNATION = stored_figures("dro_leo_dowr_alternation")
SIMU9 = next(s for s in CFG["simulation"] if s["name"] == "Simu. 9")


def _alternation_ratios() -> dict:
    """figure -> odpipe/paper over the stored variants."""
    paper = {"DRO_pos_m": SIMU9["paper"]["DRO"]["pos_m"], "LEO_pos_m": SIMU9["paper"]["LEO"]["pos_m"],
             "clock_ns": SIMU9["paper"]["clock_ns"]}
    return {k: ALTERNATION[k].astype(float).to_numpy() / v for k, v in paper.items()}


@whole_run
def test_whole_run_alternation_as_stored():
    """The whole alternation run gives the stored variants' figures to their recorded digits."""
    results = run_study("study_dro_leo_dowr_alternation")["results"]
    for r in ALTERNATION.itertuples():
        acc = results[f"Simu. 9, DOWR every 120 h from {r.first_h} h"]
        for got, want in ((acc["DRO"]["pos"], r.DRO_pos_m), (acc["LEO"]["pos"], r.LEO_pos_m),
                          (acc["clock_ns"], r.clock_ns)):
            assert got == as_recorded(want), r.first_h


def test_stored_alternation_spread_against_the_paper():
    """Simu. 9 with the paper's DOWR rate (1 h every 120 h), over where the DOWR pass falls in the cycle (the paper
    does not say; stored: first_h 0, 6, 24, 48, 72 and 96 h). The DRO position is sensitive to that choice:
    13.9-46.9 m, odpipe/paper 0.19 / 0.36 / 0.64 (min / median / max of the paper's 73.3 m; 3.4x between phases),
    converged after 16.0-30.3 days (paper 30). The LEO (15.4-19.0 m, 0.68 / 0.73 / 0.84x of 22.6 m) and the clock
    (10.5-16.7 ns, 0.23 / 0.28 / 0.36x of 46.6 ns) less. The shipped Simu. 9 (DOWR every 24 h, 5x the paper's
    rate) gives the DRO 9.8 m, below the whole range. Tolerance: the LEO within the factor 2 of the other Table 13
    comparisons at every phase; the DRO below the paper at every phase (recorded disagreement, by how much depends
    on the phase); the clock about 3x better (recorded: the truth clock's random walk between passes)."""
    ratios = _alternation_ratios()
    assert sorted(ALTERNATION["first_h"].astype(float)) == [0.0, 6.0, 24.0, 48.0, 72.0, 96.0]
    assert np.all((0.5 < ratios["LEO_pos_m"]) & (ratios["LEO_pos_m"] < 2.0))
    assert np.all(ratios["DRO_pos_m"] < 1.0) and ratios["DRO_pos_m"].max() / ratios["DRO_pos_m"].min() > 3.0
    assert np.all(ratios["clock_ns"] < 0.5)
    assert ALTERNATION["DRO_pos_m"].astype(float).min() > float(TABLE13["Simu. 9"][0])   # the 24-h plan's 9.8 m
    conv = ALTERNATION["DRO_converge_d"].astype(float)
    assert np.all((conv > 15.0) & (conv <= 30.5))
