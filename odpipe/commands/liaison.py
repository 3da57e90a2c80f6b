"""odpipe liaison: run a LiAISON crosslink scenario and write the paper-vs-odpipe report."""

from __future__ import annotations

import importlib
import json
import time
from pathlib import Path

from odpipe.liaison.config import load_config
from odpipe.products.atomic import write_text

NAME = "liaison"
HELP = "LiAISON crosslink navigation scenario (runs/liaison_*.toml): tables beside the paper's, plots"

SCENARIOS = ("turan", "baseline", "doppler", "dowr", "ground", "ground_mesh")  # modules of odpipe.liaison


def add_arguments(p):
    p.add_argument("config", type=Path, help="scenario configuration (TOML)")
    p.add_argument("-o", "--out", type=Path, default=None, help="run directory (default: runs/out/<config name>)")
    p.add_argument("--runs", type=int, default=None, help="override the Monte Carlo run count")
    p.add_argument("--parallel", action="store_true", help="Monte Carlo on a local Dask cluster")


def run(args) -> int:
    cfg = load_config(args.config)
    name = cfg.get("scenario")
    if name not in SCENARIOS:
        raise SystemExit(f"{args.config}: scenario must be one of {SCENARIOS}, got {name!r}")
    if args.runs is not None:
        cfg.setdefault("montecarlo", {})["runs"] = args.runs
    if args.parallel:
        cfg.setdefault("montecarlo", {})["parallel"] = True
    out = args.out or Path("runs/out") / args.config.stem
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    importlib.import_module(f"odpipe.liaison.{name}").run(cfg, out, log=lambda m: print(m, flush=True))
    write_text(out / "manifest.json", json.dumps(
        {"config": str(args.config), "settings": cfg, "seconds": round(time.time() - t0, 1)}, indent=1))
    print(f"report: {out / 'report.md'}")
    return 0
