"""odpipe batch: many arcs in parallel on Dask, resumable, with a summary of the night."""

import tomllib
from pathlib import Path

from odpipe.pipeline.config import load_config
from odpipe.pipeline.run import run_config
from odpipe.runs.batch import night_summary, run_batch
from odpipe.runs.schema import ConfigError

NAME = "batch"
HELP = ("run many arcs (a nightly batch config listing arc configs) in parallel; skips arcs whose config, "
        "inputs and software are unchanged")


def add_arguments(p):
    p.add_argument("config", type=Path, help="batch config: [batch] arcs = [run configs or globs], workers = N")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    p.add_argument("--workers", type=int, help="local cluster size (default: the config's, else 2)")
    p.add_argument("--force", action="store_true", help="refit every arc, even unchanged ones")


def starts_from(arcs: list[Path]) -> dict:
    """arc -> the arcs of the batch whose products its a priori state is read from."""
    cfgs = {a: load_config(a) for a in arcs}
    roots = {a: (c.run.output / c.run.name).resolve() for a, c in cfgs.items()}
    after = {}
    for a, c in cfgs.items():
        source = c.initial_state.from_oem
        if source is not None:
            after[a] = [b for b, root in roots.items() if b != a and root in source.parents]
    return after


def _arc(path: Path) -> dict:
    return run_config(path, progress=None)


def _arc_forced(path: Path) -> dict:
    return run_config(path, force=True, progress=None)


def run(args) -> int:
    data = tomllib.loads(args.config.read_text())
    batch = data.get("batch")
    if not isinstance(batch, dict) or not isinstance(batch.get("arcs"), list):
        raise ConfigError(args.config, "batch.arcs", "a list of run configs is required")
    unknown = set(batch) - {"arcs", "workers"}
    if unknown:
        raise ConfigError(args.config, f"batch.{sorted(unknown)[0]}", "unknown key (allowed: arcs, workers)")
    arcs = sorted({p for pattern in batch["arcs"] for p in args.config.parent.glob(pattern)})
    if not arcs:
        raise ConfigError(args.config, "batch.arcs", "no run config matches")
    outcomes = run_batch(arcs, _arc_forced if args.force else _arc, after=starts_from(arcs), scheduler=args.scheduler,
                         workers=args.workers or batch.get("workers", 2))
    print(night_summary(outcomes))
    return 1 if any(o.status == "failed" for o in outcomes) else 0
