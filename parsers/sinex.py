"""Reader of SINEX station solutions and eccentricity files (ILRS SLRF, ITRF; SINEX 2.0x).

A SINEX file opens with ``%=SNX`` and holds blocks ``+NAME`` ... ``-NAME`` of
fixed-column lines (``*`` starts a comment). Read here (columns 1-based):

- ``SITE/ID``: code 2-5, point 7-8, DOMES 10-18, observation technique 20,
  description 22-43, approximate east longitude 45-55 and latitude 57-67
  (deg min sec), approximate height 69-75 (m);
- ``SOLUTION/EPOCHS``: code, point, solution 10-13, technique 15, data start
  17-28, data end 30-41, mean epoch 43-54;
- ``SOLUTION/ESTIMATE``: index 2-6, type 8-13 (STAX/STAY/STAZ m, VELX/VELY/VELZ
  m/y, ...), code 15-18, point 20-21, solution 23-26, reference epoch 28-39,
  unit 41-44, constraint 46, value 48-68, standard deviation 70-80;
- ``SITE/ECCENTRICITY``: code, point, solution, technique, start 17-28, end
  30-41, reference system 43-45 (``UNE`` up/north/east or ``XYZ``), the three
  components 47-54, 56-63, 65-72 (m) from the marker to the instrument
  reference point.

A number may spill into the blank column before it (ILRS files write
``-51.5480-118.8670``): value columns are read from that blank column on.

Epochs ``YY:DDD:SSSSS`` (YY <= 50 -> 20YY; a four-digit year is read as is) are
UTC datetime64[ns]; ``00:000:00000`` (unspecified) is NaT.
:func:`stations` combines positions, velocities and reference epochs per
site and solution (ITRS of the file's frame, m and m/yr), and picks, when
given an epoch, the solution whose data span holds it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.constants import NS_PER_DAY, NS_PER_S, SECONDS_PER_DAY
from parsers.errors import ParseError, ParseReport, check_mode, handle
from parsers.fields import Fields, numbered_lines

# block -> [(column name, first col, last col (1-based, inclusive), kind)]; kind s text, f float, i int, e epoch
BLOCKS = {
    "SITE/ID": [("code", 2, 5, "s"), ("point", 7, 8, "s"), ("domes", 10, 18, "s"), ("technique", 20, 20, "s"),
                ("description", 22, 43, "s"), ("lon", 45, 55, "a"), ("lat", 57, 67, "a"),
                ("height_m", 69, 75, "f")],
    "SOLUTION/EPOCHS": [("code", 2, 5, "s"), ("point", 7, 8, "s"), ("soln", 10, 13, "s"), ("technique", 15, 15, "s"),
                        ("start", 17, 28, "e"), ("end", 30, 41, "e"), ("mean", 43, 54, "e")],
    "SOLUTION/ESTIMATE": [("index", 2, 6, "i"), ("type", 8, 13, "s"), ("code", 15, 18, "s"), ("point", 20, 21, "s"),
                          ("soln", 23, 26, "s"), ("ref_epoch", 28, 39, "e"), ("unit", 41, 44, "s"),
                          ("constraint", 46, 46, "s"), ("value", 47, 68, "f"), ("std", 69, 80, "f")],
    "SITE/ECCENTRICITY": [("code", 2, 5, "s"), ("point", 7, 8, "s"), ("soln", 10, 13, "s"),
                          ("technique", 15, 15, "s"), ("start", 17, 28, "e"), ("end", 30, 41, "e"),
                          ("system", 43, 45, "s"), ("e1", 46, 54, "f"), ("e2", 55, 63, "f"), ("e3", 64, 72, "f")],
}
ESTIMATE_TYPES = {"STAX": "x_m", "STAY": "y_m", "STAZ": "z_m", "VELX": "vx_m_per_yr", "VELY": "vy_m_per_yr",
                  "VELZ": "vz_m_per_yr"}


@dataclass
class Sinex:
    """The blocks of one SINEX file this reader knows, as DataFrames (empty when absent), and the header line."""

    path: str
    header: str
    blocks: dict[str, pd.DataFrame] = field(default_factory=dict)
    report: ParseReport = field(default_factory=ParseReport)

    def block(self, name: str) -> pd.DataFrame:
        columns = [c[0] + ("_deg" if c[3] == "a" else "") for c in BLOCKS[name]] + ["line"]
        return self.blocks.get(name, pd.DataFrame(columns=columns))

    @property
    def eccentricities(self) -> pd.DataFrame:
        """SITE/ECCENTRICITY with named components: up_m/north_m/east_m (UNE rows), x_m/y_m/z_m (XYZ rows)."""
        e = self.block("SITE/ECCENTRICITY").copy()
        une = e["system"] == "UNE"
        for names, mask in ((("up_m", "north_m", "east_m"), une), (("x_m", "y_m", "z_m"), ~une)):
            for name, col in zip(names, ("e1", "e2", "e3")):
                e[name] = e[col].where(mask)
        return e.drop(columns=["e1", "e2", "e3"])

    def eccentricity(self, code: str, at) -> pd.Series | None:
        """The eccentricity row of site ``code`` whose [start, end] holds UTC ``at`` (None if none)."""
        e = self.eccentricities
        return _holding(e[e["code"] == str(code)], np.datetime64(at, "ns"))

    def stations(self, at=None) -> pd.DataFrame:
        """One row per site and solution: x/y/z (m), vx/vy/vz (m/yr), ref_epoch, sigmas, data span, description.

        With ``at`` (UTC), only the solution of each site whose SOLUTION/EPOCHS
        span holds it (sites without one are left out).
        """
        est = self.block("SOLUTION/ESTIMATE")
        est = est[est["type"].isin(list(ESTIMATE_TYPES))]
        key = ["code", "point", "soln"]
        values = est.pivot_table(index=key, columns="type", values="value", aggfunc="first")
        sigmas = est.pivot_table(index=key, columns="type", values="std", aggfunc="first")
        out = values.rename(columns=ESTIMATE_TYPES)
        out = out.join(sigmas[[c for c in ("STAX", "STAY", "STAZ") if c in sigmas]].rename(
            columns=lambda c: "sigma_" + ESTIMATE_TYPES[c]))
        out["ref_epoch"] = est[est["type"] == "STAX"].set_index(key)["ref_epoch"].reindex(out.index)
        for col in ESTIMATE_TYPES.values():
            if col not in out:
                out[col] = 0.0 if col.startswith("v") else np.nan
        span = self.block("SOLUTION/EPOCHS").drop_duplicates(key).set_index(key)[["start", "end"]]
        out = out.join(span).reset_index()
        sites = self.block("SITE/ID").drop_duplicates(["code", "point"])[["code", "point", "domes", "description"]]
        out = out.merge(sites, on=["code", "point"], how="left")
        out[["x_m", "y_m", "z_m"]] = out[["x_m", "y_m", "z_m"]].astype(float)
        if at is not None:
            out = out[_holds(out, np.datetime64(at, "ns"))].drop_duplicates(["code", "point"], keep="last")
        return out.reset_index(drop=True)


def _holds(rows: pd.DataFrame, t: np.datetime64) -> pd.Series:
    """Mask of ``rows`` whose [start, end] holds ``t`` (NaT bounds are open)."""
    return (rows["start"].isna() | (rows["start"] <= t)) & (rows["end"].isna() | (t <= rows["end"]))


def _holding(rows: pd.DataFrame, t: np.datetime64):
    """The last of ``rows`` whose [start, end] holds ``t``, or None."""
    hit = rows[_holds(rows, t)]
    return hit.iloc[-1] if len(hit) else None


def sniff(head: bytes) -> bool:
    """True when the file starts with a SINEX header line (``%=SNX``)."""
    return head.lstrip(b"\xef\xbb\xbf").startswith(b"%=SNX")


def read(path, errors: str = "raise") -> Sinex:
    """Read the SINEX blocks listed in BLOCKS; other blocks are skipped."""
    check_mode(errors)
    path = Path(path)
    report = ParseReport()
    lines = [text for _, text in numbered_lines(path)]
    if not lines or not sniff(lines[0].encode("latin-1")):
        raise ParseError(path, "not a SINEX file (first line does not start with %=SNX)", line=1)
    rows: dict[str, list] = {}
    block = None
    for number, text in enumerate(lines, start=1):
        if text.startswith("+"):
            if block is not None:
                handle(ParseError(path, f"block +{text[1:].strip()} opened inside +{block}", line=number), errors,
                       report)
            block = text[1:].strip()
        elif text.startswith("-"):
            if text[1:].strip() != block:
                handle(ParseError(path, f"-{text[1:].strip()} closes no open block (open: {block})", line=number),
                       errors, report)
            block = None
        elif text.startswith("%ENDSNX"):
            break
        elif block in BLOCKS and text.strip() and not text.startswith("*"):
            try:
                rows.setdefault(block, []).append(_row(Fields(path, number, text, record=block, fields=[], fixed=True), block))
            except ParseError as err:
                handle(err, errors, report)
    else:
        handle(ParseError(path, "no %ENDSNX line: the file is truncated", line=len(lines)), errors, report)
    if block is not None:
        handle(ParseError(path, f"block +{block} is never closed", line=len(lines)), errors, report)
    return Sinex(str(path), lines[0], {name: pd.DataFrame(r) for name, r in rows.items()}, report)


def _row(f: Fields, block: str) -> dict:
    out = {}
    for name, first, last, kind in BLOCKS[block]:
        text = f.text[first - 1:last].strip()
        f.fields = [text]
        if kind == "s":
            out[name] = text
        elif kind == "i":
            out[name] = f.int(0, f"{name} (columns {first}-{last})")
        elif kind == "f":
            out[name] = f.float(0, f"{name} (columns {first}-{last})")
        elif kind == "e":
            out[name] = epoch(text, f, f"{name} (columns {first}-{last})")
        else:
            out[name + "_deg"] = _angle(text, f, f"{name} (columns {first}-{last})")
    out["line"] = f.number
    return out


def epoch(text: str, f: Fields, what: str) -> np.datetime64:
    """UTC datetime64[ns] of a SINEX epoch YY:DDD:SSSSS (or YYYY:DDD:SSSSS); NaT for 00:000:00000."""
    parts = text.split(":")
    if len(parts) != 3 or not all(p.isdigit() for p in parts):
        raise f.error(f"{what} must be YY:DDD:SSSSS, not {text!r}")
    yy, doy, sec = (int(p) for p in parts)
    if yy == doy == sec == 0:
        return np.datetime64("NaT", "ns")
    year = yy if len(parts[0]) == 4 else (2000 + yy if yy <= 50 else 1900 + yy)
    if not (doy <= 366 and sec <= SECONDS_PER_DAY):
        raise f.error(f"{what}: day {doy} or second {sec} out of range in {text!r}")
    jan1 = np.datetime64(f"{year:04d}-01-01", "ns")
    return jan1 + np.timedelta64((doy - 1) * NS_PER_DAY + sec * NS_PER_S, "ns")


def _angle(text: str, f: Fields, what: str) -> float:
    """Degrees from 'DDD MM SS.S' (a '-' anywhere makes it negative, as SINEX writes '-29 -2-47.3')."""
    parts = text.replace("-", " ").split()
    if len(parts) != 3:
        raise f.error(f"{what} must be degrees minutes seconds, not {text!r}")
    f.fields = parts
    d, m, s = (f.float(k, what) for k in range(3))
    return (-1.0 if "-" in text else 1.0) * (d + m / 60 + s / 3600)


def describe(path) -> list[str]:
    """Lines for ``odpipe inspect``: the header, blocks read and their sizes, unreadable lines."""
    s = read(path, errors="report")
    lines = [f"header: {s.header.strip()}"]
    lines += [f"{name}: {len(df)} lines" for name, df in s.blocks.items()]
    if "SOLUTION/ESTIMATE" in s.blocks:
        lines.append(f"stations with positions: {len(s.stations())} (site x solution)")
    return lines + [f"unreadable lines: {len(s.report)}"] + [f"  {e}" for e in list(s.report)[:5]]
