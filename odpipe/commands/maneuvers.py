"""odpipe maneuvers: designed versus estimated maneuvers over runs (thesis Table 4.4)."""

from pathlib import Path

import pandas as pd

from odpipe.analysis.maneuvers import evaluate
from odpipe.products.atomic import write_text

NAME = "maneuvers"
HELP = "designed vs estimated maneuvers (magnitude and components, mm/s and %) from runs' maneuvers.csv"


def add_arguments(p):
    p.add_argument("runs", nargs="+", type=Path, help="run folders (OUTPUT/NAME/current) or maneuvers.csv files")
    p.add_argument("-o", "--out", type=Path, help="write the table and the summary as CSV here")


def run(args) -> int:
    tables = []
    for path in args.runs:
        csv = path / "maneuvers.csv" if path.is_dir() else path
        if not csv.is_file():
            raise SystemExit(f"{path}: no maneuvers.csv (did the run estimate maneuvers?)")
        tables.append(pd.read_csv(csv).assign(run=str(path)))
    rows, stats = evaluate(pd.concat(tables, ignore_index=True))
    with pd.option_context("display.width", 160, "display.max_columns", 20, "display.precision", 3):
        print(rows.to_string(index=False))
        print()
        print(stats.to_string())
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        write_text(args.out / "maneuvers.csv", rows.to_csv(index=False))
        write_text(args.out / "maneuver_summary.csv", stats.to_csv())
    return 0
