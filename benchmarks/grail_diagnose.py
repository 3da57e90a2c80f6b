"""Station diagnostics on the GRAIL-B daily arcs (issue #24 item 3), and a check with an injected fault.

1. Every arc of a variant (default the nightly's, ``out/grail_loo/base``): the diagnosis table of
   :func:`odpipe.analysis.station_diagnostics.diagnose` (ramp segments from the arc's ODFs).
2. ``--inject STATION --offset-ms DT``: the arc ``--arc`` refitted with that station's Doppler time tags
   DT late (its rows' epochs shifted as read), then diagnosed: the diagnosis should name ``timing`` at
   that station with an offset near DT (one fit of 2-3 min). ``--candidate`` refits with a leave-one-out
   candidate's settings (e.g. ``timing``: the station time offsets estimated) instead of the nightly's.

    nice .venv/bin/python benchmarks/grail_diagnose.py [--base out/grail_loo/base] [--inject DSS-34 --offset-ms 10]
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np
import pandas as pd

import odpipe.pipeline.run as pipeline_run
from grail_arcs import DAILY, RUNS, run_variant
from grail_loo import CANDIDATES
from odpipe.analysis.station_diagnostics import diagnose, rows_used
from odpipe.pipeline.config import load_config
from odpipe.pipeline.ingest import ingest


def diagnosis(run: Path, ramps: pd.DataFrame) -> pd.DataFrame:
    """The diagnosis table of one run folder (``.../current``)."""
    rows = rows_used(pd.read_parquet(run / "residuals.parquet"), pd.read_parquet(run / "tracking.parquet"), ramps)
    return diagnose(rows)


def ramps_of(name: str) -> pd.DataFrame:
    """The uplink ramp table of arc ``name``'s tracking files (its nightly configuration)."""
    return ingest(load_config(RUNS / f"{name}.toml").data.files, "report").ramps


def _late_tags(station: str, offset_s: float):
    """An ingest whose ``station`` Doppler rows carry time tags ``offset_s`` late."""
    def read(files, errors, *spacecraft):
        data = ingest(files, errors, *spacecraft)
        hit = (data.table["station_rx"] == station) & data.table["observable"].str.startswith("doppler")
        data.table.loc[hit, "epoch"] += np.timedelta64(int(round(offset_s * 1e9)), "ns")
        return data
    return read


def injected_signatures(run: Path, ramps: pd.DataFrame, station: str) -> pd.DataFrame:
    """The diagnosis of one real arc's residuals with each fault's signature added to ``station``'s rows
    (no refit): a 5 ms tag offset, the troposphere 30 % and 100 % off, a 2 mm/s bias on its first pass, 3 mm/s on
    one interior ramp segment; one line per injection with the station's diagnosis."""
    rows = rows_used(pd.read_parquet(run / "residuals.parquet"), pd.read_parquet(run / "tracking.parquet"), ramps)
    hit = rows["station"] == station
    first = hit & (rows["pass_id"] == rows.loc[hit, "pass_id"].min())
    segs = rows.loc[first, "segment"].unique()
    faults = {"timing 5 ms": -rows["acc"] * 5e-3 * hit, "troposphere +30 %": 0.3 * rows["tropo_rate"] * hit,
              "troposphere +100 %": rows["tropo_rate"] * hit,
              "pass bias 2 mm/s": 2e-3 * first,
              "ramp segment 3 mm/s": 3e-3 * (first & (rows["segment"] == segs[len(segs) // 2]))}
    out = []
    for name, add in faults.items():
        line = diagnose(rows.assign(r=rows["r"] + add.fillna(0.0))).set_index("station").loc[station]
        out.append({"injected": name, **line.to_dict()})
    return pd.DataFrame(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=Path, default=Path("out/grail_loo/base"))
    ap.add_argument("--out", type=Path, default=Path("out/grail_diagnose"))
    ap.add_argument("--arc", default="grail_b_2012_04_10")
    ap.add_argument("--inject", default="")
    ap.add_argument("--offset-ms", type=float, default=10.0)
    ap.add_argument("--candidate", default="base", help="the leave-one-out candidate whose settings the refit uses")
    ap.add_argument("--signatures", default="", help="STATION: add each fault's signature to its residuals")
    args = ap.parse_args(argv)
    base, out = args.base.resolve(), args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    tables = []
    for name in DAILY:
        run = base / name / "current"
        if not (run / "summary.json").exists():
            continue
        tables.append(diagnosis(run, ramps_of(name)).assign(arc=name))
    with pd.option_context("display.width", 250, "display.max_columns", 40):
        if tables:
            table = pd.concat(tables, ignore_index=True)
            table.to_csv(out / "diagnosis.csv", index=False)
            print(table.round(3).to_string(index=False), flush=True)
        if args.signatures:
            sig = injected_signatures(base / args.arc / "current", ramps_of(args.arc), args.signatures)
            sig.to_csv(out / f"signatures_{args.arc}_{args.signatures}.csv", index=False)
            print(sig.round(3).to_string(index=False))
        if args.inject:
            folder = out / f"{args.inject}_{args.offset_ms:g}ms_{args.candidate}"
            source = "grail_b_2012_04_09" if args.arc == "grail_b_2012_04_10" else None
            if source and not (folder / source).exists():
                folder.mkdir(parents=True, exist_ok=True)
                os.symlink(base / source, folder / source)
            saved = pipeline_run.ingest
            pipeline_run.ingest = _late_tags(args.inject, args.offset_ms / 1e3)
            try:
                run_variant(folder, CANDIDATES[args.candidate], base.parent / "start", arcs=(args.arc,))
            finally:
                pipeline_run.ingest = saved
            run = folder / args.arc / "current"
            injected = diagnosis(run, ramps_of(args.arc)).assign(arc=args.arc, injected=f"{args.inject} {args.offset_ms:g} ms")
            injected.to_csv(folder / "diagnosis.csv", index=False)
            print(injected.round(3).to_string(index=False))


if __name__ == "__main__":
    main()
