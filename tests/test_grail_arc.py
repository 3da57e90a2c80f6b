"""Real DSN data end to end: the first GRAIL-B arc of the nightly chain (2012-04-09, ODF two-way S-band
Doppler) fitted from the a priori orbit found in its own Doppler, kilometres off, to the LP field's
residual level. With the data weights at 0.1 m/s throughout (the configs before the weight stages) the
same arc left 27-66 mm/s per station; fitted at 2 mm/s at once, it diverged into the Moon."""

import re
from pathlib import Path

import pandas as pd
import pytest

from odpipe.pipeline.run import run_config

RUNS = Path(__file__).resolve().parents[1] / "runs"


@pytest.mark.slow
@pytest.mark.realdata
def test_grail_b_first_arc_converges_to_mm_per_second(shared_data, tmp_path):
    text = (RUNS / "grail_b_2012_04_09_start.toml").read_text()
    text = re.sub(r'"\.\./\.\./shared/data/', f'"{shared_data}/', text)
    text = re.sub(r'^output = "[^"]+"', f'output = "{tmp_path}"', text, flags=re.M)
    (tmp_path / "arc.toml").write_text(text)
    out = run_config(tmp_path / "arc.toml", progress=None)
    assert out["status"] == "complete" and out["converged"]
    stats = pd.read_csv(Path(out["run"]) / "residual_statistics.csv").set_index("station_rx")
    assert set(stats.index) == {"DSS-24", "DSS-54", "DSS-65"}
    assert (stats["postfit_rms"] < 0.005).all(), stats["postfit_rms"]        # m/s along the line of sight
    assert stats["n_used"].sum() > 0.6 * (stats["n_used"].sum() + stats["n_edited"].sum())  # 253 of 380
