"""odpipe run: one arc through the whole pipeline into its run directory (progress on stderr)."""

import logging
from pathlib import Path

from odpipe.errors import Exit

NAME = "run"
HELP = "run one arc (ingest, calibrate, compress, edit, fit, products) from runs/NAME.toml"

_log = logging.getLogger(__name__)


def add_arguments(p):
    p.add_argument("config", type=Path, help="run configuration (TOML)")
    p.add_argument("--force", action="store_true", help="run even if products are up to date")


def run(args) -> int:
    from odpipe.estimation.fit import FitDiverged
    from odpipe.pipeline.run import run_config

    try:
        out = run_config(args.config, force=args.force, progress=_log.info)
    except FitDiverged as exc:  # name the arc (the attempt folder keeps run.log and FAILED.txt)
        raise FitDiverged(f"{args.config}: {exc}") from exc
    print(f"{out['status']}: {Path(out['run']) / 'report.html'}")
    return Exit.OK
