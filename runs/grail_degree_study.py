"""GRAIL-B: the effect of the lunar field's degree on post-fit residuals, daily-arc overlaps and run time.

Runs the daily arcs ``grail_b_2012_04_09`` and ``grail_b_2012_04_10`` (their overlap is
2012-04-10 04:00-07:00 UTC; the second starts from the first's solution, as configured) with the
LP field (``lpe200``) truncated at each degree, everything else as configured, and writes into OUT (default ``runs/out/grail_degree_study``):

* ``degree_study.csv`` / ``degree_study.md``: per degree and arc, post-fit 60-s two-way
  Doppler RMS per station in mm/s and mHz, fit time and run time; per degree, the overlap
  RMS in radial/in-track/cross-track and 3D;
* ``passes.csv``: post-fit RMS per station and pass (mm/s, mHz) for every run;
* ``degree_study.png``: residual RMS and overlap against degree.

Run: ``.venv/bin/python runs/grail_degree_study.py [OUT] [--degrees 50 100 150 200]`` after
``odpipe run runs/grail_b_2012_04_09_start.toml`` (the a priori of 04-09).
"""

from __future__ import annotations

import argparse
import re
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from odpipe.analysis.overlap import compare, oem_trajectory  # noqa: E402
from odpipe.pipeline.run import run_config  # noqa: E402
from odpipe.products import residuals  # noqa: E402
from parsers.atomic import save_figure, write_csv, write_text  # noqa: E402
from odpipe.time import utc_to_tdb  # noqa: E402

HERE = Path(__file__).resolve().parent
ARCS = ("grail_b_2012_04_09", "grail_b_2012_04_10")
OVERLAP = ("2012-04-10T04:00:00", "2012-04-10T07:00:00")


def derived_config(arc: str, degree: int, out: Path) -> Path:
    """The arc's configuration with the field at ``degree``, its paths made absolute, writing into ``out``."""
    text = (HERE / f"{arc}.toml").read_text()
    text = re.sub(r'"(\.\./[^"]+)"', lambda m: f'"{(HERE / m.group(1)).resolve()}"', text)
    text = re.sub(r"^degree = \d+", f"degree = {degree}", text, flags=re.M)
    text = re.sub(r'^name = "[^"]+"', f'name = "{arc}_deg{degree}"', text, count=1, flags=re.M)
    text = re.sub(r'^output = "[^"]+"', f'output = "{out}"', text, count=1, flags=re.M)
    # a chained a priori comes from the study's own run of a studied arc at this degree, else from runs/out
    text = re.sub(r'^from_oem = "out/([^/"]+)/current/trajectory.oem"', lambda m: 'from_oem = "{}"'.format(
        (out / f"{m.group(1)}_deg{degree}" if m.group(1) in ARCS else HERE / "out" / m.group(1))
        / "current" / "trajectory.oem"), text, flags=re.M)
    path = out / f"{arc}_deg{degree}.toml"
    write_text(path, text)
    return path


def residual_rms(run: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Post-fit RMS of the fitted rows per station, and per station and pass: mm/s along the line of sight and mHz."""
    res = pd.read_parquet(run / "residuals.parquet")
    out = []
    for by in (("station_rx",), ("station_rx", "pass_id")):
        st = residuals.statistics(res, by=by)
        out.append(st.assign(n=st["n_used"], rms_mm_s=st["postfit_rms"] * 1e3, rms_mhz=st["postfit_rms_unit"] * 1e3))
    return out[0], out[1]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", nargs="?", type=Path, default=HERE / "out" / "grail_degree_study")
    p.add_argument("--degrees", type=int, nargs="+", default=[50, 100, 150, 200])
    args = p.parse_args(argv)
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    rows, passes, overlaps = [], [], []
    t_ov = utc_to_tdb(np.array(OVERLAP, dtype="datetime64[ns]"))
    for degree in args.degrees:
        runs = {}
        for arc in ARCS:
            t0 = time.perf_counter()
            result = run_config(derived_config(arc, degree, out), force=True, progress=None)
            wall = time.perf_counter() - t0
            run = Path(result["run"])
            runs[arc] = run
            summary = pd.read_json(run / "summary.json", typ="series")
            st, pp = residual_rms(run)
            for rec in st.itertuples(index=False):
                rows.append({"degree": degree, "arc": arc, "station": rec.station_rx, "n": rec.n,
                             "rms_mm_s": rec.rms_mm_s, "rms_mhz": rec.rms_mhz, "converged": summary["converged"],
                             "iterations": summary["iterations"], "fit_s": summary["fit_seconds"],
                             "run_s": round(wall, 1)})
            passes.append(pp.assign(degree=degree, arc=arc))
            print(f"degree {degree} {arc}: {wall:.0f} s, " + ", ".join(
                f"{s.station_rx} {s.rms_mm_s:.1f} mm/s" for s in st.itertuples()), flush=True)
        a, b = (oem_trajectory(runs[arc] / "trajectory.oem") for arc in ARCS)
        lo, hi = max(t_ov[0], a.t0, b.t0), min(t_ov[1], a.t1, b.t1)
        stats = compare(_window(a, lo, hi), _window(b, lo, hi), f"deg{degree}", step=60.0).statistics()
        overlaps.append({"degree": degree, **stats})
    table, ov = pd.DataFrame(rows), pd.DataFrame(overlaps)
    write_csv(out / "degree_study.csv", table, index=False)
    write_csv(out / "degree_study_overlaps.csv", ov, index=False)
    write_csv(out / "passes.csv", pd.concat(passes, ignore_index=True), index=False)
    write_text(out / "degree_study.md", _markdown(table, ov))
    _plot(table, ov, out / "degree_study.png")
    print(f"report: {out / 'degree_study.md'}")
    return 0


class _window:
    """A trajectory restricted to [t0, t1] TDB s (the overlap)."""

    def __init__(self, traj, t0, t1):
        self.traj, self.t0, self.t1, self.center = traj, float(t0), float(t1), getattr(traj, "center", None)

    def state(self, t):
        return self.traj.state(t)


def _markdown(table: pd.DataFrame, ov: pd.DataFrame) -> str:
    lines = ["# GRAIL-B: lunar field degree study (LP lpe200)", "",
             "| degree | arc | station | n | post-fit RMS (mm/s) | (mHz) | iterations | fit (s) | run (s) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in table.itertuples():
        lines.append(f"| {r.degree} | {r.arc} | {r.station} | {r.n} | {r.rms_mm_s:.1f} | {r.rms_mhz:.0f} | "
                     f"{r.iterations} | {r.fit_s:.1f} | {r.run_s:.0f} |")
    lines += ["", "Overlap 2012-04-10 04:00-07:00 UTC between the two arcs (RMS of A - B):", "",
              "| degree | radial (m) | in-track (m) | cross-track (m) | 3D (m) | 3D velocity (mm/s) |",
              "|---|---|---|---|---|---|"]
    for r in ov.to_dict("records"):
        lines.append(f"| {r['degree']} | {r['pos_radial_rms']:.0f} | {r['pos_intrack_rms']:.0f} | "
                     f"{r['pos_crosstrack_rms']:.0f} | {r['pos_3d_rms']:.0f} | {r['vel_3d_rms'] * 1e3:.0f} |")
    return "\n".join(lines) + "\n"


def _plot(table: pd.DataFrame, ov: pd.DataFrame, path: Path) -> None:
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8))
    for (arc, st), g in table.groupby(["arc", "station"]):
        ax1.plot(g["degree"], g["rms_mm_s"], "o-", label=f"{arc[-5:]} {st}")
    ax1.set(xlabel="lunar field degree", ylabel="post-fit Doppler RMS (mm/s)", title="residuals")
    ax1.legend(fontsize=7)
    ax2.plot(ov["degree"], ov["pos_3d_rms"] / 1e3, "o-")
    ax2.set(xlabel="lunar field degree", ylabel="overlap 3D RMS (km)", title="04-09 / 04-10 overlap")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(path, fig, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
