"""GRAIL-B longer and multi-arc solutions against the nightly's daily arcs (issue #24 item 4).

Needs ``benchmarks/grail_loo.py --only base`` first (the nightly chain in ``OUT/base``). Then:

* ``multiarc``: the daily arcs (``--arcs``, default all four) refitted as one multi-arc solution sharing the
  SRP scale (:mod:`odpipe.pipeline.multiarc`, its configuration written to ``OUT/multiarc_<days>/multiarc.toml``;
  overlaps with the arcs not refitted are against the nightly's);
* ``twoday``: ``runs/grail_b_2day_2012_04_09.toml`` (04-09 and 04-10 as one arc, from the start-up fit) and
  ``runs/grail_b_2day_2012_04_08.toml`` (04-08 and 04-09, from the nightly's 04-09, as the daily 04-08).

Per solution: each arc's per-station two-way RMS (mm/s) and the overlaps (3D and R/I/C RMS, m) with the
daily arcs, beside the nightly's. Written to ``OUT/multiarc_figures.csv``.

    nice .venv/bin/python benchmarks/grail_multiarc.py [--out out/grail_loo] [--only multiarc,twoday]
        [--arcs grail_b_2012_04_10,grail_b_2012_04_11]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from grail_arcs import DAILY, START, run_variant
from odpipe.analysis.overlap import compare, oem_trajectory
from odpipe.pipeline.multiarc import run_multiarc

TWO_DAY = "grail_b_2day_2012_04_09"
# two-day arc -> (the arc whose solution gives its a priori, the daily arcs it overlaps)
TWO_DAYS = {TWO_DAY: (START, ("grail_b_2012_04_08", "grail_b_2012_04_11")),
            "grail_b_2day_2012_04_08": ("grail_b_2012_04_09", ("grail_b_2012_04_10",))}


def station_rms(residuals: Path) -> dict:
    """Per-station two-way Doppler post-fit RMS (mm/s) and rows edited by the fit, of a residuals file."""
    res = pd.read_parquet(residuals)
    ok = (res["status"] == "") & (res["observable"] == "doppler_2way")
    row = {"edited": int((ok & (res["flags"] != 0)).sum())}
    for st, g in res[ok & (res["flags"] == 0)].groupby("station_rx"):
        row[f"rms_mm_s.{st}"] = float(np.sqrt(np.mean(g["postfit_los"] ** 2)) * 1e3)
    return row


def overlap(a: Path, b: Path, label: str) -> dict:
    s = compare(oem_trajectory(a), oem_trajectory(b), label, 60.0).statistics()
    return {"overlap": label, "pos_3d_rms": s["pos_3d_rms"], "radial": s["pos_radial_rms"],
            "intrack": s["pos_intrack_rms"], "crosstrack": s["pos_crosstrack_rms"], "hours": s["hours"]}


def multiarc(out: Path, arcs=DAILY, shared=("srp_scale",)) -> list[dict]:
    folder = out / ("multiarc_" + "_".join(a[-2:] for a in arcs))
    folder.mkdir(parents=True, exist_ok=True)
    cfg = folder / "multiarc.toml"
    names = arcs
    arcs = ", ".join(f'"{out / "base" / "configs" / f"{a}.toml"}"' for a in names)
    cfg.write_text(f'[multiarc]\nname = "runs"\noutput = "{folder}"\narcs = [{arcs}]\n'
                   f'shared = [{", ".join(repr(s).replace(chr(39), chr(34)) for s in shared)}]\nrounds = 1\n')
    done = all((folder / "runs" / "current" / a / "trajectory.oem").exists() for a in names)
    if not done:
        result = run_multiarc(cfg)
        print(result["shared"].to_string(index=False), flush=True)
    label = folder.name
    rows = [{"solution": label, "arc": a, **station_rms(folder / "runs" / "current" / a / "residuals.parquet")} for a in names]
    oem = {a: out / "base" / a / "current" / "trajectory.oem" for a in DAILY}   # the nightly's, where not refitted
    oem.update({a: folder / "runs" / "current" / a / "trajectory.oem" for a in names})
    for a, b in zip(DAILY[:-1], DAILY[1:]):
        if a in names or b in names:
            rows.append({"solution": label, **overlap(oem[a], oem[b], f"{a[-5:]} - {b[-5:]}")})
    return rows


def twoday(out: Path, name: str = TWO_DAY) -> list[dict]:
    """One two-day arc (``TWO_DAYS[name]``: its source arc and the daily arcs it overlaps), from the nightly's
    run of its source (or the start-up fit)."""
    source, others = TWO_DAYS[name]
    if source != START and not (out / "twoday" / source).exists():
        (out / "twoday").mkdir(parents=True, exist_ok=True)
        (out / "twoday" / source).symlink_to(out / "base" / source)
    run_variant(out / "twoday", {}, out / "start", arcs=(name,), source={name: source})
    mine = out / "twoday" / name / "current"
    rows = [{"solution": "twoday", "arc": name, **station_rms(mine / "residuals.parquet")}]
    for other in others:
        if (out / "base" / other / "current" / "trajectory.oem").exists():
            rows.append({"solution": "twoday", **overlap(mine / "trajectory.oem",
                                                     out / "base" / other / "current" / "trajectory.oem",
                                                     f"{name[-10:]} - {other[-5:]}")})
    return rows


def nightly(out: Path) -> list[dict]:
    done = [a for a in DAILY if (out / "base" / a / "current" / "trajectory.oem").exists()]
    rows = [{"solution": "nightly", "arc": a, **station_rms(out / "base" / a / "current" / "residuals.parquet")}
            for a in done]
    for a, b in zip(DAILY[:-1], DAILY[1:]):
        if a in done and b in done:
            rows.append({"solution": "nightly", **overlap(out / "base" / a / "current" / "trajectory.oem",
                                                      out / "base" / b / "current" / "trajectory.oem",
                                                      f"{a[-5:]} - {b[-5:]}")})
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("out/grail_loo"))
    ap.add_argument("--only", default="multiarc,twoday")
    ap.add_argument("--arcs", default=",".join(DAILY), help="daily arcs of the multi-arc solution")
    args = ap.parse_args(argv)
    out = args.out.resolve()
    rows = nightly(out)
    for name in args.only.split(","):
        if name == "multiarc":
            rows += multiarc(out, tuple(args.arcs.split(",")))
        else:
            rows += [r for two in TWO_DAYS for r in twoday(out, two)]
    table = pd.DataFrame(rows)
    table.to_csv(out / "multiarc_figures.csv", index=False)
    with pd.option_context("display.width", 250, "display.max_columns", 40):
        print(table.round(3).to_string(index=False))


if __name__ == "__main__":
    main()
