"""Residual products: statistics per station, observable and pass, and plots in physical units.

Works on a fit's residual table (columns ``epoch``, ``observable``,
``station_rx``, ``pass_id``, ``prefit_los``, ``postfit_los`` in m or m/s
along the line of sight, ``flags``, ``status``). Rate observables are shown
in mm/s, range observables in m.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.products.atomic import save_figure

_RATE = ("doppler", "range_rate", "sst_doppler")


def is_rate(observable: str) -> bool:
    return observable.startswith(_RATE)


def display_scale(observable: str) -> tuple[float, str]:
    """(factor, unit) turning line-of-sight residuals into the plotted unit."""
    return (1e3, "mm/s") if is_rate(observable) else (1.0, "m")


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def statistics(res: pd.DataFrame, by=("station_rx", "observable")) -> pd.DataFrame:
    """Count, used count, mean and RMS of pre- and post-fit residuals (LOS units) per group of used rows,
    and the post-fit RMS in the observable's own unit (``postfit_rms_unit``, e.g. Hz) when given."""
    ok = res["status"].eq("") if "status" in res else pd.Series(True, index=res.index)
    used = res[ok & res["flags"].eq(0)]
    g = used.groupby(list(by), sort=True)
    out = pd.DataFrame({
        "n_used": g.size(),
        "postfit_mean": g["postfit_los"].mean(),
        "postfit_rms": g["postfit_los"].apply(_rms),
        "prefit_rms": g["prefit_los"].apply(_rms),
    })
    if "postfit" in used.columns:
        out["postfit_rms_unit"] = g["postfit"].apply(_rms)
    out["n_edited"] = res[ok].groupby(list(by)).size().reindex(out.index).fillna(0).astype(int) - out["n_used"]
    return out.reset_index()


def plot(res: pd.DataFrame, path, which: str = "postfit", title: str = "") -> None:
    """One panel per observable, stations coloured; edited rows drawn as grey crosses."""
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
            y = g[f"{which}_los"] * scale
            ax.plot(g["epoch"], y, ".", ms=3, label=f"{station} (RMS {np.sqrt(np.mean(y**2)):.3g} {unit})")
        if edited.any():
            ax.plot(sub.loc[edited, "epoch"], sub.loc[edited, f"{which}_los"] * scale, "x", color="0.6", ms=3,
                    label=f"edited ({int(edited.sum())})")
            lim = np.nanpercentile(np.abs(sub.loc[~edited, f"{which}_los"] * scale), 99.9) * 3 if (~edited).any() else None
            if lim:
                ax.set_ylim(-lim, lim)
        ax.set_ylabel(f"{obs} ({unit})")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right", ncol=2)
    axes[0, 0].set_title(title or f"{which.replace('fit', '-fit')} residuals along the line of sight")
    fig.autofmt_xdate()
    fig.tight_layout()
    save_figure(path, fig, dpi=100)
    plt.close(fig)
