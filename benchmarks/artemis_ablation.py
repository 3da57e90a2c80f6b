"""Ablation of the ARTEMIS twin's error budget (issue #25 item 1): the twin (runs/artemis_p2_twin.toml) refitted with one error
source switched off at a time (odpipe.simulate.ablation.SOURCES), beside the full twin and the thesis.

For each variant: the case is simulated and every short and long arc fitted as ``odpipe demo`` does
(same seed: the same noise, only the source differs), then the short- and long-arc overlap means
(R/I/C, m), the median designed − estimated station-keeping magnitude (Table 4.4, mm/s and %), the
median |designed| burn and the share of state errors within 3 sigma. A source's contribution is
read as the change from the full twin when it is off.

    nice .venv/bin/python benchmarks/artemis_ablation.py [-o out/artemis_ablation] [--days 28] [--only NAME]

About 1-2 min per variant on 2 cores; the table goes to OUT/ablation.csv and stdout (Markdown).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from odpipe.pipeline.demo import TWIN, run_demo
from odpipe.simulate import thesis
from odpipe.simulate.ablation import SOURCES, without
from odpipe.simulate.case import load


def figures(out: Path) -> dict:
    """The variant's comparison figures from its demo products (``thesis_comparison.csv``, truth comparison)."""
    versus = pd.read_csv(out / "thesis_comparison.csv").set_index("figure")
    row = {}
    for arc in ("short", "long"):
        for c in thesis.COMPONENTS:
            key = f"{arc}-arc position {c} (m)"
            row[f"{arc} {c[0].upper()} (m)"] = float(versus.loc[key, "odpipe"].split(" ± ")[0])
    for col in ("Mag. (mm/s)", "Mag. (%)"):
        row[f"T4.4 median {col}"] = float(versus.loc[f"Table 4.4 median {col}", "odpipe"])
    truth = pd.read_csv(out / "truth_comparison.csv")
    row["within 3σ (%)"] = float(truth["within 3 sigma (%)"].mean())
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--out", type=Path, default=Path("out/artemis_ablation"))
    ap.add_argument("--days", type=float, default=None, help="only the case's first days")
    ap.add_argument("--only", action="append", help="a source name (repeatable); default: all")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    base = load(TWIN)
    variants = {"full twin": base} | {f"no {k}": without(base, k) for k in (args.only or SOURCES)}
    rows = []
    for name, case in variants.items():
        out = args.out / name.replace(" ", "_").replace("(", "").replace(")", "").replace("'", "")
        run_demo(out, args.workers, progress=lambda *_: None, days=args.days, case=case)
        rows.append({"variant": name} | figures(out))
        print(name, rows[-1], flush=True)
    thesis_row = {"variant": "thesis (ch. 4)"} | {
        f"{arc} {c[0].upper()} (m)": thesis.OVERLAPS[arc]["pos"][i][0]
        for arc in ("short", "long") for i, c in enumerate(thesis.COMPONENTS)} | {
        "T4.4 median Mag. (mm/s)": thesis.TABLE_4_4.loc["Median", "Mag. (mm/s)"],
        "T4.4 median Mag. (%)": thesis.TABLE_4_4.loc["Median", "Mag. (%)"]}
    table = pd.DataFrame(rows + [thesis_row])
    args.out.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out / "ablation.csv", index=False)
    print(markdown(table))


def markdown(table: pd.DataFrame) -> str:
    """A Markdown table, numbers to 3 significant figures."""
    cells = [[f"{v:.3g}" if isinstance(v, float) else str(v) for v in row] for row in table.itertuples(index=False)]
    lines = ["| " + " | ".join(table.columns) + " |", "|" + "---|" * len(table.columns)]
    return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in cells])


if __name__ == "__main__":
    main()
