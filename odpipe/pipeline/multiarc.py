"""A multi-arc solution from a configuration: arcs already run, refitted sharing some dynamic parameters.

The configuration (TOML)::

    [multiarc]
    name = "grail_b_multiarc"      # output folder OUTPUT/NAME
    output = "out"
    arcs = ["grail_b_2012_04_08.toml", "grail_b_2012_04_09.toml"]   # run configs (relative to this file)
    shared = ["srp_scale"]         # force-model parameters every arc estimates with the same a priori
    rounds = 1                     # estimation rounds (each refits every arc about the last combination)

Every arc must have a complete run (``odpipe run``/``batch``): its edited tracking table
(``tracking.parquet``) is fitted again, and its ``solution.npz`` is the first round's estimate
(:func:`odpipe.od.multiarc.fit_multiarc`). Products go to a new attempt folder under ``OUTPUT/NAME`` that becomes ``OUTPUT/NAME/current`` only when
every file is written (:mod:`odpipe.operations.rundir`, as ``odpipe run``): ``shared.csv`` (each arc's own
estimate, its consistency chi-square and the combination) and per arc ``<arc>/trajectory.oem``,
``residuals.parquet``, ``parameters.csv`` of the fit with the shared parameters fixed.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.estimation.solution import Solution
from odpipe.od.arc import build_registry
from odpipe.od.multiarc import _SIGMA_FIELD, fit_multiarc, solution_share
from odpipe.operations import rundir
from odpipe.operations.schema import ConfigError, at_least, checked, file_name, load_file, positive
from odpipe.pipeline import setup as build
from odpipe.pipeline.config import load_config
from odpipe.pipeline.fitted_trajectory import fitted_segments
from odpipe.pipeline.ingest import ingest
from odpipe.products import parameters
from odpipe.products.oem import write_oem
from parsers.atomic import write_parquet, write_text


def _shared_names(value) -> list[tuple[str, str]]:
    return [(f"[{i}]", f"{v!r} is not a shareable parameter (names starting {sorted(_SIGMA_FIELD)})")
            for i, v in enumerate(value) if not any(v.startswith(p) for p in _SIGMA_FIELD)]


@dataclass
class MultiArcSection:
    name: str = checked(file_name)  # output folder OUTPUT/NAME
    arcs: list[Path] = checked(lambda v: [("", "needs at least two arcs")] if len(v) < 2 else [])  # run configs
    shared: list[str] = checked(_shared_names)  # force-model parameters shared by the arcs (srp_scale, cd, poly[k].*)
    output: Path = Path("out")
    rounds: int = checked(at_least(1), default=1)  # estimation rounds at most
    step: float = checked(positive, default=60.0)  # s between the OEM states


@dataclass
class MultiArcConfig:
    multiarc: MultiArcSection


def load_multiarc(path) -> MultiArcSection:
    """The ``[multiarc]`` table of ``path``, checked (ConfigError naming the key)."""
    return load_file(MultiArcConfig, path).multiarc


@dataclass
class _Arc:
    cfg: object
    table: pd.DataFrame
    setup: object
    share: object = field(default=None)
    inputs: tuple = ()


def _arc(path: Path, shared) -> _Arc:
    cfg = load_config(path)
    run = cfg.run.output / cfg.run.name / "current"
    if not (run / "solution.npz").exists():
        raise ConfigError(path, "run.name", f"{run} has no complete run (run this arc first)")
    fm = build.force_model(cfg)
    data = ingest(cfg.data.files, cfg.data.errors, cfg.arc.spacecraft)
    setup = build.arc_setup(cfg, fm, data.store, build.station_catalog(cfg))
    table = pd.read_parquet(run / "tracking.parquet")
    reg = build_registry(setup, table.iloc[:0])
    names = [f"{setup.spacecraft}.{n}" for n in shared]
    missing = [n for n in names if n not in reg.names]
    if missing:
        raise ConfigError(path, "estimation", f"does not estimate {missing} (a shared parameter needs its sigma)")
    idx = [reg.index(n) for n in names]
    share = solution_share(Solution.load(run / "solution.npz"), setup.spacecraft, shared,
                           reg.apriori[idx], reg.sigma[idx])
    return _Arc(cfg, table, setup, share, (path, run / "solution.npz", run / "tracking.parquet"))


def run_multiarc(path, log=print) -> dict:
    """Run the multi-arc solution of configuration ``path``; returns {"shared": table, "folder": path}."""
    sec = load_multiarc(path)
    arcs = [_arc(p, sec.shared) for p in sec.arcs]
    sol = fit_multiarc([(a.table, a.setup) for a in arcs], sec.shared, rounds=sec.rounds,
                       first=[a.share for a in arcs], log=log)
    attempt = rundir.start(sec.output / sec.name)
    try:
        table = sol.shared.table([a.cfg.run.name for a in arcs])
        write_text(attempt.product("shared.csv"), table.to_csv(index=False))
        for a, fitted in zip(arcs, sol.arcs):
            _write_arc(attempt, sec, a, fitted)
            log(f"multi-arc {sec.name}: {a.cfg.run.name} {'converged' if fitted.converged else 'NOT converged'}")
    except BaseException as exc:
        attempt.fail(exc)
        raise
    inputs = [Path(path).resolve()] + [p for a in arcs for p in a.inputs]
    attempt.finish(rundir.fingerprint(Path(path).read_text(), inputs))
    out = sec.output / sec.name / "current"
    return {"shared": table, "folder": str(out), "converged": [bool(f.converged) for f in sol.arcs],
            "rounds": [np.asarray(c.estimate).tolist() for c in sol.rounds]}


def _write_arc(attempt, sec: MultiArcSection, a: _Arc, fitted) -> None:
    """One arc's products of the multi-arc fit, in ``<arc>/`` of the attempt."""
    name = a.cfg.run.name
    write_oem(attempt.product(f"{name}/trajectory.oem"), fitted_segments(fitted, sec.step),
              a.cfg.products.object_name or a.cfg.arc.spacecraft, a.cfg.arc.spacecraft,
              comments=[f"odpipe multi-arc {sec.name}: {name} with {', '.join(sec.shared)} fixed at the combination"])
    write_parquet(attempt.product(f"{name}/residuals.parquet"), fitted.residuals)
    write_text(attempt.product(f"{name}/parameters.csv"), parameters.with_units(fitted.parameters).to_csv(index=False))
    write_text(attempt.product(f"{name}/summary.json"), json.dumps({"converged": bool(fitted.converged),
                                                                  "iterations": len(fitted.history)}))
