"""``odpipe multiarc`` end to end: two simulated days run with ``odpipe run``, then refitted sharing the SRP scale.

The truth flies a Sun-pointing plate, each arc's filter a cannonball of ``CR_AREA`` with an estimated scale
(``heo_case``); the plate's equivalent scale ``TRUE_SRP_SCALE`` comes from the plate formula, not from the
filter. What a user sees is checked: exit status, the table printed, ``shared.csv`` with each arc's own
estimate and the combination, per-arc products in ``current/``, and that the combination is inside its sigma
of the truth and tighter than either day's own estimate.
"""

from __future__ import annotations

import contextlib
import io
import shutil

import numpy as np
import pandas as pd
import pytest
from scipy.stats import chi2

from bounds import max_z
from heo_case import TRUE_SRP_SCALE, simulate, tdb, write_config
from odpipe.cli import main
from parsers import oem

DAYS = ("2003-06-03T00:00:00", "2003-06-04T00:00:00", "2003-06-05T00:00:00")
OFFSET = np.r_[300.0, -200.0, 150.0, 0.003, -0.002, 0.001]   # m, m/s: each arc's a priori error


pytestmark = pytest.mark.slow   # two simulated arcs run and refitted: about 13 CPU-s


@pytest.fixture(scope="module")
def multiarc_run(tmp_path_factory):
    """Two days run with ``odpipe run``, then ``odpipe multiarc``: (folder, truth, exit status, printed text)."""
    tmp = tmp_path_factory.mktemp("multiarc")
    (tmp / "a").mkdir()
    truth, _ = simulate(tmp / "a", DAYS[0], DAYS[2])
    (tmp / "b").mkdir()
    shutil.copy(tmp / "a" / "tracking.parquet", tmp / "b" / "tracking.parquet")
    for folder, start, end in (("a", DAYS[0], DAYS[1]), ("b", DAYS[1], DAYS[2])):
        x0 = truth.state(np.array([tdb(start)]))[0] + OFFSET
        write_config(tmp / folder, f"day_{folder}", start, end, x0, "reweight = false")
        assert main(["run", str(tmp / folder / "arc.toml")]) == 0
    cfg = tmp / "multi.toml"
    cfg.write_text('[multiarc]\nname = "two_days"\narcs = ["a/arc.toml", "b/arc.toml"]\n'
                   'shared = ["srp_scale"]\noutput = "out"\nrounds = 2\n')
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        status = main(["multiarc", str(cfg)])
    return tmp, truth, status, printed.getvalue()


def test_multiarc_command_writes_the_combination_and_each_arc(multiarc_run):
    tmp, truth, status, printed = multiarc_run
    current = tmp / "out" / "two_days" / "current"
    assert status == 0, printed
    assert f"products in {current}" in printed and "combined" in printed
    for name in ("day_a", "day_b"):
        for product in ("trajectory.oem", "residuals.parquet", "parameters.csv", "summary.json"):
            assert (current / name / product).is_file(), (name, product)
        seg = oem.read(current / name / "trajectory.oem")[0]
        j2000 = np.datetime64("2000-01-01T12:00:00", "ns")
        t_cov = (seg.cov_epochs - j2000) / np.timedelta64(1, "s")
        for k in (len(t_cov) // 2, len(t_cov) - 1):   # the middle and the end of the arc
            err = seg.states[np.searchsorted(seg.epochs, seg.cov_epochs[k])] - truth.state(t_cov[k:k + 1])[0]
            sig = np.sqrt(np.diag(seg.covariances[k]))
            assert np.all(np.abs(err) < max_z(6) * sig), (name, k, err, sig)

def test_shared_scale_is_inside_its_sigma_and_tighter_than_either_day(multiarc_run):
    tmp, _, _, _ = multiarc_run
    shared = pd.read_csv(tmp / "out" / "two_days" / "current" / "shared.csv")
    assert list(shared["arc"]) == ["day_a", "day_b", "combined"]
    est, sig = shared["srp_scale"].iloc[-1], shared["srp_scale_sigma"].iloc[-1]
    assert abs(est - TRUE_SRP_SCALE) < max_z(1) * sig, (est, sig, TRUE_SRP_SCALE)
    alone = shared["srp_scale_sigma"].iloc[:2].to_numpy()
    assert np.all(sig < alone), (sig, alone)
    assert np.all(shared["chi2"].iloc[:2] < chi2.ppf(0.999, 1)), shared
