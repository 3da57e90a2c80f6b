"""A small real arc job for the batch tests: writes an OEM product through a run directory.

Its config is a TOML file: ``seconds`` (how long the arc works), ``fail`` (raise instead).
"""

import time
import tomllib
from pathlib import Path

import numpy as np

from odpipe.products.segments import EphemerisSegment
from odpipe.products.oem import write_oem
from odpipe.operations import rundir


def run_arc(config: Path) -> dict:
    text = config.read_text()
    cfg = tomllib.loads(text)
    root = config.parent / "out" / config.stem
    fp = rundir.fingerprint(text, [config])
    if rundir.up_to_date(root, fp):
        return {"status": "skipped"}
    attempt = rundir.start(root)
    try:
        if cfg.get("fail"):
            raise RuntimeError(f"arc {config.stem} was told to fail")
        t = np.arange(0.0, 3601.0, 60.0)
        x = np.hstack([7e6 * np.ones((t.size, 1)), np.zeros((t.size, 5))])
        x[:, 4] = 7.5e3
        write_oem(attempt.product("trajectory.oem"), [EphemerisSegment(t, x, "earth")], "SC", config.stem)
        time.sleep(cfg.get("seconds", 0.0))
        attempt.finish(fp, {"arc": config.stem})
        return {"status": "complete"}
    except BaseException as exc:
        attempt.fail(exc)
        raise
