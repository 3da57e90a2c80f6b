"""The maneuver evaluation reproduces figures computed by hand from designed and estimated ΔV."""

import numpy as np
import pandas as pd
import pytest

from odpipe.analysis.maneuvers import evaluate, flatten


def test_table_4_4_figures_by_hand():
    table = pd.DataFrame({
        "maneuver": ["SK1", "SK2"],
        "designed": [np.array([0.3, 0.4, 0.0]), np.array([0.0, 0.0, -0.2])],
        "estimated": [np.array([0.303, 0.396, 0.001]), np.array([0.002, 0.0, -0.19])],
        "sigma": [np.array([1e-3, 1e-3, 1e-3]), np.array([2e-3, 2e-3, 2e-3])],
    })
    rows, stats = evaluate(flatten(table))
    # SK1: |d| = 0.5, |e| = sqrt(0.303^2+0.396^2+0.001^2) = 0.498630...
    e1 = np.sqrt(0.303**2 + 0.396**2 + 0.001**2)
    assert rows.loc[0, "Mag. (mm/s)"] == pytest.approx(abs(0.5 - e1) * 1e3, rel=1e-12)
    assert rows.loc[0, "Mag. (%)"] == pytest.approx(abs(0.5 - e1) / 0.5 * 100, rel=1e-12)
    assert rows.loc[0, "X (mm/s)"] == pytest.approx(3.0, rel=1e-9)
    assert rows.loc[0, "X (%)"] == pytest.approx(1.0, rel=1e-9)   # 3 mm/s of 300 mm/s
    assert rows.loc[0, "Y (%)"] == pytest.approx(1.0, rel=1e-9)   # 4 mm/s of 400 mm/s
    assert np.isnan(rows.loc[0, "Z (%)"])  # no designed Z: a percentage is undefined
    # SK2: |d| = 0.2, |e| = sqrt(0.002^2 + 0.19^2)
    e2 = np.sqrt(0.002**2 + 0.19**2)
    assert rows.loc[1, "Mag. (mm/s)"] == pytest.approx((0.2 - e2) * 1e3, rel=1e-12)
    assert rows.loc[1, "Z (mm/s)"] == pytest.approx(10.0, rel=1e-9)
    assert stats.loc["Average", "X (mm/s)"] == pytest.approx(2.5, rel=1e-9)
    assert stats.loc["Max", "Z (mm/s)"] == pytest.approx(10.0, rel=1e-9)
    assert stats.loc["Min", "Z (mm/s)"] == pytest.approx(1.0, rel=1e-9)
    assert stats.loc["Average", "Z (%)"] == pytest.approx(5.0, rel=1e-9)  # only SK2's 10 of 200 mm/s
    # sigma of the estimated magnitude: along the estimated direction, from per-axis sigmas
    u = np.array([0.303, 0.396, 0.001]) / e1
    assert rows.loc[0, "estimated sigma (mm/s)"] == pytest.approx(1.0 * np.linalg.norm(u), rel=1e-12)


def test_maneuvers_command_reads_run_products(tmp_path, capsys):
    from odpipe.cli import main

    flat = flatten(pd.DataFrame({
        "maneuver": ["SK1"], "designed": [np.array([0.3, 0.4, 0.0])],
        "estimated": [np.array([0.303, 0.396, 0.0])], "sigma": [np.array([1e-3, 1e-3, 1e-3])]}))
    run = tmp_path / "run"
    run.mkdir()
    flat.to_csv(run / "maneuvers.csv", index=False)
    assert main(["maneuvers", str(run), "-o", str(tmp_path / "out")]) == 0
    stats = pd.read_csv(tmp_path / "out" / "maneuver_summary.csv", index_col=0)
    assert stats.loc["Max", "X (mm/s)"] == pytest.approx(3.0, rel=1e-9)
    assert "Average" in capsys.readouterr().out
