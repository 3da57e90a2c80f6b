"""One daily arc refitted with each leave-one-out candidate's settings, against the nightly's neighbours.

For every candidate folder under ``OUT`` holding its own run of ``--arc`` (``benchmarks/grail_loo.py --arcs
ARC --source-from base``): convergence, rows fitted and edited, per-station RMS (mm/s), the estimated station
time offsets (ms, with sigma) and per-pass Doppler biases (mm/s), and the overlaps (3D and R/I/C RMS, m)
with the ``--against`` candidate's runs of the neighbouring arcs. Written to ``OUT/variants_<arc>.csv``.

    nice .venv/bin/python benchmarks/grail_variants.py [--out out/grail_loo] [--arc grail_b_2012_04_10]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pandas as pd

from grail_arcs import DAILY, arc_figures, trajectory
from odpipe.analysis.overlap import compare


def neighbours(arc: str) -> list[str]:
    k = DAILY.index(arc)
    return [DAILY[j] for j in (k - 1, k + 1) if 0 <= j < len(DAILY)]


def figures(out: Path, cand: str, arc: str, against: str) -> dict:
    run = out / cand / arc / "current"
    row = {"candidate": cand, **arc_figures(out / cand, arc),
           "converged": json.loads((run / "summary.json").read_text())["converged"]}
    params = pd.read_csv(run / "parameters.csv")
    for p in params[params["kind"] == "timing"].itertuples():
        row[f"{p.name}_ms"] = p.estimate * 1e3
        row[f"{p.name}_sigma_ms"] = p.sigma * 1e3
    bias = params[params["name"].str.startswith("bias.doppler_2way")]
    if len(bias):
        row["pass_bias_rms_mm_s"] = float((bias["estimate"] ** 2).mean() ** 0.5 * 1e3)
        row["pass_bias_max_mm_s"] = float(bias["estimate"].abs().max() * 1e3)
    osc = params[params["kind"] == "clock"]
    for p in osc.itertuples():
        row[p.name] = p.estimate
    for other in neighbours(arc):
        a, b = sorted((arc, other))
        ta = trajectory(out / (cand if a == arc else against), a)
        tb = trajectory(out / (cand if b == arc else against), b)
        s = compare(ta, tb, f"{a} - {b}", 60.0).statistics()
        for key, col in (("3d", "pos_3d_rms"), ("R", "pos_radial_rms"), ("I", "pos_intrack_rms"),
                         ("C", "pos_crosstrack_rms")):
            row[f"overlap_{other[-5:]}_{key}"] = s[col]
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("out/grail_loo"))
    ap.add_argument("--arc", default="grail_b_2012_04_10")
    ap.add_argument("--against", default="base")
    args = ap.parse_args(argv)
    out = args.out.resolve()
    rows = [figures(out, c.name, args.arc, args.against) for c in sorted(out.iterdir())
            if (c / args.arc / "current" / "summary.json").exists() and not (c / args.arc).is_symlink()
            and all((out / args.against / n / "current" / "trajectory.oem").exists() for n in neighbours(args.arc))]
    table = pd.DataFrame(rows)
    table.to_csv(out / f"variants_{args.arc}.csv", index=False)
    with pd.option_context("display.width", 250, "display.max_columns", 60):
        print(table.round(3).T.to_string())


if __name__ == "__main__":
    main()
