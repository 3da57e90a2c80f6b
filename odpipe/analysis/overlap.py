"""Overlap precision: how two solutions of overlapping arcs differ, in RIC.

For each overlap, the position and velocity differences (arc A minus arc B)
are resolved in A's radial / in-track / cross-track axes on a time grid, and
summarised by their RMS per component and in 3D. Over many overlaps the
report gives mean ± standard deviation of those figures, as the ARTEMIS
overlap studies did (seed 004, sections 4.5–4.6, Figures 4.10–4.13).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline

from odpipe.constants import J2000, SECONDS_PER_DAY
from odpipe.frames.local import rtn_matrix
from odpipe.time import utc_to_tdb
from parsers import oem


COMPONENTS = ("radial", "intrack", "crosstrack")
EDGE = 2e-6  # s: products start and end on whole microseconds inside their arc (pipeline.products.product_epochs)


class SampledTrajectory:
    """A trajectory from states on a grid (e.g. an OEM), by cubic Hermite interpolation of position.

    ``t_tdb`` (N,) s, ``states`` (N,6) m, m/s. Between nodes h apart the
    position error is of order h⁴·|r⁗|/384: keep h small against the orbit's
    time scales (60 s is ample for lunar and libration orbits). ``center``: the
    body the states are relative to (e.g. 'moon'), as the measurement models read it.
    """

    def __init__(self, t_tdb, states, center: str | None = None):
        self.center = center
        self.t_tdb = np.asarray(t_tdb, dtype=float)
        states = np.asarray(states, dtype=float)
        self._spline = CubicHermiteSpline(self.t_tdb, states[:, :3], states[:, 3:], axis=0)
        self._dspline = self._spline.derivative()
        self.t0, self.t1 = self.t_tdb[0], self.t_tdb[-1]

    def state(self, t_tdb):
        t = np.atleast_1d(np.asarray(t_tdb, dtype=float))
        if np.any(t < self.t0 - EDGE) or np.any(t > self.t1 + EDGE):
            raise ValueError(f"epoch outside the trajectory span [{self.t0}, {self.t1}] s TDB")
        return np.hstack([self._spline(t), self._dspline(t)])


class PiecewiseTrajectory:
    """Consecutive trajectories (e.g. OEM segments split at maneuvers) as one; at a shared
    boundary epoch the later piece (after the maneuver) answers."""

    def __init__(self, pieces):
        self.pieces = sorted(pieces, key=lambda p: p.t0)
        centers = {getattr(p, "center", None) for p in self.pieces}
        if len(centers) > 1:
            raise ValueError(f"trajectory pieces relative to different centres: {sorted(map(str, centers))}")
        self.center = centers.pop()
        self.t0, self.t1 = self.pieces[0].t0, self.pieces[-1].t1
        self._starts = np.array([p.t0 for p in self.pieces])

    def state(self, t_tdb):
        t = np.atleast_1d(np.asarray(t_tdb, dtype=float))
        k = np.clip(np.searchsorted(self._starts, t, side="right") - 1, 0, len(self.pieces) - 1)
        out = np.empty((t.size, 6))
        for j in np.unique(k):
            out[k == j] = self.pieces[j].state(t[k == j])
        return out


def oem_trajectory(path) -> PiecewiseTrajectory:
    """All segments of an OEM as one trajectory in TDB seconds past J2000 (m, m/s), centred as its CENTER_NAME."""
    pieces = []
    for seg in oem.read(path):
        scale = seg.meta.get("TIME_SYSTEM", "UTC")
        if scale == "TDB":
            t = (seg.epochs - J2000) / np.timedelta64(1, "s")
        elif scale == "UTC":
            t = utc_to_tdb(seg.epochs)
        else:
            raise ValueError(f"{path}: TIME_SYSTEM {scale} not supported (TDB or UTC)")
        center = str(seg.meta.get("CENTER_NAME", "")).strip().lower() or None
        pieces.append(SampledTrajectory(t, seg.states, center))
    return PiecewiseTrajectory(pieces)


@dataclass
class Overlap:
    """Differences (A − B) over one overlap: ``t_tdb`` (N,), ``dr_ric`` (N,3) m, ``dv_ric`` (N,3) m/s."""

    name: str
    t_tdb: np.ndarray
    dr_ric: np.ndarray
    dv_ric: np.ndarray

    def statistics(self) -> dict:
        """RMS per RIC component and 3D RMS of position (m) and velocity (m/s), and the maxima."""
        row = {"overlap": self.name, "t_start_tdb": self.t_tdb[0], "t_end_tdb": self.t_tdb[-1],
               "hours": (self.t_tdb[-1] - self.t_tdb[0]) / 3600.0}
        for kind, d in (("pos", self.dr_ric), ("vel", self.dv_ric)):
            rms = np.sqrt(np.mean(d**2, axis=0))
            for c, v in zip(COMPONENTS, rms):
                row[f"{kind}_{c}_rms"] = v
            row[f"{kind}_3d_rms"] = float(np.sqrt(np.sum(rms**2)))
            row[f"{kind}_3d_max"] = float(np.max(np.linalg.norm(d, axis=1)))
        return row


def compare(traj_a, traj_b, name: str = "", step: float = 600.0) -> Overlap:
    """Differences A − B over the common span of two trajectories, on a grid of ``step`` s.

    Each trajectory offers ``state(t_tdb) -> (N,6)`` and its span ``t0``, ``t1``;
    both must be about the same centre.
    """
    t0, t1 = max(traj_a.t0, traj_b.t0), min(traj_a.t1, traj_b.t1)
    if t1 <= t0:
        raise ValueError(f"arcs {name!r} do not overlap")
    n = max(int(np.ceil((t1 - t0) / step)), 1)
    t = np.linspace(t0, t1, n + 1)
    xa, xb = traj_a.state(t), traj_b.state(t)
    rot = rtn_matrix(xa[:, :3], xa[:, 3:])  # rows R, T(in-track), N(cross-track)
    d = xa - xb
    return Overlap(name, t, np.einsum("nij,nj->ni", rot, d[:, :3]), np.einsum("nij,nj->ni", rot, d[:, 3:]))


def summarize(overlaps: list[Overlap]) -> pd.DataFrame:
    """One row per overlap, then 'mean' and 'std' rows over all overlaps."""
    table = pd.DataFrame([o.statistics() for o in overlaps])
    figures = [c for c in table.columns if c.startswith(("pos_", "vel_"))]
    mean = table[figures].mean().to_dict() | {"overlap": "mean"}
    std = table[figures].std(ddof=1 if len(table) > 1 else 0).to_dict() | {"overlap": "std"}
    return pd.concat([table, pd.DataFrame([mean, std])], ignore_index=True)


def report_tables(table: pd.DataFrame) -> list[tuple[str, pd.DataFrame, dict]]:
    """(caption, table, formats) of a :func:`summarize` table for a report: per overlap its span (UTC)
    and the RIC RMS, 3D RMS and 3D maximum differences, position in m and velocity in mm/s, each to 3
    significant figures as the run reports' statistics (GRAIL-B's 566.818 m showed its mm); then the mean
    and standard deviation over the overlaps, without the span columns."""
    from odpipe.numerics.precision import significant
    from odpipe.time import tdb_to_utc

    each = table[~table["overlap"].isin(["mean", "std"])]
    out = pd.DataFrame({"overlap": each["overlap"],
                        "start (UTC)": np.asarray(tdb_to_utc(each["t_start_tdb"].to_numpy(float)), "datetime64[ns]"),
                        "end (UTC)": np.asarray(tdb_to_utc(each["t_end_tdb"].to_numpy(float)), "datetime64[ns]"),
                        "duration (h)": each["hours"]})
    figures = pd.DataFrame({"overlap": table["overlap"]})
    names = {"radial_rms": "radial RMS", "intrack_rms": "in-track RMS", "crosstrack_rms": "cross-track RMS",
             "3d_rms": "3D RMS", "3d_max": "3D max"}
    for kind, what, scale, unit in (("pos", "position", 1.0, "m"), ("vel", "velocity", 1e3, "mm/s")):
        for key, name in names.items():
            figures[f"{what} {name} ({unit})"] = table[f"{kind}_{key}"] * scale
    formats = {c: significant for c in figures.columns[1:]} | {"duration (h)": "{:.1f}"}
    stats = figures[figures["overlap"].isin(["mean", "std"])].rename(columns={"overlap": "statistic"})
    return [("per overlap", pd.concat([out, figures.loc[each.index].drop(columns="overlap")], axis=1), formats),
            ("over all overlaps", stats, formats)]


def consecutive_overlaps(trajs: dict, order, out, label: str, title: str = "", step: float = 600.0):
    """Overlaps of consecutive arcs in ``order`` (names in ``trajs``) whose spans overlap: the
    summary table written to ``out/overlap_{label}.csv`` and its position and velocity plots.

    Returns (table, [(png path, caption)]), or (None, []) when no consecutive arcs overlap.
    """
    from parsers.atomic import write_text

    names = list(order)
    pairs = [(a, b) for a, b in zip(names[:-1], names[1:]) if trajs[a].t1 > trajs[b].t0]
    if not pairs:
        return None, []
    table = summarize([compare(trajs[a], trajs[b], f"{a} - {b}", step) for a, b in pairs])
    write_text(out / f"overlap_{label}.csv", table.to_csv(index=False))
    pngs = []
    for q, what, unit in (("pos", "position", "m"), ("vel", "velocity", "mm/s")):
        pngs.append((out / f"overlap_{label}_{q}.png",
                     f"{what.capitalize()} differences over each overlap: radial, in-track, cross-track and 3D RMS "
                     f"({unit})"))
        plot_overlaps(table, pngs[-1][0], q, f"{title or label} {what} overlaps")
    return table, pngs


def short_arc_schedule(maneuvers_tdb, arc_days: float = 5.0, margin_s: float = 3600.0):
    """Short-arc overlap pairs between consecutive maneuvers (seed 004 §4.5).

    For each interval between maneuvers k and k+1: arc A starts ``margin_s``
    after maneuver k and lasts ``arc_days``; arc B ends ``margin_s`` before
    maneuver k+1 and lasts ``arc_days``. Returns a list of ((a0, a1), (b0, b1)).
    """
    m = np.sort(np.asarray(maneuvers_tdb, dtype=float))
    span = arc_days * SECONDS_PER_DAY
    return [((m0 + margin_s, m0 + margin_s + span), (m1 - margin_s - span, m1 - margin_s))
            for m0, m1 in zip(m[:-1], m[1:])]


def long_arc_schedule(maneuvers_tdb, margin_s: float = 3600.0):
    """Long-arc overlap pairs spanning one maneuver each (seed 004 §4.6).

    Arc k runs from just after maneuver k to just before maneuver k+2 (so it
    estimates maneuver k+1); arc k+1 starts just after maneuver k+1. Consecutive
    arcs overlap between maneuvers k+1 and k+2. Returns a list of ((a0, a1), (b0, b1)).
    """
    m = np.sort(np.asarray(maneuvers_tdb, dtype=float))
    arcs = [(m[k] + margin_s, m[k + 2] - margin_s) for k in range(len(m) - 2)]
    return list(zip(arcs[:-1], arcs[1:]))


def plot_overlaps(summary: pd.DataFrame, path, kind: str = "pos", title: str = "") -> None:
    """Bar chart per overlap of the R, I, C and 3D RMS differences (thesis Figs. 4.10–4.13), on a bare Agg
    figure (no pyplot). Margins (inches) are sized from the longest overlap name, measured by the renderer
    without drawing (a tight layout's extra draw): the 30°-slanted names and the x label fit the figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from parsers.atomic import save_figure

    rows = summary[~summary["overlap"].isin(["mean", "std"])]
    labels = ["Radial", "In-track", "Cross-track", "3D RMS"]
    cols = [f"{kind}_{c}_rms" for c in COMPONENTS] + [f"{kind}_3d_rms"]
    scale, unit = (1.0, "m") if kind == "pos" else (1e3, "mm/s")
    x = np.arange(len(rows))
    fig = Figure(figsize=(8, 4))
    canvas = FigureCanvasAgg(fig)
    ax = fig.subplots()
    for k, (label, col) in enumerate(zip(labels, cols)):
        ax.bar(x + (k - 1.5) * 0.2, rows[col] * scale, width=0.2, label=label)
    ax.set_xticks(x, rows["overlap"], rotation=30, ha="right")
    ax.set_xlim(-0.5, len(rows) - 0.5)
    measure = canvas.get_renderer().get_text_width_height_descent
    w, h = np.max([measure(str(t.get_text()), t.get_fontproperties(), ismath=False)[:2] for t in ax.get_xticklabels()]
                  or [[0, 0]],
                  axis=0) / fig.dpi   # inches, unrotated
    wide, tall = w * np.cos(np.pi / 6) + h * np.sin(np.pi / 6), w * np.sin(np.pi / 6) + h * np.cos(np.pi / 6)
    first = 0.5 / max(len(rows), 1)   # the first tick's place along the axes (fraction of their width)
    width, right, top, plot_h, bottom = 8.0, 0.15, 0.35, 2.8, tall + 0.45   # inches; 0.45: ticks, x label
    left = max(0.8, (wide + 0.1 - (width - right) * first) / (1 - first))
    fig.set_size_inches(width, top + plot_h + bottom)
    fig.subplots_adjust(left=left / width, right=1 - right / width, top=1 - top / (top + plot_h + bottom),
                        bottom=bottom / (top + plot_h + bottom))
    ax.set_ylabel(f"RMS difference ({unit})")
    ax.set_xlabel("overlap (arc A − arc B)")
    ax.set_title(title or ("Position" if kind == "pos" else "Velocity") + " overlap differences", y=1.0)
    top = float(np.nanmax(rows[cols].to_numpy(float))) * scale if len(rows) else 0.0
    if top > 0:
        ax.set_ylim(0, 1.25 * top)   # headroom: the one-row legend above the tallest bar, not on it
    ax.legend(ncol=4, loc="upper center")
    ax.grid(axis="y", alpha=0.3)
    save_figure(path, fig, dpi=110)
