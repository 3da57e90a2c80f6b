"""Station diagnostics: which station's Doppler residuals stand out, and the signature that explains them.

Each station's post-fit line-of-sight residuals r (m/s, rows used by the fit) are compared with what a
known fault leaves in them:

* ``timing``: a time-tag offset dt (s, tags late) leaves r = -a dt, a the rows' line-of-sight
  acceleration (the time derivative of the computed range rate along each pass);
* ``troposphere``: a troposphere model wrong by a fraction s leaves r = s g, g the model's own
  Doppler correction (``tropo_m`` over the count time, m/s), largest at low elevation (counted beyond
  the pass biases: see :func:`signature_fit`);
* ``pass_bias``: a constant offset per pass (what a per-pass Doppler bias parameter absorbs);
* ``ramp_segment``: one uplink ramp segment offset from its neighbours (a bad ramp record).

The daily arcs' post-fit residuals are smooth signals of the lunar field (lag-1 autocorrelation
0.88-0.99 at 60 s), so tests that take rows as independent find everything significant. The rules
are therefore: timing, troposphere and pass bias name the cause when their least-squares fit explains
at least ``min_explained`` of the station's residual variance (the largest wins); a ramp segment does
when its offset from the average of the segments either side is ``min_z`` robust sigmas (1.4826 MAD) of
those offsets over the station's segments. A station stands out when its RMS exceeds ``factor`` times
the median of the stations' RMS, or ``max_rms``.

Where the fit estimated a station's time-tag offset (registry kind ``timing``) or per-pass Doppler
biases, :func:`estimated_terms` says how much of that station's residuals they took: the fraction of the
variance of r0 = r + their contribution (the residuals the same orbit would leave without them) that they
remove, with the time offset and its formal sigma. A station is then said to be explained by the
estimated term when that fraction is at least ``min_explained`` and the estimates differ from zero
(sum of (estimate / sigma)^2 above the chi-square 99 % point for their number): an estimate within its
sigma also "removes" variance, because the orbit takes the opposite of its signature (on 04-10, DSS-34's
offset 5.4 ± 7.5 ms took 86 %). The causes are named ``timing_estimated`` and ``pass_bias_estimated``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.special import chdtri  # chi-square inverse survival function (scipy.stats costs ~1 s to import)

SIGNATURES = ("timing", "troposphere", "pass_bias")
FACTOR, MAX_RMS = 1.5, 2e-3   # a station stands out above FACTOR times the stations' median RMS, or MAX_RMS (m/s)


def rows_used(residuals: pd.DataFrame, tracking: pd.DataFrame, ramps: pd.DataFrame | None = None,
              observable: str = "doppler_2way") -> pd.DataFrame:
    """The fitted rows of ``observable`` with what the signatures need: station, pass, time (TDB s), residual
    ``r`` (m/s), line-of-sight acceleration ``acc`` (m/s²), troposphere rate ``tropo_rate`` (m/s) and
    ``segment``, the index in ``ramps`` (columns station, start, end UTC) of the transmitter's ramp
    segment at the row's mid-count transmission (-1: none). ``residuals``/``tracking``: a run's
    residuals.parquet and tracking.parquet (rows by ``row``)."""
    res = residuals[(residuals["observable"] == observable) & (residuals["status"] == "")
                    & (residuals["flags"] == 0)]
    trk = tracking.loc[res["row"].to_numpy()]
    out = pd.DataFrame({"station": res["station_rx"].to_numpy(), "pass_id": res["pass_id"].to_numpy(),
                        "time": res["time"].to_numpy(float), "r": res["postfit_los"].to_numpy(float),
                        "rate": ((trk["value"].to_numpy(float) - res["prefit"].to_numpy(float))
                                 * res["to_los"].to_numpy(float)),
                        "tropo_rate": (trk["tropo_m"].to_numpy(float) if "tropo_m" in trk else np.nan)
                        / trk["count_time"].to_numpy(float),
                        "segment": _segments(trk, ramps)})
    out = out.sort_values(["station", "pass_id", "time"], kind="stable").reset_index(drop=True)
    out["acc"] = np.nan
    for _, g in out.groupby(["station", "pass_id"]):
        if len(g) >= 3:
            out.loc[g.index, "acc"] = np.gradient(g["rate"].to_numpy(), g["time"].to_numpy())
    return out.drop(columns="rate")


def _segments(trk: pd.DataFrame, ramps: pd.DataFrame | None) -> np.ndarray:
    seg = np.full(len(trk), -1)
    if ramps is None or not len(ramps):
        return seg
    sent = (trk["epoch"].to_numpy("datetime64[ns]")
            - (trk["rtlt_s"].to_numpy(float) * 1e9).astype("timedelta64[ns]"))
    tx = trk["station_tx"].astype(str).to_numpy()
    for st in np.unique(tx):
        r = ramps[ramps["station"] == st].sort_values("start")
        if not len(r):  # a station without ramps (one-way, a non-DSN network): no segments
            continue
        on = tx == st
        k = np.searchsorted(r["start"].to_numpy("datetime64[ns]"), sent[on], side="right") - 1
        inside = (k >= 0) & (sent[on] < r["end"].to_numpy("datetime64[ns]")[np.clip(k, 0, None)])
        seg[on] = np.where(inside, r.index.to_numpy()[np.clip(k, 0, None)], -1)
    return seg


def _design(g: pd.DataFrame, signature: str) -> np.ndarray:
    """Columns of the signature's regression for one station's rows ``g``."""
    if signature == "timing":
        return -g[["acc"]].to_numpy()
    if signature == "troposphere":
        return g[["tropo_rate"]].to_numpy()
    passes = g["pass_id"].to_numpy()
    return (passes[:, None] == np.unique(passes)[None, :]).astype(float)


def _ss(A: np.ndarray, r: np.ndarray) -> float:
    x, *_ = np.linalg.lstsq(A, r, rcond=None)
    return float(np.sum((r - A @ x) ** 2))


def signature_fit(g: pd.DataFrame, signature: str) -> dict:
    """Least-squares fit of one signature to one station's residuals: parameters and the fraction of the
    residual variance it explains. The troposphere's fraction is what it explains beyond the pass biases
    (its Doppler signature changes sign between a pass's rise and set; on one side of a pass alone it
    would pass for a bias)."""
    A = _design(g, signature)
    ok = np.all(np.isfinite(A), axis=1) & np.isfinite(g["r"].to_numpy())
    A, r = A[ok], g["r"].to_numpy()[ok]
    if r.size <= A.shape[1] or not np.any(A):
        return {"signature": signature, "explained": 0.0, "params": np.zeros(A.shape[1])}
    x, *_ = np.linalg.lstsq(A, r, rcond=None)
    ss0 = float(r @ r)
    if signature == "troposphere":
        B = _design(g[ok], "pass_bias")
        gain = _ss(B, r) - _ss(np.column_stack([A, B]), r)
    else:
        gain = ss0 - _ss(A, r)
    return {"signature": signature, "explained": gain / ss0 if ss0 > 0 else 0.0, "params": x}


def segment_offsets(g: pd.DataFrame) -> pd.DataFrame:
    """Per interior ramp segment of one station's passes: its mean residual minus the average of the
    means of the segments either side (m/s; a straight trend cancels), and that offset in robust sigmas
    (1.4826 MAD) over the station's segments."""
    rows = []
    for _, p in g[g["segment"] >= 0].groupby("pass_id"):
        means = p.groupby("segment", sort=False)["r"].agg(["mean", "size"])
        m = means["mean"].to_numpy()
        for j in range(1, len(means) - 1):
            rows.append({"segment": means.index[j], "rows": int(means["size"].iloc[j]),
                         "offset": m[j] - 0.5 * (m[j - 1] + m[j + 1])})
    out = pd.DataFrame(rows, columns=["segment", "rows", "offset"])
    mad = 1.4826 * np.median(np.abs(out["offset"] - np.median(out["offset"]))) if len(out) else np.nan
    out["z"] = (out["offset"] - np.median(out["offset"])) / mad if mad > 0 else 0.0
    return out


def estimated_terms(g: pd.DataFrame, params: pd.DataFrame | None, observable: str = "doppler_2way") -> dict:
    """What the fit's estimated time-tag offset and per-pass biases of one station (rows ``g`` of
    :func:`rows_used`) took from its residuals: ``timing_estimated_ms`` and its sigma, and the fraction of
    the variance of r0 = r + contribution each removes (``timing_estimated_explained``,
    ``pass_bias_estimated_explained``; 0 when not estimated). ``params``: the run's parameters table
    (name, kind, estimate, sigma; SI)."""
    st = g["station"].iloc[0]
    out = {"timing_estimated_ms": np.nan, "timing_estimated_sigma_ms": np.nan,
           "timing_estimated_explained": 0.0, "pass_bias_estimated_explained": 0.0,
           "timing_estimated_significant": False, "pass_bias_estimated_significant": False}
    if params is None or not len(params):
        return out
    r = g["r"].to_numpy()
    terms = {}
    timing = params[(params["kind"] == "timing") & (params["name"] == f"timing.{st}")]
    if len(timing):
        dt = float(timing["estimate"].iloc[0])
        out["timing_estimated_ms"], out["timing_estimated_sigma_ms"] = dt * 1e3, float(timing["sigma"].iloc[0]) * 1e3
        terms["timing"] = np.nan_to_num(-g["acc"].to_numpy() * dt)
        out["timing_estimated_significant"] = _significant(timing)
    bias = params[params["kind"] == "bias"].set_index("name")
    names = [f"bias.{observable}.{st}.pass{p}" for p in g["pass_id"].to_numpy()]
    if any(n in bias.index for n in names):
        terms["pass_bias"] = bias["estimate"].reindex(names).fillna(0.0).to_numpy()
        out["pass_bias_estimated_significant"] = _significant(bias.loc[bias.index.intersection(set(names))])
    for name, c in terms.items():
        ss0 = float(np.sum((r + c) ** 2))
        out[f"{name}_estimated_explained"] = 1.0 - float(r @ r) / ss0 if ss0 > 0 else 0.0
    return out


def _significant(p: pd.DataFrame, p_false: float = 0.01) -> bool:
    """Whether estimates ``p`` (estimate, sigma) differ from zero: chi-square test at ``p_false``."""
    return bool(np.sum((p["estimate"] / p["sigma"]) ** 2) > chdtri(len(p), p_false))


def diagnose(rows: pd.DataFrame, min_explained: float = 0.5, min_z: float = 6.0, factor: float = FACTOR,
             max_rms: float = MAX_RMS, params: pd.DataFrame | None = None) -> pd.DataFrame:
    """One line per station: RMS (mm/s), whether it stands out, each signature's explained fraction, the
    estimated timing offset (ms) and troposphere scale, the worst ramp segment's offset (mm/s) and z, what
    the fit's own time-offset and pass-bias parameters took (:func:`estimated_terms`, from ``params``), and
    the likely cause by the module's rules (``none``: smooth residuals, field-like). ``rows``: :func:`rows_used`."""
    lines = []
    if not len(rows):
        return pd.DataFrame(columns=["station", "rows", "passes", "rms_mm_s", "stands_out", "likely_cause"])
    for st, g in rows.groupby("station"):
        line = {"station": st, "rows": len(g), "passes": g["pass_id"].nunique(),
                "rms_mm_s": float(np.sqrt(np.mean(g["r"] ** 2)) * 1e3)}
        fits = {s: signature_fit(g, s) for s in SIGNATURES}
        for s, f in fits.items():
            line[f"{s}_explained"] = f["explained"]
        line["timing_offset_ms"] = float(fits["timing"]["params"][0] * 1e3)
        line["troposphere_scale"] = float(fits["troposphere"]["params"][0])
        seg = segment_offsets(g)
        worst = seg.iloc[int(np.argmax(np.abs(seg["z"])))] if len(seg) else None
        line["worst_segment"] = int(worst["segment"]) if worst is not None else -1
        line["segment_offset_mm_s"] = float(worst["offset"] * 1e3) if worst is not None else np.nan
        line["segment_z"] = float(worst["z"]) if worst is not None else np.nan
        est = estimated_terms(g, params)
        line.update(est)
        best = max(SIGNATURES, key=lambda s: fits[s]["explained"])
        took = max(("timing", "pass_bias"), key=lambda s: est[f"{s}_estimated_explained"]
                   * est[f"{s}_estimated_significant"])
        if est[f"{took}_estimated_significant"] and est[f"{took}_estimated_explained"] >= min_explained:
            line["likely_cause"] = f"{took}_estimated"
        elif worst is not None and abs(worst["z"]) >= min_z:
            line["likely_cause"] = "ramp_segment"
        elif fits[best]["explained"] >= min_explained:
            line["likely_cause"] = best
        else:
            line["likely_cause"] = "none"
        lines.append(line)
    table = pd.DataFrame(lines)
    median = table["rms_mm_s"].median()
    table.insert(4, "stands_out", (table["rms_mm_s"] > factor * median) | (table["rms_mm_s"] > max_rms * 1e3))
    return table


CAUSES = {"timing": "a time-tag offset", "troposphere": "a troposphere (low-elevation) error",
          "pass_bias": "a per-pass bias", "ramp_segment": "a bad ramp segment",
          "timing_estimated": "a time-tag offset, estimated by the fit",
          "pass_bias_estimated": "per-pass biases, estimated by the fit",
          "none": "none found: smooth, field-like residuals"}


def summary(table: pd.DataFrame, factor: float = FACTOR, max_rms: float = MAX_RMS) -> str:
    """One sentence per standing-out station (or that none stands out) for a report, saying which of
    :func:`diagnose`'s rules (``factor`` times the median, ``max_rms`` in m/s) it exceeds; an empty table (no
    two-way Doppler fitted) says so."""
    if not len(table):
        return "No two-way Doppler fitted in this arc: nothing to diagnose."
    out = table[table["stands_out"].astype(bool)]
    taken = table[table["likely_cause"].str.endswith("_estimated") & ~table["stands_out"].astype(bool)]
    said = " ".join(f"{r.station}'s residuals were explained by {CAUSES[r.likely_cause]}." for r in taken.itertuples())
    if not len(out):
        return " ".join(["No station stands out.", said]).strip()
    median = table["rms_mm_s"].median()

    def why(rms: float) -> str:
        ratio = f"{rms / median:.1f} times the stations' median"
        return ratio if rms > factor * median else f"above {max_rms * 1e3:g} mm/s; {ratio}"
    return said + (" " if said else "") + " ".join(f"{r.station} stands out ({r.rms_mm_s:.2f} mm/s, {why(r.rms_mm_s)}); "
                                                   f"likely cause: {CAUSES[r.likely_cause]}." for r in out.itertuples())


# the likely cause in a report table's cell: short, the summary above the table says it in full (CAUSES)
SHORT = {"timing": "time-tag offset", "troposphere": "troposphere", "pass_bias": "per-pass bias",
         "ramp_segment": "bad ramp segment", "timing_estimated": "time offset (estimated)",
         "pass_bias_estimated": "pass biases (estimated)", "none": "none (smooth)"}


def _plus_minus(value_ms, sigma_ms) -> list:
    """"estimate ± sigma" (ms, 0.1 ms) per row; NaN where nothing was estimated."""
    return [f"{v:.1f} ± {s:.1f}" if np.isfinite(v) else np.nan
            for v, s in zip(np.asarray(value_ms, float), np.asarray(sigma_ms, float))]


def report_table(table: pd.DataFrame) -> tuple[pd.DataFrame, dict]:
    """(table, formats) of a :func:`diagnose` table for a report, with units in the headers: the RMS against
    the stations' median, explained fractions in %, time offsets in ms (the estimated one with its sigma),
    the ramp-segment z in sigmas, and the likely cause as a short ``reason`` (:data:`SHORT`); narrow enough
    for the report's page."""
    n = len(table)
    shown = pd.DataFrame({"station_rx": table["station"], "rows": table["rows"], "RMS (mm/s)": table["rms_mm_s"],
                          "RMS / median (1)": table["rms_mm_s"] / table["rms_mm_s"].median()})
    for col, name in (("timing_explained", "timing"), ("troposphere_explained", "troposphere"),
                      ("pass_bias_explained", "pass bias")):
        shown[f"{name}: explained (%)"] = 100.0 * table.get(col, np.nan)
    shown["timing offset (ms)"] = table.get("timing_offset_ms", np.nan)
    shown["estimated time offset (ms)"] = _plus_minus(table.get("timing_estimated_ms", np.full(n, np.nan)),
                                                      table.get("timing_estimated_sigma_ms", np.full(n, np.nan)))
    shown["estimated offset: explained (%)"] = 100.0 * table.get("timing_estimated_explained", np.nan)
    shown["estimated pass biases: explained (%)"] = 100.0 * table.get("pass_bias_estimated_explained", np.nan)
    shown["worst ramp segment (mm/s)"] = table.get("segment_offset_mm_s", np.nan)
    shown["its offset (sigma)"] = table.get("segment_z", np.nan)
    shown["reason"] = table["likely_cause"].map(SHORT)
    fmt = {c: "{:.0f}" for c in shown.columns if c.endswith("(%)")}
    return shown, fmt | {"RMS (mm/s)": "{:.2f}", "RMS / median (1)": "{:.1f}", "timing offset (ms)": "{:.1f}",
                         "worst ramp segment (mm/s)": "{:.2f}", "its offset (sigma)": "{:.1f}"}
