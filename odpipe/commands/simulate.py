"""``odpipe simulate``: generate a simulated tracking case (truth, tracking files, calibrations) from a case file."""

from __future__ import annotations

from pathlib import Path

from odpipe.commands._values import number
from odpipe.errors import Exit

NAME = "simulate"
HELP = "simulate a tracking case (e.g. runs/artemis_p2_like.toml) into a directory"


def add_arguments(parser) -> None:
    parser.add_argument("case", type=Path, help="case description (TOML; its keys: docs/config.md)")
    parser.add_argument("-o", "--output", type=Path, required=True, help="output directory")
    parser.add_argument("--days", type=number(), help="simulate only the first DAYS of the case")


def run(args) -> int:
    from odpipe.simulate import run_case

    paths, truth, obs = run_case(args.case, args.output, days=args.days)
    t = obs.table
    print(f"{len(t)} observables in {t['pass_id'].nunique()} passes, {len(truth.epochs)} maneuvers; files:")
    for role, p in paths.items():
        print(f"  {role}: {p}")
    return Exit.OK
