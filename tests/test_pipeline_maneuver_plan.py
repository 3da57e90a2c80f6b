"""A run's planned maneuvers: the plan's sigma_time (or the config's default) makes the epoch estimated."""

from __future__ import annotations

import numpy as np

from odpipe.pipeline.config import load_config
from odpipe.pipeline.setup import maneuver_plans, tdb


def test_plan_epoch_sigmas_reach_the_estimator(tmp_path):
    (tmp_path / "plan.csv").write_text(
        "name,epoch,kind,frame,dv1,dv2,dv3,sigma_dv,sigma_time\n"
        "SK-1,2010-11-21T00:00:00,impulsive,ICRF,0.1,0.0,0.0,0.01,10.0\n"
        "SK-2,2010-11-22T00:00:00,impulsive,ICRF,0.0,0.2,0.0,0.01,\n")
    text = """
[run]
name = "plan"
output = "out"
[arc]
spacecraft = "2"
start = "2010-11-20T00:00:00"
end = "2010-11-23T00:00:00"
[data]
files = []
[dynamics]
center = "earth"
third_bodies = ["moon"]
mass = 100.0
[initial_state]
epoch = "2010-11-20T00:00:00"
state = [4.2e8, 0.0, 0.0, 0.0, 1000.0, 0.0]
[estimation]
maneuver_plan = "plan.csv"
"""
    for default, second in ((None, None), (30.0, 30.0)):
        extra = "" if default is None else f"maneuver_epoch_sigma = {default}\n"
        (tmp_path / "arc.toml").write_text(text + extra)
        cfg = load_config(tmp_path / "arc.toml")
        plans = maneuver_plans(cfg, None, np.zeros(6), tdb("2010-11-20T00:00:00"))
        assert [p.label for p in plans] == ["SK-1", "SK-2"]
        assert plans[0].sigma_epoch == 10.0 and plans[1].sigma_epoch == second
        assert plans[1].designed == (0.0, 0.2, 0.0)
