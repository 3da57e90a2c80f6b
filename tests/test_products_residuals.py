"""Residual statistics per station and per pass, in line-of-sight units and in the observable's unit."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from odpipe.products.residuals import statistics


def test_rms_per_station_and_pass_in_both_units():
    rng = np.random.default_rng(3)
    n = 400
    hz_per_mps = 15.2  # S-band two-way: 1 mm/s = 15.2 mHz
    los = np.where(np.arange(n) < 200, 1e-3, 3e-3) * rng.standard_normal(n)
    res = pd.DataFrame({"station_rx": "DSS-24", "observable": "doppler_2way", "pass_id": np.arange(n) // 200,
                        "postfit_los": los, "prefit_los": 2 * los, "postfit": los * hz_per_mps,
                        "flags": 0, "status": ""})
    res.loc[5, "flags"] = 8  # an edited row is counted, not used
    per_pass = statistics(res, by=("station_rx", "pass_id"))
    want = [np.sqrt(np.mean(np.delete(los[:200], 5) ** 2)), np.sqrt(np.mean(los[200:] ** 2))]
    assert per_pass["postfit_rms"].tolist() == pytest.approx(want, rel=1e-12)
    assert per_pass["postfit_rms_unit"].tolist() == pytest.approx(np.array(want) * hz_per_mps, rel=1e-12)
    assert per_pass["n_used"].tolist() == [199, 200] and per_pass["n_edited"].tolist() == [1, 0]
    whole = statistics(res)
    assert whole["postfit_rms"].iloc[0] == pytest.approx(np.sqrt(np.mean(np.delete(los, 5) ** 2)), rel=1e-12)
