"""Study formation_observability (Turan et al. 2022): range-only against range-rate-only crosslinks for
EML1/EML2 halo and halo/lunar-orbiter formations.

Table 1 (Xi_mean, Gramian condition number and unobservability index for range and range-rate; the
paper's values in runs/study_formation_observability.toml [paper.table1]) is checked two ways: against
the paper with the tolerance each column's set-up allows, and against odpipe's own recorded values
(snapshots, relative 1e-3: the Gramians are deterministic). A few Monte Carlo runs of the fit scatter
like the CRLB predicts, and range beats range-rate at 1 m / 0.3 mm/s.
"""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import chi2

from odpipe.analysis.montecarlo import monte_carlo
from odpipe.studies.crosslink_pair import CrosslinkPair
from odpipe.studies.crtbp_orbits import halo_by_period, keplerian_orbit
from odpipe.studies.crtbp_problem import RANGE, RANGE_RATE
from odpipe.studies.formation_observability import (formations, halo_start_sensitivity, log_ratios,
                                                    lunar_phase_rows, lunar_phase_sensitivity, observability_row,
                                                    orbits, units)
from odpipe.studies.scenarios import load_config

CFG = load_config(Path(__file__).parents[1] / "runs" / "study_formation_observability.toml")
PAPER = CFG["paper"]["table1"]
DAY = 86400.0
# odpipe's Table 1, recorded 2026-11-25, columns as formations() orders them (EML1/L2 x4, EML1/Lunar x4,
# EML2/Lunar x4)
TABLE1 = {
    "cond range": [7.4717e+10, 4.1999e+10, 1.0815e+11, 1.3333e+10, 3.0835e+10, 2.7406e+10, 2.0266e+10, 1.5485e+10,
                   9.646e+09, 9.7731e+09, 9.8042e+09, 9.7211e+09],
    "cond range-rate": [2.8803e+10, 6.5503e+09, 3.0619e+09, 7.4558e+08, 3.8244e+10, 3.7058e+10, 3.7652e+10,
                        3.7104e+10, 2.9996e+10, 2.8075e+10, 2.7155e+10, 2.3162e+10],
    "1/min eig range": [4997.2, 4968.9, 23210, 5813.7, 749.09, 685.05, 540.81, 434.62, 164.6, 168.03, 174.96, 189.3],
    "1/min eig range-rate": [454.92, 194.96, 178.7, 93.528, 0.71316, 0.70957, 0.7366, 0.75724, 0.37722, 0.35657,
                             0.35184, 0.34345],
    "Xi_mean": [128.27, 87.787, 79.195, 159.28, 72.373, 108.04, 74.626, 71.313, 63.593, 118.75, 108.69, 140.15],
}
# mean deviation factor from the paper over the EML1/L2 columns for each start of the two halos
HALO_START_MEAN_FACTOR = [1.2627, 5.5729, 7.4986, 19.948, 2.8500, 26.493, 10.810, 426.83]
# odpipe/paper over the 16 EML1/L2 measures pooled over the 8 starts: min, median, max
HALO_START_SPREAD = [0.0041004, 1.6360, 11088.4]
# the lunar columns over the orbiter's 8 start phases (0, 45, ..., 315 deg): mean factor per phase, and
# odpipe/paper over the 32 measures pooled over the phases: min, median, max
LUNAR_PHASE_MEAN_FACTOR = [1.9277, 1.9063, 4.6999, 19.137, 25.391, 15.587, 4.5029, 1.6002]
LUNAR_PHASE_SPREAD = [0.00095400, 0.36180, 4.6038]


@pytest.fixture(scope="module")
def table1():
    U = units(CFG)
    orb = orbits(CFG, U)
    cols = formations(CFG, U, orb)
    return U, orb, cols, [observability_row(pair) for _, pair in cols]


def test_table1_snapshot(table1):
    """All 60 of odpipe's Table 1 values, relative 1e-3 (condition numbers near 1e11 leave about 1e-5 of
    floating-point play; anything beyond is a change of the orbits, partials or Gramian)."""
    *_, rows = table1
    for key, recorded in TABLE1.items():
        np.testing.assert_allclose([r[key] for r in rows], recorded, rtol=1e-3, err_msg=key)


def test_table1_eml1_l2_agrees_with_the_paper(table1):
    """EML1/L2 (columns 1-4): each of the 16 Gramian measures within 2.5x of the paper's (odpipe: 0.42-1.21x,
    geometric-mean factor 1.26). Tolerance: the paper gives neither the halos' start phase nor their hemisphere;
    this start (both at apolune, north) is the best of the eight choices, the others are 2.8-427x off on average
    (test_halo_start_snapshot): the agreement partly comes from that choice, and 2.5x is the largest factor the
    chosen start shows. Ranking the choices is what a looser bound could not do."""
    *_, cols, rows = table1
    factors = np.array([10 ** np.abs(log_ratios(rows[j], PAPER, j)) for j, (label, _) in enumerate(cols)
                        if label.startswith("EML1/L2")])
    assert factors.shape == (4, 4) and factors.max() < 2.5
    assert 10 ** np.log10(factors).mean() < 1.3


def test_table1_xi_mean_agrees_with_the_paper(table1):
    """Xi_mean of all 12 formations within a factor 2 (odpipe 0.78-1.97x). Tolerance: Xi is the mean over epochs
    and the 12 components of a ratio with a long tail (odpipe's medians are 9-43 where the means are 64-159), so
    a handful of epochs near close approach set it; its order of magnitude and ranking are what compare."""
    *_, rows = table1
    ratio = np.array([r["Xi_mean"] for r in rows]) / np.array(PAPER["xi_mean"])
    assert np.all((ratio > 0.5) & (ratio < 2.0)), ratio.round(2)


def test_table1_lunar_columns_differ_from_the_paper_as_recorded(table1):
    """The 8 lunar columns are NOT reproduced closely: the paper gives the orbiter's period only (0.93 d) and the
    configured orbiter (e 0.4, i 56.2 deg, from periselene) leaves odpipe 0.19-4.6x off the paper's Gramian
    measures (worst 1/5.13), geometric-mean factor 2.47 (EML1/Lunar) and 1.50 (EML2/Lunar). This records
    those factors (relative 1e-3) and checks what does carry over: range-rate's unobservability
    index is over 100x below range's (paper: 1,100-1,900x) and Xi_mean > 1 (range wins)."""
    *_, cols, rows = table1
    lunar = [j for j, (label, _) in enumerate(cols) if "Lunar" in label]
    L = np.array([np.abs(log_ratios(rows[j], PAPER, j)) for j in lunar])
    assert 10 ** L[:4].mean() == pytest.approx(2.4697, rel=1e-3)
    assert 10 ** L[4:].mean() == pytest.approx(1.5047, rel=1e-3)
    assert 10 ** L.max() == pytest.approx(5.1292, rel=1e-3)
    for j in lunar:
        assert rows[j]["1/min eig range"] > 100 * rows[j]["1/min eig range-rate"]
        assert rows[j]["Xi_mean"] > 1


def test_halo_start_snapshot(table1):
    """The report's halo_start table: odpipe's mean factor from the paper for each of the eight starts of the
    two halos (the paper gives none) and the spread of odpipe/paper over all of them, relative 1e-3; the
    shipped start is the first and the best."""
    U, orb, cols, _ = table1
    table = halo_start_sensitivity(CFG, U, cols, orb)
    np.testing.assert_allclose(table["mean factor"][:8], HALO_START_MEAN_FACTOR, rtol=1e-3)
    assert table["mean factor"][:8].idxmin() == 0
    pooled = table.iloc[8]
    np.testing.assert_allclose(pooled[["ratio min", "ratio median", "ratio max"]].to_numpy(float), HALO_START_SPREAD,
                               rtol=1e-3)
    # Over the 8 starts, odpipe/paper on the 16 EML1/L2 measures spans 0.0041-11,088 (median 1.64): Table 1 is
    # sensitive to the start, and only the shipped start (the best) is within 2.5x. The median is within 2x of the
    # paper, the ends are not: the close agreement is the start's, not the set-up's alone.
    assert 0.5 < pooled["ratio median"] < 2.0
    assert pooled["ratio min"] < 0.01 and pooled["ratio max"] > 1000
    assert (table["worst factor"][:8] < 2.5).sum() == 1


def test_lunar_columns_spread_over_the_orbiter_start_phase(table1):
    """The lunar columns over the orbiter's start phase (the paper gives the period only): mean factor 1.6-25 by
    phase (snapshot, relative 1e-3), odpipe/paper pooled over the phases 0.00095-4.6 with median 0.36. The
    configured start (periselene) is within 2x of the paper on average, as are 45 and 315 deg; the figures move
    up to 1000x with the phase: sensitive."""
    U, orb, cols, _ = table1
    table = lunar_phase_sensitivity(CFG, lunar_phase_rows(CFG, U, cols, orb))
    np.testing.assert_allclose(table["mean factor"][:8], LUNAR_PHASE_MEAN_FACTOR, rtol=1e-3)
    pooled = table.iloc[8]
    np.testing.assert_allclose(pooled[["ratio min", "ratio median", "ratio max"]].to_numpy(float), LUNAR_PHASE_SPREAD,
                               rtol=1e-3)
    assert list(table["mean factor"][:8] < 2.0) == [True, True, False, False, False, False, False, True]


@pytest.fixture(scope="module")
def setup():
    U = units(CFG)
    h, lo = CFG["halo"]["L1"], CFG["lunar"]
    halo, T = halo_by_period(2.78, h["x0"], h["vy0"], 0.11, 0.13, U.mu)
    lunar = keplerian_orbit(lo["period_days"] * DAY / U.time, lo["ecc"], np.radians(lo["inc_deg"]), U.mu,
                            true_anomaly=np.radians(lo["true_anomaly_deg"]))
    f = CFG["filter"]
    return CrosslinkPair(U, U.to_si(halo), U.to_si(lunar), arc=T * U.time,
                         dt=CFG["cadence"]["dt_tu"] * U.time,
                         sigma=(CFG["noise"]["range_m"], CFG["noise"]["range_rate_mps"]),
                         apriori=(f["apriori_pos_m"], f["apriori_vel_mps"]),
                         error=(f["error_pos_m"], f["error_vel_mps"]), block=f["block_h"] * 3600.0,
                         max_iter=f["max_iter"])


def test_range_beats_range_rate_and_mc_scatter_matches_crlb(setup):
    """EML1 halo / lunar orbiter (2.78 TU halo): range beats range-rate in the CRLB, and three Monte Carlo runs of
    the fit scatter like the CRLB (NEES sum inside chi-square(36)'s 99.9 % interval)."""
    pair = setup
    final = {}
    for name, kinds in (("range", (RANGE,)), ("range-rate", (RANGE_RATE,))):
        p = replace(pair, kinds=kinds)
        t, P = p.crlb()
        final[name] = np.sqrt(np.trace(P[-1][:3, :3])), P[-1]
    assert final["range"][0] < final["range-rate"][0]
    runs = monte_carlo(replace(pair, kinds=(RANGE,)), 3, seed=4)
    P_end = final["range"][1]
    nees = [r["filtered"][-1] @ np.linalg.solve(P_end, r["filtered"][-1]) for r in runs]
    print("NEES vs CRLB at the arc end", nees, "converged", [r["converged"] for r in runs])
    assert all(r["converged"] for r in runs)
    # three independent runs: the sum of their NEES is chi-square(36) when the CRLB is the covariance
    assert chi2.ppf(0.0005, 36) < np.sum(nees) < chi2.ppf(0.9995, 36)
    sig = np.array([r["filtered_sigma"][-1] for r in runs])
    assert np.allclose(sig, np.sqrt(np.diag(P_end)), rtol=0.25)  # filter covariance ~ CRLB
