"""Settings chosen by a rule that never looks at the arc it is judged on (leave-one-out over arcs).

Inputs are the figures of every candidate setting on every arc of a chain:

* ``arcs``: one row per (candidate, arc): ``converged`` (bool) and ``worst_rms`` (the arc's largest
  per-station post-fit RMS, mm/s);
* ``overlaps``: one row per (candidate, a, b) overlap of consecutive arcs: ``pos_3d_rms`` (m).

A figure may use more arcs' data than its own (a two-day arc, an overlap of one with a daily arc): an
optional ``days`` column (arc names joined by ","; default the row's ``arc``, or ``a`` and ``b``) names
them all, and an optional ``judges`` column of ``overlaps`` the arcs whose solution it judges (default
``a`` and ``b``), and an optional ``vs`` column the arc it was compared with (default the other of ``a``
and ``b``).

The rule, for a set of training arcs (any arcs but the judged one), takes the candidates with a figure for
every training arc and sees only figures whose ``days`` are all training arcs: a candidate is admissible
when every such arc figure converged with every station at most ``max_rms`` mm/s; among the admissible
ones (all candidates when none is) it takes the smallest mean 3D overlap RMS over such overlaps (none: not
chosen), then the smallest mean worst-station RMS. An unseen arc is judged with the candidate the rule
picks on all the arcs before it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def _days(table: pd.DataFrame, column: str, default) -> pd.Series:
    """Each row's set of arcs from ``column`` ("a,b") where present and not empty, else ``default(row)``."""
    given = table[column] if column in table else pd.Series("", index=table.index)
    return pd.Series([set(str(g).split(",")) if isinstance(g, str) and g else default(r)
                      for g, r in zip(given, table.itertuples(index=False))], index=table.index, dtype=object)


def arc_days(arcs: pd.DataFrame) -> pd.Series:
    """The arcs whose data each arc figure uses."""
    return _days(arcs, "days", lambda r: {r.arc})


def overlap_days(overlaps: pd.DataFrame, column: str = "days") -> pd.Series:
    """The arcs whose data each overlap uses (``column`` "days"), or whose solutions it judges ("judges")."""
    return _days(overlaps, column, lambda r: {r.a, r.b})


def choose(arcs: pd.DataFrame, overlaps: pd.DataFrame, training, max_rms: float = 2.0) -> str:
    """The candidate the rule picks from the ``training`` arcs' figures alone (see the module)."""
    training = set(training)
    complete = arcs[arcs["arc"].isin(training)].groupby("candidate")["arc"].nunique() == len(training)
    candidates = sorted(complete[complete].index)
    if not candidates:
        raise ValueError(f"no candidate has figures on every training arc {sorted(training)}")
    a = arcs[arcs["candidate"].isin(candidates) & arc_days(arcs).map(lambda d: d <= training).astype(bool)]
    o = overlaps[overlap_days(overlaps).map(lambda d: d <= training).astype(bool)] if len(overlaps) else overlaps
    score = pd.DataFrame(index=candidates)
    g = a.groupby("candidate")
    ok = g.apply(lambda d: bool(d["converged"].all() and (d["worst_rms"] <= max_rms).all()))
    score["admissible"] = ok.reindex(candidates).astype("boolean").fillna(False).astype(bool)   # no figure seen: no
    score["overlap"] = o.groupby("candidate")["pos_3d_rms"].mean().reindex(candidates).fillna(np.inf)
    score["rms"] = g["worst_rms"].mean().reindex(candidates)
    pool = score[score["admissible"]] if score["admissible"].any() else score
    return str(pool.sort_values(["overlap", "rms"], kind="stable").index[0])


def held_out(arcs: pd.DataFrame, overlaps: pd.DataFrame, max_rms: float = 2.0) -> pd.DataFrame:
    """For each arc: the candidate chosen on the other arcs and that arc's own figures with it (every
    column of ``arcs``), plus the overlaps it takes part in (``overlap_<other arc>_*`` columns)."""
    names = sorted(arcs["arc"].unique())
    rows = []
    for judged in names:
        pick = choose(arcs, overlaps, [n for n in names if n != judged], max_rms)
        row = arcs[(arcs["candidate"] == pick) & (arcs["arc"] == judged)].iloc[0].to_dict()
        judges = overlap_days(overlaps, "judges").map(lambda d: judged in d).astype(bool)
        mine = overlaps[(overlaps["candidate"] == pick) & judges]
        for o in mine.itertuples(index=False):
            vs = getattr(o, "vs", "")
            other = vs if isinstance(vs, str) and vs else (o.b if o.a == judged else o.a)
            for col in ("pos_3d_rms", "radial", "intrack", "crosstrack"):
                row[f"overlap_{other}_{col}"] = getattr(o, col)
        rows.append(row)
    return pd.DataFrame(rows)
