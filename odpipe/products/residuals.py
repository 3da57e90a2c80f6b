"""Residual products: statistics per station, observable and pass, and plots in physical units.

Works on a fit's residual table (columns ``epoch``, ``observable``,
``station_rx``, ``pass_id``, ``unit``, ``apriori_los`` (pre-fit, against the
a priori), ``postfit_los`` in m or m/s along the line of sight, ``postfit`` in
the row's unit, ``flags``, ``status``). Rate observables are shown in mm/s,
range observables in m.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from parsers.atomic import save_figure

_RATE = ("doppler", "range_rate", "sst_doppler")


def is_rate(observable: str) -> bool:
    return observable.startswith(_RATE)


def display_scale(observable: str) -> tuple[float, str]:
    """(factor, unit) turning line-of-sight residuals into the plotted unit."""
    return (1e3, "mm/s") if is_rate(observable) else (1.0, "m")


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


LOS_UNIT = {True: "m/s", False: "m"}


def statistics(res: pd.DataFrame, by=("station_rx", "observable"), edited_before=None) -> pd.DataFrame:
    """Per group: rows fitted (``n_used``), edited by the fit or, the tracking rows ``edited_before`` (e.g. the
    a priori blunder test's), before it (``n_edited``) and not computable by the
    models (``n_failed``); first and last epoch (UTC) of the used rows; mean and RMS of the post-fit and
    RMS of the pre-fit residual against the a priori (``apriori_los``, the first iteration's), all
    along the line of sight in ``los_unit`` (m or m/s); and the post-fit RMS in the observable's own
    unit (``postfit_rms_obs`` in ``obs_unit``, e.g. Hz, RU) when the residuals carry ``unit``."""
    by = list(by)
    ok = res["status"].eq("") if "status" in res else pd.Series(True, index=res.index)
    used = res[ok & res["flags"].eq(0)]
    g = used.groupby(by, sort=True)
    out = pd.DataFrame({"n_used": g.size()})
    out["n_edited"] = _count(res[ok & res["flags"].ne(0)], by, out.index)
    if edited_before is not None:
        out["n_edited"] += _count(edited_before, by, out.index)
    out["n_failed"] = _count(res[~ok], by, out.index)
    if "epoch" in used:
        out["start"], out["end"] = g["epoch"].min(), g["epoch"].max()
    out["prefit_rms"] = g["apriori_los"].apply(_rms)
    out["postfit_mean"] = g["postfit_los"].mean()
    out["postfit_rms"] = g["postfit_los"].apply(_rms)
    out = out.reset_index()
    if "observable" in out:
        out["los_unit"] = [LOS_UNIT[is_rate(o)] for o in out["observable"]]
    if "unit" in used and "postfit" in used:
        units = g["unit"].agg(lambda u: "/".join(sorted(set(u))))
        out["postfit_rms_obs"] = g["postfit"].apply(_rms).to_numpy()
        out["obs_unit"] = units.to_numpy()
    return out


def _count(rows: pd.DataFrame, by: list, index) -> np.ndarray:
    return rows.groupby(by).size().reindex(index).fillna(0).astype(int).to_numpy()


def report_tables(stats: pd.DataFrame) -> list[tuple[str, pd.DataFrame, dict]]:
    """(caption, table, formats) per observable and unit of a :func:`statistics` table for a report:
    residuals in the display unit (:func:`display_scale`) to 0.1 µm/s or 1 mm, in the observable's unit
    to 4 significant figures, the unit in each column name. Columns before ``n_used`` (e.g. arc,
    station, pass) lead."""
    keys = [c for c in stats.columns[: list(stats.columns).index("n_used")] if c != "observable"]
    out = []
    for (obs, unit), sub in stats.groupby(["observable", stats.get("obs_unit", pd.Series("", index=stats.index))],
                                          sort=True):
        scale, shown = display_scale(obs)
        t = sub[keys + ["n_used", "n_edited", "n_failed"]].copy()
        for col in ("start", "end"):
            if col in sub:
                t[f"{col} (UTC)"] = pd.to_datetime(sub[col]).to_numpy("datetime64[ns]")
        t[f"pre-fit RMS ({shown})"] = sub["prefit_rms"] * scale
        t[f"post-fit mean ({shown})"] = sub["postfit_mean"] * scale
        t[f"post-fit RMS ({shown})"] = sub["postfit_rms"] * scale
        if unit:
            t[f"post-fit RMS ({unit})"] = sub["postfit_rms_obs"]
        fmt = {c: ("{:.4f}" if shown == "mm/s" else "{:.3f}") for c in t.columns if f"({shown})" in c}
        if unit:
            fmt[f"post-fit RMS ({unit})"] = "{:.4g}"
        out.append((f"{obs}" + (f" (observed in {unit})" if unit else ""), t, fmt))
    return out


def edit_summary(preprocess: pd.DataFrame, res: pd.DataFrame) -> pd.DataFrame:
    """Where every row went, the preprocessing editors' and the fit's counts in one table that adds up:
    ``preprocess`` is the editors' summary (``reason``, ``rows``, last line ``used``; see
    :func:`odpipe.preprocess.flags.summary`), ``res`` the fit's residuals of the rows it was given.
    Columns ``stage``, ``reason``, ``rows``; reasons with no rows are left out; a row with two
    preprocessing reasons counts in both; the last line, ``fitted``, equals the residual tables' used rows."""
    handed = int(preprocess.loc[preprocess["reason"] == "used", "rows"].iloc[0])
    out = [("preprocess", r, int(n)) for r, n in zip(preprocess["reason"], preprocess["rows"])
           if r not in ("used", "residual") and n]
    out.append(("preprocess", "passed to the fit", handed))
    ok = res["status"].eq("") if "status" in res else pd.Series(True, index=res.index)
    out.append(("fit", "outside the arc or no data sigma", handed - len(res)))
    out += [("fit", f"not computable: {st}", int(n)) for st, n in res.loc[~ok, "status"].value_counts().items()]
    out.append(("fit", "edited (innovation test)", int((ok & res["flags"].ne(0)).sum())))
    out.append(("fit", "fitted", int((ok & res["flags"].eq(0)).sum())))
    return pd.DataFrame([r for r in out if r[2] or r[1] in ("passed to the fit", "fitted")],
                        columns=["stage", "reason", "rows"])


COLUMN = {"prefit": "apriori_los", "postfit": "postfit_los"}  # pre-fit: against the a priori


def plot(res: pd.DataFrame, path, which: str = "postfit", title: str = "") -> None:
    """One panel per observable of the ``which`` ("prefit": against the a priori, or "postfit")
    residuals, stations coloured; edited rows drawn as grey crosses; time axis UTC."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = res["status"].eq("") if "status" in res else pd.Series(True, index=res.index)
    res = res[ok]
    observables = sorted(res["observable"].unique())
    fig, axes = plt.subplots(len(observables), 1, figsize=(10, 2.8 * max(len(observables), 1)), squeeze=False)
    for ax, obs in zip(axes[:, 0], observables):
        scale, unit = display_scale(obs)
        sub = res[res["observable"] == obs]
        edited = sub["flags"] != 0
        for station, g in sub[~edited].groupby("station_rx"):
            y = g[COLUMN[which]] * scale
            ax.plot(g["epoch"], y, ".", ms=3, label=f"{station} (RMS {np.sqrt(np.mean(y**2)):.3g} {unit})")
        if edited.any():
            ax.plot(sub.loc[edited, "epoch"], sub.loc[edited, COLUMN[which]] * scale, "x", color="0.6", ms=3,
                    label=f"edited ({int(edited.sum())})")
            lim = np.nanpercentile(np.abs(sub.loc[~edited, COLUMN[which]] * scale), 99.9) * 3 if (~edited).any() else None
            if lim:
                ax.set_ylim(-lim, lim)
        ax.set_ylabel(f"{obs} ({unit})")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right", ncol=2)
    axes[-1, 0].set_xlabel("time (UTC)")
    axes[0, 0].set_title(title or f"{which.replace('fit', '-fit')} residuals along the line of sight")
    fig.autofmt_xdate()
    fig.tight_layout()
    save_figure(path, fig, dpi=100)
    plt.close(fig)
