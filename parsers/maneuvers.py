"""Maneuver files: odpipe's planned-maneuver schema (CSV or TOML) and the GRAIL maneuver log.

Planned maneuvers (``read_plan`` / ``write_plan``), one row each:

========== ======= ===========================================================
column     unit    meaning
========== ======= ===========================================================
name       --      label, e.g. ``TCM-3``
epoch      UTC     impulse time, or start of a finite burn (ISO 8601)
kind       --      ``impulsive`` or ``finite``
frame      --      ``ICRF``, ``RTN`` (radial, transverse, normal) or ``VNB``
                   (velocity, normal, binormal) - frame of dv / direction
dv1..dv3   m/s     impulsive delta-V components in ``frame`` (finite: empty)
duration   s       finite burn length (impulsive: empty)
thrust     N       finite burn thrust magnitude
dir1..dir3 --      finite burn thrust direction in ``frame`` (unit vector)
mass       kg      spacecraft mass at burn start (finite burns)
sigma_dv   m/s     a priori 1-sigma per delta-V component (finite: of dv = thrust/mass*duration)
sigma_time s       a priori 1-sigma of the epoch
========== ======= ===========================================================

CSV: a header line with these names (any order, ``#`` comment lines allowed).
TOML: one ``[[maneuver]]`` table per row with the same keys, ``dv`` and
``direction`` as 3-element arrays and ``epoch`` a TOML datetime or ISO string.

The GRAIL maneuver log (``read_mas``, e.g. ``mas00_2012_04_06_a_04.asc``) is a
text table, fields separated by three or more spaces, whose header has quoted
names spanning two lines. Its ``DOY`` column (``YY-DDD``) with the SCET time
gives the UTC epoch; its ``Date`` column is mostly the US Pacific calendar day
and is kept as given, with ``date_mismatch`` set where it is neither the UTC
nor the Pacific day of the epoch. ΔV magnitudes are read from event names
such as ``TCM-A2 (13.973 m/sec)``.
"""

from __future__ import annotations

import csv
import io
import re
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

from parsers.atomic import write_text
from parsers.errors import ParseError, ParseReport, handle

PLAN_COLUMNS = ["name", "epoch", "kind", "frame", "dv1", "dv2", "dv3", "duration", "thrust",
                "dir1", "dir2", "dir3", "mass", "sigma_dv", "sigma_time"]
KINDS = ("impulsive", "finite")
FRAMES = ("ICRF", "RTN", "VNB")
_NUMERIC = PLAN_COLUMNS[4:]
_NEEDED = {"impulsive": ["dv1", "dv2", "dv3"], "finite": ["duration", "thrust", "dir1", "dir2", "dir3"]}

MAS_COLUMNS = ["event", "date", "doy", "time", "fuel_kg", "fuel_sigma_2s_kg", "mass_kg",
               "cm_x", "cm_y", "cm_z", "boresight_x", "boresight_y", "boresight_z"]
MAS_HEADER = ["Event", "Date", "DOY", "Maneuver End Time (SCET)", "Fuel Mass Remaining Book Keeping (kg)",
              "Book Keeping Uncertainty-2s (kg)", "Post Maneuver Spacecraft Mass", "Post Maneuver CM X",
              "Post Maneuver CM Y", "Post Maneuver CM Z", "Post Maneuver Boresight Vec X",
              "Post Maneuver Boresight Vec Y", "Post Maneuver Boresight Vec Z"]
_SEP = re.compile(r" {3,}|\t")
_DV = re.compile(r"\(([-+0-9.]+)\s*m/s(?:ec)?\)")


def sniff(head: bytes) -> bool:
    """True for a GRAIL maneuver log, a plan CSV (header starting ``name,epoch``) or a plan TOML."""
    text = head.decode("latin-1")
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    first = lines[0] if lines else ""
    return (first.startswith("Event") and "Maneuver End Time" in first) or \
        first.replace(" ", "").lower().startswith("name,epoch") or "[[maneuver]]" in text


def read(path, errors: str = "raise", report: ParseReport | None = None) -> pd.DataFrame:
    """Read any maneuver file this module knows (dispatch on its first bytes)."""
    head = Path(path).read_bytes()[:4096].decode("latin-1")
    if head.startswith("Event"):
        return read_mas(path, errors, report)
    return read_plan(path, errors, report)


# ---------------------------------------------------------------- planned maneuvers

def _check_plan(rows: list[dict], where: list[dict], path, errors, report) -> pd.DataFrame:
    good = []
    for row, loc in zip(rows, where):
        try:
            good.append(_plan_row(row))
        except (ValueError, TypeError) as exc:
            handle(ParseError(path, str(exc), **loc), errors, report)
    df = pd.DataFrame(good, columns=PLAN_COLUMNS)
    df["epoch"] = pd.to_datetime(df["epoch"]).astype("datetime64[ns]")
    for c in _NUMERIC:
        df[c] = df[c].astype(float)
    return df


def _plan_row(row: dict) -> dict:
    unknown = set(row) - set(PLAN_COLUMNS)
    if unknown:
        raise ValueError(f"unknown field(s) {sorted(unknown)}")
    out = {c: row.get(c) for c in PLAN_COLUMNS}
    if not out["name"]:
        raise ValueError("missing name")
    ts = pd.Timestamp(out["epoch"])
    if ts.tzinfo is not None:
        ts = ts.tz_convert("UTC").tz_localize(None)
    out["epoch"] = ts.to_datetime64()
    if out["kind"] not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, not {out['kind']!r}")
    if out["frame"] not in FRAMES:
        raise ValueError(f"frame must be one of {FRAMES}, not {out['frame']!r}")
    for c in _NUMERIC:
        v = out[c]
        out[c] = np.nan if v is None or v == "" else float(v)
    missing = [c for c in _NEEDED[out["kind"]] if np.isnan(out[c])]
    if missing:
        raise ValueError(f"{out['kind']} maneuver needs {missing}")
    if out["kind"] == "finite":
        norm = np.hypot.reduce([out["dir1"], out["dir2"], out["dir3"]])
        if abs(norm - 1.0) > 1e-6:
            raise ValueError(f"thrust direction is not a unit vector (norm {norm:.9f})")
    return out


def read_plan(path, errors: str = "raise", report: ParseReport | None = None) -> pd.DataFrame:
    """Planned maneuvers from CSV or TOML (by content); columns PLAN_COLUMNS, epoch UTC.

    With ``errors='report'`` bad rows are skipped and added to ``report``.
    """
    text = Path(path).read_text()
    if "[[maneuver]]" in text:
        try:
            doc = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ParseError(path, f"TOML: {exc}") from exc
        rows = []
        for m in doc.get("maneuver", []):
            m = dict(m)
            for key, cols in (("dv", ("dv1", "dv2", "dv3")), ("direction", ("dir1", "dir2", "dir3"))):
                if key in m:
                    vec = m.pop(key)
                    if len(vec) != 3:
                        vec = [None, None, None]
                    m.update(dict(zip(cols, vec)))
            rows.append(m)
        where = [{"record": i} for i in range(len(rows))]
    else:
        lines = [(n, ln) for n, ln in enumerate(text.splitlines(), 1) if ln.strip() and not ln.startswith("#")]
        if not lines:
            raise ParseError(path, "no header line")
        reader = csv.DictReader(io.StringIO("\n".join(ln for _, ln in lines)), skipinitialspace=True)
        rows, where = [], []
        for i, row in enumerate(reader):
            if None in row or None in row.values():
                handle(ParseError(path, "wrong number of fields", line=lines[i + 1][0], record=i), errors, report)
                continue
            rows.append({k.strip(): v.strip() for k, v in row.items()})
            where.append({"line": lines[i + 1][0], "record": i})
    return _check_plan(rows, where, path, errors, report)


def _fmt(v) -> str:
    return "" if isinstance(v, float) and np.isnan(v) else repr(float(v)) if isinstance(v, float) else str(v)


def write_plan(plan: pd.DataFrame, path) -> None:
    """Write planned maneuvers as CSV or TOML (by the file suffix), losslessly."""
    path = Path(path)
    rows = plan[PLAN_COLUMNS].copy()
    iso = pd.to_datetime(rows["epoch"]).dt.strftime("%Y-%m-%dT%H:%M:%S.%f")
    if path.suffix.lower() == ".toml":
        parts = []
        for (_, r), t in zip(rows.iterrows(), iso):
            parts.append("[[maneuver]]")
            parts.append(f'name = "{r["name"]}"\nepoch = {t}Z\nkind = "{r["kind"]}"\nframe = "{r["frame"]}"')
            vecs = {"dv": ("dv1", "dv2", "dv3"), "direction": ("dir1", "dir2", "dir3")}
            for key, cols in vecs.items():
                if not np.isnan(r[list(cols)].astype(float)).any():
                    parts.append(f"{key} = [{', '.join(repr(float(r[c])) for c in cols)}]")
            for c in ("duration", "thrust", "mass", "sigma_dv", "sigma_time"):
                if not np.isnan(r[c]):
                    parts.append(f"{c} = {float(r[c])!r}")
            parts.append("")
        text = "\n".join(parts)
    else:
        lines = [",".join(PLAN_COLUMNS)]
        for (_, r), t in zip(rows.iterrows(), iso):
            lines.append(",".join([str(r["name"]), t] + [_fmt(r[c]) for c in PLAN_COLUMNS[2:]]))
        text = "\n".join(lines) + "\n"
    write_text(path, text)


# ---------------------------------------------------------------- GRAIL maneuver log

def _mas_header(lines: list[str], path) -> int:
    """Check the (multi-line, quoted) header; return the number of lines it spans."""
    n, quotes = 0, 0
    while n < len(lines):
        quotes += lines[n].count('"')
        n += 1
        if quotes % 2 == 0:
            break
    names = [f.strip().strip('"').replace("\n", " ") for f in _SEP.split("\n".join(lines[:n]).strip())]
    names = [re.sub(r"\s+", " ", x) for x in names]
    if names != MAS_HEADER:
        raise ParseError(path, f"unexpected header {names}", line=1)
    return n


def read_mas(path, errors: str = "raise", report: ParseReport | None = None) -> pd.DataFrame:
    """GRAIL maneuver/desaturation log: one row per event, columns described in the module doc.

    Numbers: masses kg, centre-of-mass coordinates as given (m), boresight unit
    vector; ``epoch`` UTC from DOY + SCET time; ``dv_mps`` (m/s) from the event
    name; ``line`` is the 1-based line number in the file. With ``errors='report'``
    unreadable lines are skipped and added to ``report``.
    """
    lines = Path(path).read_text().splitlines()
    start = _mas_header(lines, path)
    rows = []
    for ln, text in enumerate(lines[start:], start + 1):
        if not text.strip():
            continue
        fields = [f.strip() for f in _SEP.split(text.strip())]
        if len(fields) < 7 or len(fields) > len(MAS_COLUMNS):
            handle(ParseError(path, f"{len(fields)} fields", line=ln), errors, report)
            continue
        fields += [""] * (len(MAS_COLUMNS) - len(fields))
        rows.append(fields + [ln])
    df = pd.DataFrame(rows, columns=MAS_COLUMNS + ["line"])
    for c in MAS_COLUMNS[4:]:
        df[c] = pd.to_numeric(df[c].replace("", np.nan), errors="coerce")
    yy_doy = df["doy"].str.extract(r"^(\d{2})-(\d{3})$").astype(float)
    bad = yy_doy.isna().any(axis=1) | pd.to_timedelta(df["time"], errors="coerce").isna()
    for i in np.flatnonzero(bad.to_numpy()):
        handle(ParseError(path, f"bad DOY/time {df['doy'].iat[i]!r} {df['time'].iat[i]!r}",
                          line=int(df["line"].iat[i])), errors, report)
    df = df[~bad.to_numpy()].reset_index(drop=True)
    yy_doy = yy_doy[~bad.to_numpy()].reset_index(drop=True)
    year0 = pd.to_datetime((2000 + yy_doy[0]).astype(int).astype(str), format="%Y")
    df.insert(0, "epoch", (year0 + pd.to_timedelta(yy_doy[1] - 1, unit="D")
                           + pd.to_timedelta(df["time"])).astype("datetime64[ns]"))
    given = pd.to_datetime(df["date"], format="%m/%d/%Y", errors="coerce")
    days = [(df["epoch"] - pd.Timedelta(hours=h)).dt.normalize() for h in (0, 7, 8)]
    df["date_mismatch"] = ~np.logical_or.reduce([given == d for d in days])
    df["dv_mps"] = pd.to_numeric(df["event"].str.extract(_DV)[0], errors="coerce")
    df["kind"] = np.where(df["event"].str.contains(r"\bDesat\b"), "desat",
                          np.where(df["dv_mps"].notna(), "maneuver", "event"))
    return df
