"""odpipe study: run the seed papers' scenarios (:mod:`odpipe.studies`) and write the paper-vs-odpipe reports."""

from __future__ import annotations

import importlib
import json
import logging
import time
from pathlib import Path

from odpipe.errors import Exit, describe

NAME = "study"
HELP = "the seed papers' navigation studies (runs/study_*.toml): tables beside the paper's, plots"

_log = logging.getLogger(__name__)


def add_arguments(p):
    p.add_argument("configs", nargs="+", type=Path, metavar="config",
                   help="scenario configurations (TOML); several run one after the other")
    p.add_argument("-o", "--out", type=Path, default=None,
                   help="run directory (default: runs/out/<config name>); with several configurations, "
                        "the folder of their run directories (OUT/<config name>)")
    p.add_argument("--runs", type=int, default=None, help="override the Monte Carlo run count")
    p.add_argument("--parallel", action="store_true", help="Monte Carlo on a local Dask cluster")


def scenario(path: Path, out: Path, runs: int | None, parallel: bool) -> Path:
    """Run the scenario of configuration ``path`` into ``out``; returns its report."""
    from odpipe.studies.scenarios import load_config
    from parsers.atomic import write_text

    cfg = load_config(path)
    if runs is not None:
        cfg.setdefault("montecarlo", {})["runs"] = runs
    if parallel:
        cfg.setdefault("montecarlo", {})["parallel"] = True
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    _log.info("%s: scenario %s into %s", path, cfg["scenario"], out)
    importlib.import_module(f"odpipe.studies.{cfg['scenario']}").run(cfg, out, log=_log.info)
    write_text(out / "manifest.json", json.dumps(
        {"config": str(path), "settings": cfg, "seconds": round(time.time() - t0, 1)}, indent=1))
    return out / "report.md"


def run(args) -> int:
    from odpipe.studies.scenarios import load_config

    if args.runs is not None and args.runs < 0:
        raise ValueError(f"--runs {args.runs}: must be 0 or more")
    for path in args.configs:  # every configuration checked before hours of work start
        load_config(path)
    several = len(args.configs) > 1
    failed = 0
    for path in args.configs:
        out = (args.out / path.stem if several else args.out) if args.out else Path("runs/out") / path.stem
        try:
            print(f"report: {scenario(path, out, args.runs, args.parallel)}", flush=True)
        except Exception as exc:
            if not several:
                raise
            code, line = describe(exc)
            if code == Exit.INTERNAL:
                raise
            failed += 1
            _log.error("%s: %s", path, line)
    return Exit.PARTIAL if failed else Exit.OK
