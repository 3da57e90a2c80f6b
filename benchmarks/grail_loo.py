"""Leave-one-out choice of the GRAIL-B nightly settings (issue #24 item 2).

Every candidate setting (only existing config keys: process noise, field degree, data weights, editing)
runs the whole nightly chain (04-08 .. 04-11 from the shared start-up fit); then, for each daily arc, the
rule of :mod:`odpipe.analysis.leave_one_out` picks a candidate from the other three arcs' figures and the
arc is judged with it. Figures go to ``OUT/arcs.csv``, ``OUT/overlaps.csv`` and ``OUT/held_out.csv``.

    nice .venv/bin/python benchmarks/grail_loo.py [--out out/grail_loo] [--only base,q3e-8]
        [--arcs grail_b_2012_04_10 --source-from base]

``--arcs`` runs only those arcs of each candidate; ``--source-from`` takes their a priori from another
candidate's runs of the source arcs (linked in), not from the candidate's own chain.

About 4 fits of 2-3 min per candidate on a loaded 2-core machine; finished arcs are skipped on a rerun.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import pandas as pd

from grail_arcs import DAILY, ORDER, PAIRS, SOURCE, START, arc_figures, overlap_figures, run_start, run_variant
from odpipe.analysis.leave_one_out import held_out

# name -> {"section.key": TOML literal}; "base" is the nightly configs as they are (since issue #24's rule:
# stochastic sigma 3e-7 m/s^2 and preprocess.apriori_blunder_k 10; docs/validation.md names the earlier runs)
CANDIDATES = {
    "base": {},
    "q1e-7": {"estimation.stochastic.sigma": "1e-7"},
    "q3e-8": {"estimation.stochastic.sigma": "3e-8"},
    "q2e-7": {"estimation.stochastic.sigma": "2e-7"},
    "deg100": {"dynamics.gravity.degree": "100"},
    "reweight": {"estimation.reweight": "true"},
    "edit3": {"estimation.edit_k": "[1e6, 10.0, 3.0]"},
    # per-pass two-way Doppler biases (m/s), per-station time-tag offsets (s)
    "bias": {"estimation.doppler_bias_sigma": "0.002"},
    "timing": {"estimation.station_time_offset_sigma": "0.01"},
    # the X-band one-way Doppler too (runs/grail_b_oneway_2012_04_10.toml's settings), the oscillator estimated
    "oneway": {"data.observables": '["doppler_2way", "doppler_1way:X"]',
               "estimation.data_sigma": "{ doppler_2way = 0.002, doppler_1way = 0.002 }",
               "estimation.oscillator_sigma": "[1e-6, 1e-12]"},
}


def collect(out: Path, names) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Per (candidate, arc) and per (candidate, overlap) figures of the candidates' finished runs."""
    arcs, overlaps = [], []
    for cand in names:
        done = [a for a in DAILY if (out / cand / a / "current" / "summary.json").exists()
                and not (out / cand / a).is_symlink()]   # a linked source arc is another candidate's
        for a in done:
            row = arc_figures(out / cand, a)
            summary = pd.read_json(out / cand / a / "current" / "summary.json", typ="series")
            rms = [v for k, v in row.items() if k.startswith(("rms_mm_s.", "rms1w_mm_s."))]  # one-way too
            arcs.append({"candidate": cand, **row, "converged": bool(summary["converged"]), "worst_rms": max(rms)})
        for a, b in PAIRS:
            if a in done and b in done:
                overlaps.append({"candidate": cand, **overlap_figures(out / cand, a, b)})
    return pd.DataFrame(arcs), pd.DataFrame(overlaps)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("out/grail_loo"))
    ap.add_argument("--only", default="", help="comma-separated candidates to run (default all)")
    ap.add_argument("--arcs", default="", help="comma-separated daily arcs to run (default the whole chain)")
    ap.add_argument("--source-from", default="", help="candidate whose source-arc runs give the a priori")
    args = ap.parse_args(argv)
    out = args.out.resolve()
    names = [n for n in CANDIDATES if not args.only or n in args.only.split(",")]
    t0 = time.perf_counter()
    run_start(out / "start")
    print(f"start-up fit ready ({time.perf_counter() - t0:.0f} s)", flush=True)
    chosen = [a for a in ORDER if not args.arcs or a in args.arcs.split(",")]
    for cand in names:
        if args.source_from and cand != args.source_from:
            for a in {SOURCE[a] for a in chosen} - {START} - set(chosen):
                link = out / cand / a
                if not link.exists():
                    link.parent.mkdir(parents=True, exist_ok=True)
                    link.symlink_to(out / args.source_from / a)
        run_variant(out / cand, CANDIDATES[cand], out / "start", arcs=chosen,
                    log=lambda s: print(f"[{time.perf_counter() - t0:6.0f} s] {s}", flush=True))
        arcs, overlaps = collect(out, CANDIDATES)
        arcs.to_csv(out / "arcs.csv", index=False)
        overlaps.to_csv(out / "overlaps.csv", index=False)
    arcs, overlaps = collect(out, CANDIDATES)
    complete = arcs.groupby("candidate")["arc"].nunique()
    full = complete[complete == len(DAILY)].index
    table = held_out(arcs[arcs["candidate"].isin(full)], overlaps[overlaps["candidate"].isin(full)])
    table.to_csv(out / "held_out.csv", index=False)
    with pd.option_context("display.width", 250, "display.max_columns", 40):
        print(arcs.round(3).to_string(index=False))
        print(overlaps.round(1).to_string(index=False))
        print(table.round(3).to_string(index=False))


if __name__ == "__main__":
    main()
