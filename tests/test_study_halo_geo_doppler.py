"""Scenario 1b (Fujimoto et al. secs. 3-4) plumbing: the simulated crosslink Doppler and the
fit's TrackingProblem agree on the same trajectory; the Earth blocks the link geometrically."""

from pathlib import Path

import numpy as np
import pytest

from odpipe.studies.scenarios import load_config
from odpipe.dynamics.propagator import propagate
from odpipe.estimation.fit import build_grid
from odpipe.estimation.registry import ParameterRegistry
from odpipe.studies.halo_geo_doppler import NAMES, R_EARTH, _rows, force_models, link_clear
from odpipe.measurements import MeasurementSetup, compute
from odpipe.od.problem import TrackingProblem
from odpipe.time import utc_to_tdb
from study_runs import as_recorded, run_study, whole_run

CFG = load_config(Path(__file__).parents[1] / "runs" / "study_halo_geo_doppler.toml")


def test_link_blocked_only_through_the_earth():
    r1 = np.array([[2 * R_EARTH, 0, 0], [2 * R_EARTH, 0, 0], [2 * R_EARTH, 0, 0]])
    r2 = np.array([[-2 * R_EARTH, 0, 0], [-2 * R_EARTH, 3 * R_EARTH, 0], [4 * R_EARTH, 0, 0]])  # miss by 1.2 R
    assert list(link_clear(r1, r2)) == [False, True, True]


@pytest.mark.realdata
def test_simulated_doppler_equals_the_fit_reference():
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
        reg.add_state(sc, x0[sc], 100.0, 0.1)
        reg.add_stochastic_acceleration(sc, 2e-7, 0.0, 1000.0)
    reg.add("bias.sst_doppler", "bias", 0.0, 1e-3, owner="L1", observable="sst_doppler")
    grid, _ = build_grid(reg, t0, t1, 1000.0)
    prob = TrackingProblem(reg, rows, times, fm, meas, t0, t1, lookback=180.0, epochs=grid)
    reference, to_los, status = prob.reference(reg.apriori)
    assert set(status) == {""}
    assert np.all(np.abs(simulated) > 100.0)                       # GEO-halo round-trip rates, m/s
    # same model and data; the fit integrates per 1000-s segment at atol 1e-6 m: a few um/s,
    # well below the X-band noise (0.1 mm/s)
    assert np.max(np.abs(reference - simulated)) < 2e-5
    assert np.allclose(to_los, 0.5)


# odpipe's Tables 4-6 for the shipped configuration (3-D RMS over the last half of the arc; seeded run):
# (case, estimator, spacecraft, quantity) -> figure as recorded in docs/validation.md
RECORDED = {("S", "filter_smoother", "L1", "Pos"): "165", ("S", "filter_smoother", "GEO", "Pos"): "25.0",
            ("X", "filter_smoother", "L1", "Pos"): "82", ("X", "filter_smoother", "GEO", "Pos"): "10.6",
            ("S", "ekf", "L1", "Pos"): "165.0", ("S", "ekf", "GEO", "Pos"): "25.0",
            ("S", "ekf", "L1", "Vel"): "0.00378", ("S", "ekf", "GEO", "Vel"): "0.00180",
            ("X", "ekf", "L1", "Pos"): "82.1", ("X", "ekf", "GEO", "Pos"): "10.6",
            ("X", "ekf", "L1", "Vel"): "0.00144", ("X", "ekf", "GEO", "Vel"): "0.00078",
            ("S_L1_known", "ekf", "GEO", "Pos"): "23.6", ("S_L1_known", "ekf", "GEO", "Vel"): "0.00170",
            ("X", "ekf_gap_snc", "L1", "Pos"): "223", ("X", "ekf_gap_snc", "GEO", "Pos"): "31.7",
            ("X", "ekf_gap_snc", "L1", "Vel"): "0.00264", ("X", "ekf_gap_snc", "GEO", "Vel"): "0.00229"}


def _table():
    table = run_study("study_halo_geo_doppler")["table"]
    return {(r["case"], r["estimator"], r["spacecraft"], r["quantity"].split()[0]): r for _, r in table.iterrows()}


@whole_run
def test_whole_run_tables456_snapshot():
    """odpipe's 3-D RMS of Tables 4-6 by estimator, to the digits docs/validation.md records."""
    rows = _table()
    for key, recorded in RECORDED.items():
        assert rows[key]["odpipe 3D"] == as_recorded(recorded), key


@whole_run
def test_whole_run_tables45_disagree_with_the_paper_as_recorded():
    """odpipe's filter-smoother does NOT reproduce Tables 4-5: its positions are 1.8-7.5x better than the paper's
    (S band: L1 0.56x, GEO 0.33x; X band 0.28x, 0.13x), and its X band is 2-2.4x better than its S band where the
    paper's two bands are nearly equal. What does agree: the GEO satellite is better determined than the halo in
    both bands, as in the paper."""
    rows = _table()
    for band in ("S", "X"):
        for sc in ("L1", "GEO"):
            assert rows[(band, "filter_smoother", sc, "Pos")]["odpipe/paper 3D"] < 0.6
        assert rows[(band, "filter_smoother", "GEO", "Pos")]["odpipe 3D"] < rows[(band, "filter_smoother", "L1", "Pos")]["odpipe 3D"]
    assert rows[("X", "filter_smoother", "L1", "Pos")]["odpipe 3D"] < 0.6 * rows[("S", "filter_smoother", "L1", "Pos")]["odpipe 3D"]


@whole_run
def test_whole_run_the_paper_s_ekf_is_not_the_cause():
    """The paper's estimator, one EKF pass with the same SNC, gives odpipe's filter-smoother's positions to within
    1 % in both bands (S: L1 165.0 against 165 m, GEO 25.0 against 25.0 m; X: 82.1 against 82 m, 10.6 against
    10.6 m): the 1.8-7.5x gap to Tables 4-5 does not come from iterating and smoothing. Tolerance 5 %: both are
    forward filters of the same model and data, only the linearization differs. The S-band halo velocity, 1.8x
    the paper's, is the EKF's too (3.78 against 2.08 mm/s); in the X band it is 0.65x (1.44 against 2.19)."""
    rows = _table()
    for band in ("S", "X"):
        for sc in ("L1", "GEO"):
            ekf, fs = (rows[(band, est, sc, "Pos")]["odpipe 3D"] for est in ("ekf", "filter_smoother"))
            assert ekf == pytest.approx(fs, rel=0.05), (band, sc)
            assert rows[(band, "ekf", sc, "Pos")]["odpipe/paper 3D"] < 0.6
    assert rows[("S", "ekf", "L1", "Vel")]["odpipe/paper 3D"] > 1.5


@whole_run
def test_whole_run_table6_halo_known_is_no_better_as_in_the_paper():
    """Table 6 (S band, the halo's state known): the paper finds the GEO satellite no better than with both states
    estimated (79.3 against 75.0 m, 1.06x). The EKF agrees on that: 23.6 against 25.0 m (0.94x; tolerance
    0.8-1.2x, "not any better" read as within 20 %), while the level is 0.30x the paper's (recorded
    disagreement, as Tables 4-5)."""
    rows = _table()
    known, both = rows[("S_L1_known", "ekf", "GEO", "Pos")], rows[("S", "ekf", "GEO", "Pos")]
    assert 0.8 < known["odpipe 3D"] / both["odpipe 3D"] < 1.2
    assert known["paper 3D"] / both["paper 3D"] == pytest.approx(1.056, abs=1e-3)
    assert known["odpipe/paper 3D"] < 0.4


@whole_run
def test_whole_run_snc_over_the_data_gaps_moves_toward_the_paper():
    """Eqs. 10-11 taken literally (Gamma Q Gamma^T over the time since the previous point, so the GEO cut-off's
    gaps of about 13 intervals get 13^2 times one interval's velocity variance instead of 13 times): X band L1
    223 m and GEO 31.7 m, 2.7-3.0x the per-interval EKF's and 0.75x / 0.40x the paper's (velocities 1.20x /
    0.40x). The L1 halo lands within the factor 2 the other studies allow; GEO does not. A candidate cause of the
    gap to Table 5, measured on the X band only (the S band was not run this session)."""
    rows = _table()
    for sc in ("L1", "GEO"):
        gap, ekf = (rows[("X", est, sc, "Pos")]["odpipe 3D"] for est in ("ekf_gap_snc", "ekf"))
        assert gap > 2.5 * ekf, sc
    assert 0.5 < rows[("X", "ekf_gap_snc", "L1", "Pos")]["odpipe/paper 3D"] < 2.0
    assert rows[("X", "ekf_gap_snc", "GEO", "Pos")]["odpipe/paper 3D"] < 0.5
