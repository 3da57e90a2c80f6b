"""odpipe maneuvers: designed versus estimated maneuvers over runs (thesis Table 4.4)."""

from pathlib import Path

from odpipe.errors import Exit

NAME = "maneuvers"
HELP = "designed vs estimated maneuvers (magnitude and components, mm/s and percent) from runs' maneuvers.csv"
NEEDED = ["maneuver"] + [f"{v}_{a}" for v in ("designed", "estimated", "sigma") for a in "xyz"]  # evaluate()'s


def add_arguments(p):
    p.add_argument("runs", nargs="+", type=Path, help="run folders (OUTPUT/NAME/current) or maneuvers.csv files")
    p.add_argument("-o", "--out", type=Path, help="write the table and the summary as CSV here")


def run(args) -> int:
    import pandas as pd

    from odpipe.analysis.maneuvers import evaluate
    from parsers.atomic import write_text

    tables = []
    for path in args.runs:
        if not path.exists():
            raise FileNotFoundError(2, "No such file or directory", str(path))
        csv = path / "maneuvers.csv" if path.is_dir() else path
        if not csv.is_file():
            raise ValueError(f"{path}: no maneuvers.csv (did the run estimate maneuvers?)")
        try:
            table = pd.read_csv(csv)
        except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
            raise ValueError(f"{csv}: not a CSV table ({exc})") from None
        missing = [c for c in NEEDED if c not in table.columns]
        if missing:
            raise ValueError(f"{csv}: not a maneuvers.csv of a run (no column {', '.join(missing)})")
        tables.append(table.assign(run=str(path)))
    rows, stats = evaluate(pd.concat(tables, ignore_index=True))
    with pd.option_context("display.width", 160, "display.max_columns", 20, "display.precision", 3):
        print(rows.to_string(index=False))
        print()
        print(stats.to_string())
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        write_text(args.out / "maneuvers.csv", rows.to_csv(index=False))
        write_text(args.out / "maneuver_summary.csv", stats.to_csv())
    return Exit.OK
