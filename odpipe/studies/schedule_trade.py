"""The tracking-schedule trade study (Leonard 2015, secs. 8.1.2.3-8.1.2.4): the Fig. 8.4 mesh of
(LiAISON gap, ground gap) schedules and the Fig. 8.9 scheduling offset, on the set-up of
:mod:`.ground_and_crosslink` (same truth, data, noise and filter).

* Mesh: every pair of ``mesh.gaps_h`` (h after each 3-h pass; ``inf`` = that data type unused),
  3-D position 3-sigma and error of the forward filter, RMS over days 6-9, per spacecraft.
* Offset: the mesh's diagonal (equal gaps) with the ground passes starting halfway through the
  first LiAISON gap, against simultaneous passes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from parsers.atomic import save_figure

from .ground_and_crosslink import NAMES, fit_schedule, prepare
from .study_report import plot_convergence, write_markdown, write_table


def _fit(cfg, sim, case) -> dict:
    r = fit_schedule(cfg, sim, case)
    m = r["metrics"]
    return {**case, "rows": len(r["rows"]), "converged": r["solution"].converged,
            **{f"{sc} {k}": m[sc][k] for sc in NAMES for k in ("rms_sig3", "rms_err")}}


def plot_mesh(out: Path, df: pd.DataFrame, gaps) -> Path:
    """Fig. 8.4 analogue: 3-sigma RMS (days 6-9) over the (ground gap, LiAISON gap) mesh, per spacecraft."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    labels = ["inf" if not np.isfinite(g) else f"{g:g}" for g in gaps]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    for ax, sc, vmax in zip(axes, NAMES, (500.0, 150.0)):           # the thesis' colour limits
        grid = df.pivot(index="liaison_gap_h", columns="ground_gap_h", values=f"{sc} rms_sig3")
        grid = grid.reindex(index=list(gaps), columns=list(gaps)).to_numpy()
        im = ax.imshow(grid, origin="lower", norm=LogNorm(vmin=1.0, vmax=vmax), cmap="viridis")
        for (i, j), v in np.ndenumerate(grid):
            if np.isfinite(v):
                ax.text(j, i, f"{v:.0f}", ha="center", va="center", fontsize=7,
                        color="w" if v < 0.3 * vmax else "k")
        ax.set_xticks(range(len(gaps)), labels)
        ax.set_yticks(range(len(gaps)), labels)
        ax.set_xlabel("ground gap (h)")
        ax.set_ylabel("LiAISON gap (h)")
        ax.set_title(f"{sc}: 3-D position 3-sigma, RMS days 6-9 (m)", fontsize=9)
        fig.colorbar(im, ax=ax, shrink=0.85)
    fig.tight_layout()
    path = Path(out) / "mesh.png"
    save_figure(path, fig, dpi=110)
    plt.close(fig)
    return path


def run(cfg: dict, out, log=print, sim: dict | None = None) -> dict:
    """The mesh and the offset study on ``sim`` (a :func:`prepare` of this set-up; made when None); writes
    report.md, the tables and plots into ``out``."""
    sim = sim or prepare(cfg, log)
    gaps = [float(g) for g in cfg["mesh"]["gaps_h"]]
    mesh = []
    for lg in gaps:
        for gg in gaps:
            if np.isfinite(lg) or np.isfinite(gg):
                mesh.append(_fit(cfg, sim, {"liaison_gap_h": lg, "ground_gap_h": gg}))
                r = mesh[-1]
                log(f"mesh ({lg:g}, {gg:g}): L1 {r['L1 rms_sig3']:.1f} m, GEO {r['GEO rms_sig3']:.1f} m (3-sigma)")
    mesh = pd.DataFrame(mesh)
    plot_mesh(out, mesh, gaps)
    offset = []
    for g in (float(g) for g in cfg["offset"]["gaps_h"]):
        for shift in (0.0, 0.5 * g) if g > 0 else (0.0,):          # continuous: nothing to offset
            offset.append(_fit(cfg, sim, {"liaison_gap_h": g, "ground_gap_h": g, "ground_offset_h": shift}))
        a, b = offset[-2] if g > 0 else offset[-1], offset[-1]
        log(f"offset study gap {g:g} h: L1 {a['L1 rms_sig3']:.1f} -> {b['L1 rms_sig3']:.1f} m, "
            f"GEO {a['GEO rms_sig3']:.1f} -> {b['GEO rms_sig3']:.1f} m")
    offset = pd.DataFrame(offset)
    simultaneous = offset[offset.ground_offset_h == 0]
    shifted = offset[(offset.ground_offset_h > 0) | (offset.liaison_gap_h == 0)]
    panels = [{"title": f"{sc}: ground simultaneous or offset by half the gap (cf. Fig. 8.9)",
               "t_days": None, "xlabel": "gap between passes, LiAISON = ground (h)",
               "curves": [(f"{what} {kind}", d[f"{sc} {col}"].to_numpy(),
                           {"t": d["liaison_gap_h"].to_numpy(), "color": color, "ls": ls, "marker": "o", "ms": 3})
                          for kind, d, color in (("simultaneous", simultaneous, "C0"), ("offset", shifted, "C3"))
                          for what, col, ls in (("3-sigma", "rms_sig3", "--"), ("error", "rms_err", "-"))]}
              for sc in NAMES]
    plot_convergence(out, "offset", panels, "RMS days 6-9 (m)")
    ratio = (shifted.set_index("liaison_gap_h")[[f"{sc} rms_sig3" for sc in NAMES]]
             / simultaneous.set_index("liaison_gap_h")[[f"{sc} rms_sig3" for sc in NAMES]])
    cols = ["liaison_gap_h", "ground_gap_h", "rows"] + [f"{sc} {k}" for sc in NAMES for k in ("rms_sig3", "rms_err")]
    sections = [
        ("Fig. 8.4: 3-sigma RMS over days 6-9 for every (LiAISON gap, ground gap) schedule",
         "![mesh](mesh.png)\n\n" + write_table(out, "mesh", mesh[cols + ["converged"]])),
        ("Sec. 8.1.2.4 / Fig. 8.9: scheduling offset on the diagonal (x-axis: the common gap, h)",
         "![offset](offset.png)\n\nOffset / simultaneous 3-sigma, by gap:\n\n"
         + write_table(out, "offset_ratio", ratio.reset_index())
         + "\n" + write_table(out, "offset", offset[cols + ["ground_offset_h", "converged"]])),
        ("Set-up", "As `study_ground_and_crosslink.toml` (see its report for the differences from the thesis); the "
                   "x-axis of the offset plot is the gap in hours.\n")]
    write_markdown(out, "Study schedule_trade: tracking-schedule trade study (Leonard thesis secs. 8.1.2.3-8.1.2.4)",
                   sections)
    return {"mesh": mesh, "offset": offset, "ratio": ratio}
