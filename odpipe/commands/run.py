"""odpipe run: one arc through the whole pipeline into its run directory."""

from pathlib import Path

from odpipe.pipeline.run import run_config

NAME = "run"
HELP = "run one arc (ingest, calibrate, compress, edit, fit, products) from runs/NAME.toml"


def add_arguments(p):
    p.add_argument("config", type=Path, help="run configuration (TOML)")
    p.add_argument("--force", action="store_true", help="run even if products are up to date")


def run(args) -> int:
    out = run_config(args.config, force=args.force)
    print(f"{out['status']}: {Path(out['run']) / 'report.html'}")
    return 0
