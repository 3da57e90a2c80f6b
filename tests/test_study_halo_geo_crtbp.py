"""Scenario 1 (Fujimoto et al. sec. 2.1): GEO + EML1 halo, crosslink range 1 m and
range-rate 1 cm/s every 100 s. Paper: the position uncertainty of either satellite
converges to about one metre within about eight days (values from runs/study_halo_geo_crtbp.toml)."""

from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.studies.scenarios import load_config
from odpipe.cli import main
from odpipe.studies.halo_geo_crtbp import setup

CONFIG = Path(__file__).parents[1] / "runs" / "study_halo_geo_crtbp.toml"
CFG = load_config(CONFIG)
DAY = 86400.0


def test_crlb_reaches_the_metre_level_in_about_eight_days():
    t, P = setup(CFG).crlb()
    sig = np.sqrt(np.diagonal(P, axis1=1, axis2=2))
    paper = CFG["paper"]
    k8 = np.argmin(np.abs(t / DAY - CFG["compare_day"]))
    k1 = np.argmin(np.abs(t / DAY - 1.0))
    for cs in (slice(0, 3), slice(6, 9)):
        at8 = sig[k8, cs].max()
        print("max axis sigma day 1", sig[k1, cs].max(), "day 8", at8)
        assert paper["position_sigma_m"] / 2 < at8 < 2 * paper["position_sigma_m"]
        assert sig[k1, cs].max() > 10 * at8                      # it takes days, not a pass
        still_above = np.flatnonzero(sig[:, cs].max(axis=1) >= paper["level_m"])
        days = t[still_above[-1] + 1] / DAY
        assert paper["days_to_level"] / 2 < days < 1.5 * paper["days_to_level"]


def test_command_writes_the_report(tmp_path):
    text = CONFIG.read_text().replace("arc_days = 9.0", "arc_days = 1.0") \
        .replace("cadence_s = 100.0", "cadence_s = 300.0").replace("compare_day = 8.0", "compare_day = 1.0")
    text = text[:text.index("[[variant]]")] + text[text.index("[montecarlo]"):]
    cfg = tmp_path / "liaison_short.toml"
    cfg.write_text(text)
    assert main(["liaison", str(cfg), "-o", str(tmp_path / "out")]) == 0
    out = tmp_path / "out"
    for name in ("report.md", "baseline.csv", "sensitivity.csv", "convergence.png", "manifest.json"):
        assert (out / name).stat().st_size > 0
    table = pd.read_csv(out / "baseline.csv")
    rms = table.loc[table.quantity.str.startswith("post-fit range residual"), "odpipe"].iloc[0]
    assert 0.8 < rms < 1.2                                        # 1 m noise, 578 rows
    assert table.loc[table.quantity.str.startswith("post-fit range residual"), "paper"].iloc[0] \
        == CFG["paper"]["postfit_range_rms_m"]
