"""Scenario 1b (Fujimoto et al. secs. 3-4) plumbing: the simulated crosslink Doppler and the
fit's TrackingProblem agree on the same trajectory; the Earth blocks the link geometrically."""

from pathlib import Path

import numpy as np
import pytest

from odpipe.studies.scenarios import load_config
from odpipe.dynamics.propagator import propagate
from odpipe.estimation.fit import Observations, build_grid
from odpipe.estimation.registry import ParameterRegistry
from odpipe.studies.halo_geo_doppler import (NAMES, R_EARTH, _rows, cases, evaluate, force_models, link_clear,
                                            simulate)
from odpipe.measurements import MeasurementSetup, compute
from odpipe.od.problem import TrackingProblem
from odpipe.studies.ekf import ekf
from odpipe.time import utc_to_tdb
from study_runs import as_recorded, run_study, stored_figures, whole_run

CFG = load_config(Path(__file__).parents[1] / "runs" / "study_halo_geo_doppler.toml")


def test_link_blocked_only_through_the_earth():
    r1 = np.array([[2 * R_EARTH, 0, 0], [2 * R_EARTH, 0, 0], [2 * R_EARTH, 0, 0]])
    r2 = np.array([[-2 * R_EARTH, 0, 0], [-2 * R_EARTH, 3 * R_EARTH, 0], [4 * R_EARTH, 0, 0]])  # miss by 1.2 R
    assert list(link_clear(r1, r2)) == [False, True, True]


def _short_arc(offset_m=0.0):
    """0.2 days of noise-free crosslink Doppler every 1000 s on the filter's dynamics, a priori states ``offset_m``
    off along x: (rows kept -> TrackingProblem over them, simulated values, rows' TDB times, t0, t1)."""
    meas = MeasurementSetup.default()
    start = np.datetime64(CFG["epoch_utc"], "ns")
    t0 = float(utc_to_tdb(start))
    t1 = t0 + 0.2 * 86400.0
    fm = force_models(CFG, meas.ephemeris, "filter")
    x0 = {sc: np.asarray(CFG["state"][sc], float) for sc in NAMES}
    truth = {sc: propagate(x0[sc], t0, t1 + 60.0, fm[sc]) for sc in NAMES}
    epochs = start + np.arange(1, 17) * np.timedelta64(1000, "s")
    rows = _rows(epochs, CFG)
    times = np.asarray(utc_to_tdb(epochs), float)
    simulated = compute(rows, truth, meas).value
    reg = ParameterRegistry()
    for sc in NAMES:
        reg.add_state(sc, x0[sc] + np.r_[offset_m, 0.0, 0.0, 0.0, 0.0, 0.0], 100.0, 0.1)
        reg.add_stochastic_acceleration(sc, 2e-7, 0.0, 1000.0)
    reg.add("bias.sst_doppler", "bias", 0.0, 1e-3, owner="L1", observable="sst_doppler")
    grid, _ = build_grid(reg, t0, t1, 1000.0)

    def problem(kept=slice(None)):
        return TrackingProblem(reg, rows.iloc[kept], times[kept], fm, meas, t0, t1, lookback=180.0, epochs=grid)
    return problem, simulated, times, t0, t1


@pytest.mark.realdata
def test_simulated_doppler_equals_the_fit_reference():
    problem, simulated, _, _, _ = _short_arc()
    prob = problem()
    reg = prob.registry
    reference, to_los, status = prob.reference(reg.apriori)
    assert set(status) == {""}
    assert np.all(np.abs(simulated) > 100.0)                       # GEO-halo round-trip rates, m/s
    # same model and data; the fit integrates per 1000-s segment at atol 1e-6 m: a few um/s,
    # well below the X-band noise (0.1 mm/s)
    assert np.max(np.abs(reference - simulated)) < 2e-5
    assert np.allclose(to_los, 0.5)


@pytest.mark.realdata
def test_ekf_transitions_from_a_problem_without_rows_are_the_same():
    """The EKF's transitions asked from a problem without rows (``dynamics``: no measurement evaluated on the
    references flown after each update) give the same pass, to the last bit, as from the problem with the rows;
    the a priori is 100 m off, so every update moves the reference."""
    problem, simulated, times, t0, t1 = _short_arc(offset_m=100.0)
    obs = Observations(times, simulated + 1e-4, np.full(times.size, 1e-4), np.zeros(times.size, int))
    slow = ekf(problem(), obs, t0, t1, 1000.0)
    fast = ekf(problem(), obs, t0, t1, 1000.0, dynamics=problem(slice(0)))
    assert np.abs(slow.x[-1, :3] - slow.x[0, :3]).max() > 1.0               # the reference moved
    for a, b in ((slow.x, fast.x), (slow.P, fast.P), (slow.postfit, fast.postfit)):
        assert np.array_equal(a, b, equal_nan=True)


# odpipe's Tables 4-6 for the shipped configuration (3-D RMS over the last half of the arc; seeded whole runs), as
# fixtures/studies/halo_geo_doppler_tables456.csv records them: (case, estimator, spacecraft, Pos|Vel) -> text
FIGURES = {(r.case, r.estimator, r.spacecraft, r.quantity): r.odpipe_3d
           for r in stored_figures("halo_geo_doppler_tables456").itertuples()}


def _stored(case, estimator, sc, quantity="Pos") -> float:
    return float(FIGURES[(case, estimator, sc, quantity)])


def _paper(case, sc, quantity="Pos") -> float:
    return CFG["paper"][case][f"{sc}_{quantity.lower()}"][3]


def _table():
    table = run_study("study_halo_geo_doppler")["table"]
    return {(r["case"], r["estimator"], r["spacecraft"], r["quantity"].split()[0]): r for _, r in table.iterrows()}


@whole_run
def test_whole_run_tables456_snapshot():
    """The whole run gives every stored figure to its recorded digits: the tests on the stored figures below hold
    for the code as it is."""
    rows = _table()
    for key, recorded in FIGURES.items():
        assert rows[key]["odpipe 3D"] == as_recorded(recorded), key


def test_stored_tables45_disagree_with_the_paper_as_recorded():
    """odpipe's filter-smoother does NOT reproduce Tables 4-5: its positions are 1.8-7.5x better than the paper's
    (S band: L1 0.56x, GEO 0.33x; X band 0.28x, 0.13x), and its X band is 2-2.4x better than its S band where the
    paper's two bands are nearly equal. What does agree: the GEO satellite is better determined than the halo in
    both bands, as in the paper."""
    for band in ("S", "X"):
        for sc in ("L1", "GEO"):
            assert _stored(band, "filter_smoother", sc) / _paper(band, sc) < 0.6
        assert _stored(band, "filter_smoother", "GEO") < _stored(band, "filter_smoother", "L1")
    assert _stored("X", "filter_smoother", "L1") < 0.6 * _stored("S", "filter_smoother", "L1")


def test_stored_the_paper_s_ekf_is_not_the_cause():
    """The paper's estimator, one EKF pass with the same SNC, gives odpipe's filter-smoother's positions to within
    5 % in both bands and in Table 6 (S: L1 165.0 against 165 m, GEO 25.0 against 25.0 m; X: 82.1 against 82 m,
    10.6 against 10.6 m; Table 6 GEO: 23.6 against 23.6 m): the 1.8-7.5x gap to Tables 4-5 does not come from iterating
    and smoothing. Tolerance 5 %: both are forward filters of the same model and data, only the linearization
    differs. The S-band halo velocity, 1.8x the paper's, is the EKF's too (3.78 against 2.08 mm/s); in the X band
    it is 0.65x (1.44 against 2.19)."""
    for case, sc in (("S", "L1"), ("S", "GEO"), ("X", "L1"), ("X", "GEO"), ("S_L1_known", "GEO")):
        assert _stored(case, "ekf", sc) == pytest.approx(_stored(case, "filter_smoother", sc), rel=0.05), (case, sc)
        assert _stored(case, "ekf", sc) / _paper(case, sc) < 0.6
    assert _stored("S", "ekf", "L1", "Vel") / _paper("S", "L1", "Vel") > 1.5


def test_stored_table6_halo_known_is_no_better_as_in_the_paper():
    """Table 6 (S band, the halo's state known): the paper finds the GEO satellite no better than with both states
    estimated (79.3 against 75.0 m, 1.06x). Every estimator agrees: the filter-smoother and the EKF with SNC per
    interval (23.6 against 25.0 m, 0.94x) and the EKF with SNC over the data gaps (48.4 against 49.4 m, 0.98x);
    tolerance 0.8-1.2x, "not any better" read as within 20 %. The level stays below the paper's: 0.30x and 0.61x
    (recorded disagreement, as Tables 4-5)."""
    assert _paper("S_L1_known", "GEO") / _paper("S", "GEO") == pytest.approx(1.056, abs=1e-3)
    for estimator in ("filter_smoother", "ekf", "ekf_gap_snc"):
        assert 0.8 < _stored("S_L1_known", estimator, "GEO") / _stored("S", estimator, "GEO") < 1.2, estimator
    assert _stored("S_L1_known", "ekf", "GEO") / _paper("S_L1_known", "GEO") < 0.4
    assert 0.5 < _stored("S_L1_known", "ekf_gap_snc", "GEO") / _paper("S_L1_known", "GEO") < 0.7


def test_stored_snc_over_the_data_gaps_moves_toward_the_paper():
    """Eqs. 10-11 taken literally (Gamma Q Gamma^T over the time since the previous point, so the GEO cut-off's
    gaps of about 13 intervals get 13^2 times one interval's velocity variance instead of 13 times) multiply the
    per-interval EKF's positions 2.0-3.0x in both bands and in Table 6, every one toward the paper's:
    S band L1 499 m (1.70x the paper's 293 m), GEO 49.4 m (0.66x); X band L1 223 m (0.75x), GEO 31.7 m (0.40x);
    Table 6 GEO 48.4 m (0.61x). Tolerance: the halo within the factor 2 the other studies allow, in both bands;
    GEO below the paper in every case (0.40-0.66x; the X band's outside the factor 2: recorded disagreement). The
    S-band halo velocity, 7.48 mm/s, is 3.6x the paper's: the gap noise overshoots it where the per-interval EKF
    was 1.8x."""
    for case, sc in (("S", "L1"), ("S", "GEO"), ("X", "L1"), ("X", "GEO"), ("S_L1_known", "GEO")):
        ratio = _stored(case, "ekf_gap_snc", sc) / _stored(case, "ekf", sc)
        assert 1.9 < ratio < 3.5, (case, sc)
        assert abs(np.log(_stored(case, "ekf_gap_snc", sc) / _paper(case, sc))) < abs(
            np.log(_stored(case, "ekf", sc) / _paper(case, sc))), (case, sc)         # toward the paper's
    for band in ("S", "X"):
        assert 0.5 < _stored(band, "ekf_gap_snc", "L1") / _paper(band, "L1") < 2.0, band
    for case in ("S", "X", "S_L1_known"):
        assert _stored(case, "ekf_gap_snc", "GEO") / _paper(case, "GEO") < 0.7, case
    assert _stored("X", "ekf_gap_snc", "GEO") / _paper("X", "GEO") < 0.5
    assert _stored("S", "ekf_gap_snc", "L1", "Vel") / _paper("S", "L1", "Vel") > 3.0


# the study on its first 1.5 days (S band and Table 6; the EKF with SNC per interval and over the data gaps), as
# fixtures/studies/halo_geo_doppler_short_arc.csv records it
SHORT = {(r.case, r.estimator, r.spacecraft, r.quantity): r.odpipe_3d
         for r in stored_figures("halo_geo_doppler_short_arc").itertuples()}


@pytest.mark.slow
@pytest.mark.realdata
def test_short_arc_as_recorded():
    """A fast check on the code behind the stored whole-run figures: the same study cut to 1.5 days (88 tracked
    epochs, the GEO cut-off's first gaps included) gives its recorded figures within 10 %. Tolerance: wide enough
    for integrator and light-time changes elsewhere (fractions of a per cent), far inside the several-fold
    change a broken SNC, gap noise, Doppler model or EKF update would make."""
    cfg = dict(CFG, arc_days=1.5, bands=["S"], known_bands=["S"])
    sim = simulate(cfg, log=lambda m: None)
    got = {}
    for case, band, known in cases(cfg):
        for estimator in ("ekf", "ekf_gap_snc"):
            for r in evaluate(cfg, sim, case, band, known, estimator, log=lambda m: None)[1]:
                got[(case, estimator, r["spacecraft"], r["quantity"].split()[0])] = r["odpipe 3D"]
    assert set(got) == set(SHORT)
    for key, recorded in SHORT.items():
        assert got[key] == pytest.approx(float(recorded), rel=0.1), key
