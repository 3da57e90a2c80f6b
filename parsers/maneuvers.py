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
import datetime
import re
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

from parsers.atomic import write_text
from parsers.errors import ParseError, ParseReport, check_mode, finite, handle, integer, read_text

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

_POSITIVE = ("duration", "thrust", "mass")
_NON_NEGATIVE = ("sigma_dv", "sigma_time")
_ISO = re.compile(r"\d{4}-\d{2}-\d{2}([T ]\d{2}:\d{2}(:\d{2}(\.\d{1,9})?)?)?(Z|[+-]\d{2}:?\d{2})?", re.ASCII)


def _check_plan(rows: list[dict], where: list[dict], path, errors, report) -> pd.DataFrame:
    good = []
    for row, loc in zip(rows, where):
        try:
            good.append(_plan_row(row, path, loc))
        except ParseError as err:
            handle(err, errors, report)
    df = pd.DataFrame(good, columns=PLAN_COLUMNS)
    df["epoch"] = pd.to_datetime(df["epoch"]).astype("datetime64[ns]")
    for c in _NUMERIC:
        df[c] = df[c].astype(float)
    return df


def _plan_epoch(value, path, loc) -> np.datetime64:
    """UTC datetime64[ns] of an ISO 8601 string or a TOML datetime; ParseError for anything else."""
    if isinstance(value, str) and not _ISO.fullmatch(value.strip()):
        raise ParseError(path, f"epoch {value[:40]!r} is not an ISO 8601 UTC time", **loc)
    if not isinstance(value, (str, datetime.datetime)):
        raise ParseError(path, f"epoch must be an ISO 8601 time, not {type(value).__name__} {str(value)[:40]!r}",
                         **loc)
    try:
        ts = pd.Timestamp(value)
        if ts.tzinfo is not None:
            ts = ts.tz_convert("UTC").tz_localize(None)
        return ts.as_unit("ns").to_datetime64()  # raises beyond 1677-2262 (e.g. year 0)
    except (ValueError, OverflowError) as exc:  # pandas' OutOfBoundsDatetime is a ValueError
        raise ParseError(path, f"epoch {str(value)[:40]!r}: {exc}", **loc) from None


def _plan_number(value, path, name, loc) -> float:
    if value is None or (isinstance(value, str) and not value.strip()):
        return np.nan
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise ParseError(path, f"{name} must be a number, not {type(value).__name__}", **loc)
    if isinstance(value, int) and abs(value) > 10**18:
        raise ParseError(path, f"{name} = {str(value)[:20]}... is not a plausible number", **loc)
    return finite(str(value), path, name, **loc)


def _plan_row(row: dict, path, loc: dict) -> dict:
    unknown = set(row) - set(PLAN_COLUMNS)
    if unknown:
        raise ParseError(path, f"unknown field(s) {sorted(map(str, unknown))[:5]}", **loc)
    out = {c: row.get(c) for c in PLAN_COLUMNS}
    if not isinstance(out["name"], str) or not out["name"].strip():
        raise ParseError(path, "missing name", **loc)
    if out["epoch"] is None or out["epoch"] == "":
        raise ParseError(path, "missing epoch", **loc)
    out["epoch"] = _plan_epoch(out["epoch"], path, loc)
    for key, choices in (("kind", KINDS), ("frame", FRAMES)):
        if not isinstance(out[key], str) or out[key] not in choices:
            raise ParseError(path, f"{key} must be one of {choices}, not {str(out[key])[:40]!r}", **loc)
    for c in _NUMERIC:
        out[c] = _plan_number(out[c], path, c, loc)
    missing = [c for c in _NEEDED[out["kind"]] if np.isnan(out[c])]
    if missing:
        raise ParseError(path, f"{out['kind']} maneuver needs {missing}", **loc)
    bad = [c for c in _POSITIVE if out[c] <= 0] + [c for c in _NON_NEGATIVE if out[c] < 0]
    if bad:
        raise ParseError(path, f"{bad} must be positive", **loc)
    if out["kind"] == "finite":
        norm = np.hypot.reduce([out["dir1"], out["dir2"], out["dir3"]])
        if abs(norm - 1.0) > 1e-6:
            raise ParseError(path, f"thrust direction is not a unit vector (norm {norm:.9f})", **loc)
    return out


def read_plan(path, errors: str = "raise", report: ParseReport | None = None) -> pd.DataFrame:
    """Planned maneuvers from CSV or TOML (by content); columns PLAN_COLUMNS, epoch UTC.

    With ``errors='report'`` bad rows are skipped and added to ``report``; a file that is
    empty, not UTF-8, not TOML or without a CSV header raises in both modes.
    """
    check_mode(errors)
    text = read_text(path)
    if "[[maneuver]]" in text:
        rows, where = _toml_rows(text, path)
    else:
        rows, where = _csv_rows(text, path, errors, report)
    return _check_plan(rows, where, path, errors, report)


def _toml_rows(text: str, path) -> tuple[list, list]:
    try:
        doc = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, ValueError, RecursionError) as exc:  # ValueError: e.g. a 5000-digit integer
        at = re.search(r"at line (\d+)", str(exc))
        raise ParseError(path, f"TOML: {str(exc)[:200]}",
                         line=int(at[1]) if at else text.count("\n") + 1) from None
    if set(doc) != {"maneuver"} or not isinstance(doc["maneuver"], list):
        raise ParseError(path, f"a plan holds only [[maneuver]] tables, not {sorted(doc)[:5]}")
    rows = []
    for m in doc["maneuver"]:
        m = dict(m) if isinstance(m, dict) else {"?": m}
        for key, cols in (("dv", ("dv1", "dv2", "dv3")), ("direction", ("dir1", "dir2", "dir3"))):
            if key in m:
                vec = m.pop(key)
                m.update(dict(zip(cols, vec)) if isinstance(vec, list) and len(vec) == 3 else {f"{key} (3 numbers)": vec})
        rows.append(m)
    starts = [n for n, ln in enumerate(text.splitlines(), 1) if ln.strip() == "[[maneuver]]"]
    if len(starts) != len(rows):  # tables written another way: no line to name
        starts = [None] * len(rows)
    return rows, [{"line": n, "record": i} for i, n in enumerate(starts)]


def _csv_rows(text: str, path, errors, report) -> tuple[list, list]:
    lines = [(n, ln) for n, ln in enumerate(text.splitlines(), 1) if ln.strip() and not ln.startswith("#")]
    if not lines:
        raise ParseError(path, "no header line")
    header = _csv_fields(lines[0][1], path, lines[0][0])
    if not {"name", "epoch", "kind", "frame"} <= set(header) or len(set(header)) != len(header):
        raise ParseError(path, f"CSV header needs name, epoch, kind, frame once each, got {header[:20]}",
                         line=lines[0][0])
    rows, where = [], []
    for i, (n, ln) in enumerate(lines[1:]):
        try:
            fields = _csv_fields(ln, path, n)
            if len(fields) != len(header):
                raise ParseError(path, f"{len(fields)} fields, header has {len(header)}", line=n, record=i)
        except ParseError as err:
            err.record = i
            handle(err, errors, report)
            continue
        rows.append(dict(zip(header, fields)))
        where.append({"line": n, "record": i})
    return rows, where


def _csv_fields(line: str, path, n: int) -> list[str]:
    try:
        return [f.strip() for f in next(csv.reader([line], skipinitialspace=True))]
    except csv.Error as exc:  # e.g. a field over the csv module's limit, a NUL byte
        raise ParseError(path, f"CSV: {exc}", line=n) from None


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
    check_mode(errors)
    lines = read_text(path).splitlines()
    start = _mas_header(lines, path)
    rows = []
    for ln, text in enumerate(lines[start:], start + 1):
        if not text.strip():
            continue
        try:
            rows.append(_mas_row(text, path, ln, len(rows)))
        except ParseError as err:
            handle(err, errors, report)
    df = pd.DataFrame(rows, columns=["epoch"] + MAS_COLUMNS + ["line"])
    df["epoch"] = df["epoch"].astype("datetime64[ns]")
    for c in MAS_COLUMNS[4:]:
        df[c] = df[c].astype(float)
    df["line"] = df["line"].astype(np.int64)
    given = pd.to_datetime(df["date"], format="%m/%d/%Y", errors="coerce")
    days = [(df["epoch"] - pd.Timedelta(hours=h)).dt.normalize() for h in (0, 7, 8)]
    df["date_mismatch"] = ~np.logical_or.reduce([given == d for d in days]) if len(df) else np.zeros(0, bool)
    df["dv_mps"] = pd.to_numeric(df["event"].str.extract(_DV)[0], errors="coerce").astype(float)
    df["kind"] = np.where(df["event"].str.contains(r"\bDesat\b"), "desat",
                          np.where(df["dv_mps"].notna(), "maneuver", "event"))
    return df


_DOY = re.compile(r"(\d{2})-(\d{3})", re.ASCII)
_SCET = re.compile(r"(\d{2}):(\d{2}):(\d{2}(?:\.\d{1,9})?)", re.ASCII)


def _mas_row(text: str, path, ln: int, record: int) -> list:
    """[epoch, fields..., line] of one log line; ParseError for a line that is not an event."""
    loc = {"line": ln, "record": record}
    fields = [f.strip() for f in _SEP.split(text.strip())]
    if len(fields) < 7 or len(fields) > len(MAS_COLUMNS):
        raise ParseError(path, f"{len(fields)} fields (want 7 to {len(MAS_COLUMNS)})", **loc)
    fields += [""] * (len(MAS_COLUMNS) - len(fields))
    doy, scet = _DOY.fullmatch(fields[2]), _SCET.fullmatch(fields[3])
    if not doy or not scet:
        raise ParseError(path, f"bad DOY/time {fields[2][:20]!r} {fields[3][:20]!r} (want YY-DDD HH:MM:SS.fff)", **loc)
    year = 2000 + int(doy[1])
    day = integer(doy[2], path, "day of year", 1, 366 if year % 4 == 0 else 365, **loc)
    hh = integer(scet[1], path, "hour", 0, 23, **loc)
    mm = integer(scet[2], path, "minute", 0, 59, **loc)
    ss = finite(scet[3], path, "second", **loc)
    if ss >= 61:
        raise ParseError(path, f"second {ss} is out of range", **loc)
    epoch = (np.datetime64(f"{year}-01-01", "ns") + np.timedelta64(day - 1, "D")
             + np.timedelta64((hh * 60 + mm) * 60, "s") + np.timedelta64(round(ss * 1e9), "ns"))
    numbers = [np.nan if not f else finite(f, path, name, **loc) for f, name in zip(fields[4:], MAS_COLUMNS[4:])]
    return [epoch] + fields[:4] + numbers + [ln]
