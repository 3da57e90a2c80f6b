"""Settings chosen by a rule that never looks at the arc it is judged on (leave-one-out over arcs).

Inputs are the figures of every candidate setting on every arc of a chain:

* ``arcs``: one row per (candidate, arc): ``converged`` (bool) and ``worst_rms`` (the arc's largest
  per-station post-fit RMS, mm/s);
* ``overlaps``: one row per (candidate, a, b) overlap of consecutive arcs: ``pos_3d_rms`` (m).

The rule, for a set of training arcs (any arcs but the judged one): a candidate is admissible when every
training arc converged with every station at most ``max_rms`` mm/s; among the admissible ones (all
candidates when none is) it takes the smallest mean 3D overlap RMS over the overlaps whose two arcs are
both training arcs, then the smallest mean worst-station RMS. An unseen arc is judged with the candidate
the rule picks on all the arcs before it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def choose(arcs: pd.DataFrame, overlaps: pd.DataFrame, training, max_rms: float = 2.0) -> str:
    """The candidate the rule picks from the ``training`` arcs' figures alone (see the module)."""
    training = set(training)
    a = arcs[arcs["arc"].isin(training)]
    o = overlaps[overlaps["a"].isin(training) & overlaps["b"].isin(training)]
    complete = a.groupby("candidate")["arc"].nunique() == len(training)
    candidates = sorted(complete[complete].index)
    if not candidates:
        raise ValueError(f"no candidate has figures on every training arc {sorted(training)}")
    score = pd.DataFrame(index=candidates)
    g = a.groupby("candidate")
    score["admissible"] = g.apply(lambda d: bool(d["converged"].all() and (d["worst_rms"] <= max_rms).all()))
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
        mine = overlaps[(overlaps["candidate"] == pick) & ((overlaps["a"] == judged) | (overlaps["b"] == judged))]
        for o in mine.itertuples(index=False):
            other = o.b if o.a == judged else o.a
            for col in ("pos_3d_rms", "radial", "intrack", "crosstrack"):
                row[f"overlap_{other}_{col}"] = getattr(o, col)
        rows.append(row)
    return pd.DataFrame(rows)
