"""Study halo_geo_crtbp (Fujimoto et al. 2012, sec. 2.1): an L1 halo and a GEO satellite tracked only by
each other, crosslink range 1 m and range-rate 1 cm/s every 100 s in the CRTBP.

Paper (sec. 2.1): "the uncertainty of the position of either satellite converges to about one meter
within about eight days"; post-fit range residual RMS 0.99519 m. odpipe's figures (docs/validation.md):
CRLB max-axis position sigma at day 8 of 0.55 m (halo) and 0.79 m (GEO), post-fit range RMS 0.994 m.
Each figure is checked against the paper with the tolerance its wording allows, and against odpipe's
own recorded value (a snapshot, relative 1e-3: the runs are seeded and the CRLB has no randomness)."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.stats import chi2, f

from odpipe.cli import main
from odpipe.studies.halo_geo_crtbp import setup
from odpipe.studies.scenarios import load_config

CONFIG = Path(__file__).parents[1] / "runs" / "study_halo_geo_crtbp.toml"
CFG = load_config(CONFIG)
DAY = 86400.0
SPACECRAFT = {"L1 halo": slice(0, 3), "GEO": slice(6, 9)}
# odpipe's figures, recorded 2026-11-25 (unchanged since session 6's docs/validation.md)
DAY8_SIGMA_M = {"L1 halo": 0.54715, "GEO": 0.79157}     # CRLB, largest axis at day 8
DAYS_BELOW_LEVEL = {"L1 halo": 5.870, "GEO": 5.913}     # every axis CRLB sigma < 1.5 m from this day on
POSTFIT_RANGE_RMS_M = 0.993691                          # the 9-day fit, seed 2012


@pytest.fixture(scope="module")
def crlb():
    t, P = setup(CFG).crlb()
    return t, np.sqrt(np.diagonal(P, axis1=1, axis2=2))


def _day8(crlb, cs):
    t, sig = crlb
    return sig[np.argmin(np.abs(t / DAY - CFG["compare_day"])), cs].max()


def _days_below(crlb, cs, level):
    t, sig = crlb
    return t[np.flatnonzero(sig[:, cs].max(axis=1) >= level)[-1] + 1] / DAY


def test_metre_level_in_about_eight_days_as_the_paper_says(crlb):
    """Paper: "about one meter" within "about eight days". Tolerance: "about one meter" read as 0.5-1.5 m for
    the largest axis sigma at day 8 (the paper gives no closer figure, nor the halo or the GEO orientation it
    used); "about eight days" as the day after which every axis stays below 1.5 m lying in 4-12 days. odpipe
    is at 0.55 and 0.79 m, below 1.5 m from day 5.9: agreement within the wording, both satellites 25 % early."""
    paper = CFG["paper"]
    t, sig = crlb
    for name, cs in SPACECRAFT.items():
        assert 0.5 * paper["position_sigma_m"] < _day8(crlb, cs) < 1.5 * paper["position_sigma_m"], name
        assert paper["days_to_level"] / 2 < _days_below(crlb, cs, paper["level_m"]) < 1.5 * paper["days_to_level"]
        assert sig[np.argmin(np.abs(t / DAY - 1.0)), cs].max() > 10 * _day8(crlb, cs)   # it takes days, not a pass


def test_day8_uncertainty_snapshot(crlb):
    """odpipe's own figures, relative 1e-3 (the CRLB is deterministic): a change in the dynamics, the
    crosslink partials or the halo selection shows here first."""
    for name, cs in SPACECRAFT.items():
        assert _day8(crlb, cs) == pytest.approx(DAY8_SIGMA_M[name], rel=1e-3), name
        assert _days_below(crlb, cs, CFG["paper"]["level_m"]) == pytest.approx(DAYS_BELOW_LEVEL[name], abs=0.01)


def test_postfit_range_rms_against_the_paper():
    """The 9-day fit's post-fit range RMS against the paper's 0.99519 m. Both are one realization of 1-m white
    noise over about 7,800 ranges, so the ratio of their squares is F(n, n)-distributed (n the range count);
    tolerance: its 99.9 % interval (about +-7.5 %). Snapshot: relative 1e-4 (seed 2012)."""
    pair = setup(CFG)
    rms = pair(np.random.default_rng(CFG["seed"]))["postfit_rms"][0]
    n = pair.epochs.size
    assert f.ppf(0.0005, n, n) < rms**2 / CFG["paper"]["postfit_range_rms_m"] ** 2 < f.ppf(0.9995, n, n)
    assert rms == pytest.approx(POSTFIT_RANGE_RMS_M, rel=1e-4)


def test_command_writes_the_report(tmp_path, monkeypatch):
    from odpipe.studies import study_report

    figures = []
    monkeypatch.setattr(study_report, "save_figure",
                        lambda path, fig, **kw: (figures.append(fig), path.write_bytes(b"png")))
    text = CONFIG.read_text().replace("arc_days = 9.0", "arc_days = 1.0") \
        .replace("cadence_s = 100.0", "cadence_s = 300.0").replace("compare_day = 8.0", "compare_day = 1.0")
    text = text[:text.index("[[variant]]")] + text[text.index("[montecarlo]"):]
    cfg = tmp_path / "study_short.toml"
    cfg.write_text(text)
    assert main(["study", str(cfg), "-o", str(tmp_path / "out")]) == 0
    out = tmp_path / "out"
    for name in ("report.md", "halo_geo_crtbp.csv", "sensitivity.csv", "convergence.png", "manifest.json"):
        assert (out / name).stat().st_size > 0
    table = pd.read_csv(out / "halo_geo_crtbp.csv")
    rms = table.loc[table.quantity.str.startswith("post-fit range residual"), "odpipe"].iloc[0]
    n = 289                                                       # 1-m noise on 289 ranges, 12 parameters
    assert chi2.ppf(0.0005, n - 12) < n * rms**2 < chi2.ppf(0.9995, n)
    assert table.loc[table.quantity.str.startswith("post-fit range residual"), "paper"].iloc[0] \
        == CFG["paper"]["postfit_range_rms_m"]
    # each y label is its panel's unit (convergence.png's position panels said 'error / sigma' over metres)
    for ax in figures[0].axes:
        if ax.get_ylabel():
            assert ax.get_title().endswith(f"({ax.get_ylabel()})"), (ax.get_title(), ax.get_ylabel())
