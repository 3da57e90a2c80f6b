"""Residual products: statistics per station, observable and pass, and plots in physical units.

Works on a fit's residual table (columns ``epoch``, ``observable``,
``station_rx``, ``pass_id``, ``unit``, ``apriori_orbit_los`` (pre-fit: on the
a priori orbit, see :func:`apriori_orbit_los`), ``postfit_los`` in m or m/s
along the line of sight, ``postfit`` in the row's unit, ``flags``, ``status``).
Rate observables are shown in mm/s, range observables in m; angles in the plots in degrees.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.constants import C_LIGHT
from odpipe.measurements import oscillators
from odpipe.measurements.bands import downlink_bands
from odpipe.numerics.precision import decimals, significant
from parsers.atomic import save_figure

_RATE = ("doppler", "range_rate", "sst_doppler")


def is_rate(observable: str) -> bool:
    return observable.startswith(_RATE)


def display_scale(observable: str) -> tuple[float, str]:
    """(factor, unit) turning line-of-sight residuals into the plotted unit."""
    return (1e3, "mm/s") if is_rate(observable) else (1.0, "m")


PREFIT_MEANING = ("Pre-fit: observed − computed on the a priori orbit (the arc's a priori state and force "
                  "parameters, the fit's first reference)")
ONE_WAY_PREFIT = "the one-way Doppler with its oscillator at the fitted offset and drift"


def apriori_orbit_los(arc, table: pd.DataFrame) -> np.ndarray:
    """Pre-fit residuals of an arc fit (an :class:`odpipe.od.arc.ArcSolution`) along the line of sight (m,
    m/s): observed − computed on the a priori orbit (``apriori_los``) with the one-way oscillator at its
    fitted offset and drift, ``apriori_los + c (Δy0 + Δy1 (t − t_ref))`` on ``doppler_1way`` rows (Δ: fitted −
    a priori of the row's own oscillator, :mod:`odpipe.measurements.oscillators`, found from the tracking
    ``table`` row's band and pass; t the row's TDB time). The oscillator's a priori (0 ± 1e-6 when unknown) is no prediction:
    against it every one-way row reads −c y0, 4.5 m/s for GRAIL-B's 1.5e-8. A fractional offset y lowers
    the one-way Doppler along the line of sight by c y (1 − proper) span/Tc
    (:func:`odpipe.measurements.dsn.one_way_doppler`): c y to |range rate|/c + |proper| ≲ 1e-5 of itself."""
    res = arc.residuals
    out = res["apriori_los"].to_numpy(float).copy()
    oneway = res["observable"].astype(str).eq("doppler_1way").to_numpy()
    est, apriori = arc.parameters["estimate"].to_numpy(float), arc.registry.apriori
    fitted = {}   # oscillator name -> [Δy0, Δy1, t_ref]
    for i, p in enumerate(arc.registry.parameters):
        if p.kind == "clock" and "oscillator" in p.info:
            terms = fitted.setdefault(p.owner, [0.0, 0.0, p.info["t_ref"]])
            terms[("y0", "y1").index(p.info["oscillator"])] = est[i] - apriori[i]
    if not fitted or not oneway.any():
        return out
    rows = res.loc[oneway]
    bands = table.loc[rows["row"].to_numpy(), "band_down"].to_numpy()
    names = oscillators.row_names(arc.spacecraft, rows.assign(band_down=bands), fitted)
    t = rows["time"].to_numpy(float)
    dy = np.zeros(len(rows))
    for osc in set(names) & set(fitted):
        dy0, dy1, t_ref = fitted[osc]
        at = names == osc
        dy[at] = dy0 + dy1 * (t[at] - t_ref)
    out[oneway] += C_LIGHT * dy
    return out


def prefit_note(res: pd.DataFrame) -> str:
    """What the pre-fit residuals of a run's table are (a sentence for the report), with the one-way
    oscillator's share when it was fitted: the median of ``apriori_los − apriori_orbit_los`` (mm/s)."""
    oneway = res["observable"].astype(str).eq("doppler_1way") & res["status"].eq("")
    shift = (res.loc[oneway, "apriori_los"] - res.loc[oneway, "apriori_orbit_los"]).to_numpy(float) * 1e3
    if not oneway.any() or not np.any(shift):
        return PREFIT_MEANING + "."
    return (f"{PREFIT_MEANING}; {ONE_WAY_PREFIT}: its a priori (zero) is no prediction, and against it every "
            f"one-way row would be offset by {significant(np.median(shift))} mm/s (−c × the fitted offset).")


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


LOS_UNIT = {True: "m/s", False: "m"}


def statistics(res: pd.DataFrame, by=("station_rx", "observable", "band"), edited_before=None) -> pd.DataFrame:
    """Per group (a key the frame lacks is left out: ``band``, the downlink band, keeps one station's S- and
    X-band one-way apart): rows fitted (``n_used``), edited by the fit or, the tracking rows ``edited_before`` (e.g. the
    a priori blunder test's), before it (``n_edited``) and not computable by the
    models (``n_failed``); first and last epoch (UTC) of the used rows; mean and RMS of the post-fit and
    RMS of the pre-fit residual (``apriori_orbit_los``, :func:`apriori_orbit_los`), all
    along the line of sight in ``los_unit`` (m or m/s); and the post-fit RMS in the observable's own
    unit (``postfit_rms_obs`` in ``obs_unit``, e.g. Hz, RU) when the residuals carry ``unit``."""
    by = [k for k in by if k in res]
    ok = res["status"].eq("") if "status" in res else pd.Series(True, index=res.index)
    used = res[ok & res["flags"].eq(0)]
    g = used.groupby(by, sort=True)
    out = pd.DataFrame({"n_used": g.size()})
    out["n_edited"] = _count(res[ok & res["flags"].ne(0)], by, out.index)
    if edited_before is not None:
        if "band" in by and "band" not in edited_before:
            edited_before = edited_before.assign(band=downlink_bands(edited_before))
        out["n_edited"] += _count(edited_before, by, out.index)
    out["n_failed"] = _count(res[~ok], by, out.index)
    if "epoch" in used:
        out["start"], out["end"] = g["epoch"].min(), g["epoch"].max()
    out["prefit_rms"] = g["apriori_orbit_los"].apply(_rms)
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
    residuals in the display unit (:func:`display_scale`) and in the observable's unit, the unit in each
    column name; each RMS to 3 significant figures (an RMS of n rows is known to 1/√(2n): 9 % for 60),
    the post-fit mean to the first digit of its smallest standard error (RMS/√n) in the table. Columns
    before ``n_used`` (e.g. arc, station, pass) lead."""
    keys = [c for c in stats.columns[: list(stats.columns).index("n_used")] if c != "observable"]
    out = []
    for (obs, unit), sub in stats.groupby(["observable", stats.get("obs_unit", pd.Series("", index=stats.index))],
                                          sort=True):
        scale, shown = display_scale(obs)
        shown_keys = [k for k in keys if k != "band" or sub[k].fillna("").ne("").any()]   # no empty band column
        t = sub[shown_keys + ["n_used", "n_edited", "n_failed"]].copy()
        for col in ("start", "end"):
            if col in sub:
                t[f"{col} (UTC)"] = pd.to_datetime(sub[col]).to_numpy("datetime64[ns]")
        t[f"pre-fit RMS ({shown})"] = sub["prefit_rms"] * scale
        t[f"post-fit mean ({shown})"] = sub["postfit_mean"] * scale
        t[f"post-fit RMS ({shown})"] = sub["postfit_rms"] * scale
        if unit:
            t[f"post-fit RMS ({unit})"] = sub["postfit_rms_obs"]
        fmt = {c: significant for c in t.columns if "RMS" in c}
        places = decimals(np.min(sub["postfit_rms"] / np.sqrt(sub["n_used"])) * scale)  # the mean's standard error
        fmt[f"post-fit mean ({shown})"] = f"{{:.{places}f}}"   # a mean rounded to zero: html_table drops its sign
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


COLUMN = {"prefit": "apriori_orbit_los", "postfit": "postfit_los"}  # pre-fit: see apriori_orbit_los


_LARGER = {"mm/s": ("m/s", 1e-3), "m/s": ("km/s", 1e-3), "m": ("km", 1e-3)}   # unit -> (next unit, factor)


def plotted(rows: pd.DataFrame, which: str) -> tuple[np.ndarray, str]:
    """(values, unit) of one observable's ``which`` residuals as a plot shows them: along the line of sight
    (:func:`display_scale`), angles (rows in rad) in degrees, their observed unit, not range x angle in m.
    While the unedited rows reach 10^4 of the unit, the next larger one (mm/s → m/s → km/s, m → km): a
    pre-fit misfit of 1.8e6 mm/s is drawn as 1.8 km/s, not under an axis multiplier of 1e6."""
    los = rows[COLUMN[which]].to_numpy(float)
    if "unit" in rows and len(rows) and (rows["unit"] == "rad").all():
        return np.degrees(los / rows["to_los"].to_numpy(float)), "deg"
    scale, unit = display_scale(str(rows["observable"].iloc[0]) if len(rows) else "")
    values = los * scale
    kept = values[(rows["flags"] == 0).to_numpy()] if "flags" in rows else values
    kept = np.abs(kept[np.isfinite(kept)])
    big = float(kept.max()) if kept.size else 0.0
    while unit in _LARGER and big >= 1e4:
        unit, factor = _LARGER[unit]
        values, big = values * factor, big * factor
    return values, unit


def plot(res: pd.DataFrame, path, which: str = "postfit", title: str = "") -> None:
    """One panel per observable of the ``which`` ("prefit": :func:`apriori_orbit_los`, or "postfit")
    residuals, each station in one colour in every panel; edited rows drawn as grey crosses; time axis UTC.

    Drawn on a bare Agg figure (no pyplot, no tight layout: fixed margins, one draw per PNG), one marker
    line per station and one for the edited rows."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.dates import DateFormatter, date2num
    from matplotlib.figure import Figure
    from matplotlib.ticker import MultipleLocator

    ok = res["status"].eq("") if "status" in res else pd.Series(True, index=res.index)
    res = res[ok]
    observables = sorted(res["observable"].unique())
    n = max(len(observables), 1)
    height = 2.8 * n
    fig = Figure(figsize=(10, height))
    FigureCanvasAgg(fig)
    fig.subplots_adjust(left=0.09, right=0.955, top=1 - 0.35 / height, bottom=0.75 / height, hspace=0.12)
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    colour: dict = {}   # series -> matplotlib cycle colour, fixed at its first panel
    for ax, obs in zip(axes, observables):
        sub = res[res["observable"] == obs]
        edited = (sub["flags"] != 0).to_numpy()
        y_all, unit = plotted(sub, which)
        t_all = date2num(sub["epoch"].to_numpy("datetime64[ns]"))  # days: no unit conversion at each draw
        stations = series(sub, edited)
        for station in sorted(set(stations[~edited])):
            sel = ~edited & (stations == station)
            y = y_all[sel]
            ax.plot(t_all[sel], y, ".", ms=3, color=colour.setdefault(station, f"C{len(colour) % 10}"),
                    label=f"{station} (RMS {significant(np.sqrt(np.mean(y**2)))} {unit})")
        if edited.any():
            ax.plot(t_all[edited], y_all[edited], "x", color="0.6", ms=3,
                    label=f"edited ({int(edited.sum())})")
            if (~edited).any():
                lim = np.nanpercentile(np.abs(y_all[~edited]), 99.9) * 3
                if lim:
                    ax.set_ylim(-lim, lim)
        ax.set_ylabel(f"{obs} ({unit})")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best", ncol=2)   # the corner with the fewest points under it
    days = date2num(res["epoch"].to_numpy("datetime64[ns]")) if len(res) else np.zeros(1)
    step = _tick_step_days(np.ptp(days))
    axes[-1].xaxis.set_major_locator(MultipleLocator(step))
    # ticks on whole days as ISO dates; on hours as month-day and time, the year in the axis label
    axes[-1].xaxis.set_major_formatter(DateFormatter("%Y-%m-%d" if step >= 1 else "%m-%d %H:%M"))
    year = str(np.datetime64(res["epoch"].min(), "Y")) if len(res) else ""
    axes[-1].set_xlabel("time (UTC)" if step >= 1 or not year else f"time (UTC, {year})")
    # y given: the title sits on the axes' top without matplotlib laying out tick labels to look for some there
    axes[0].set_title(title or f"{which.replace('fit', '-fit')} residuals along the line of sight", y=1.0)
    save_figure(path, fig, dpi=100)


TICK_STEPS_H = (1, 2, 3, 6, 12, 24, 48, 96, 168)  # h: whole UTC hours and days


def series(rows: pd.DataFrame, edited: np.ndarray) -> np.ndarray:
    """The plot series of each row of one panel: its station, with its downlink band when the panel's used
    rows hold more than one (a station's S- and X-band one-way drawn and summed apart)."""
    stations = rows["station_rx"].astype(str).to_numpy()
    bands = rows["band"].astype(str).to_numpy() if "band" in rows else np.full(len(rows), "")
    if len(set(bands[~edited])) < 2:
        return stations
    return np.array([f"{s} {b}".rstrip() for s, b in zip(stations, bands)])


def _tick_step_days(span_days: float, most: int = 9) -> float:
    """The shortest of :data:`TICK_STEPS_H` (in days) that puts at most ``most`` ticks on ``span_days``: a
    fixed step instead of matplotlib's date locator, which searches its intervals at every draw."""
    return next((h / 24 for h in TICK_STEPS_H if span_days / (h / 24) <= most - 1), TICK_STEPS_H[-1] / 24)
