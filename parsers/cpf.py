"""Reader of ILRS Consolidated Prediction Format (CPF) ephemerides, v1 and v2 (``.sgf``, ``.hts``, ``.cpf``, ...).

Records (type first, blank-separated): ``H1`` (``CPF``, version, ephemeris
source, production year month day hour, sequence number, v2 sub-daily
sequence, target name), ``H2`` (ILRS id, SIC, NORAD id, start and end
year month day hour minute second, seconds between entries, compatibility
with TIVs, target class, reference frame, rotation angle type, centre-of-mass
correction, v2 target location), ``H3``-``H5`` (accuracy, transponder,
centre-of-mass offset; kept as text), ``H9`` end of header, ``00`` comment,
``10`` position (direction flag, MJD, seconds of day UTC, leap second flag,
x y z m), ``20`` velocity (direction flag, vx vy vz m/s) and ``30``
corrections (direction flag, aberration x y z m, relativistic range
correction ns) of the preceding ``10``, ``40``/``50``/``60``/``70`` (kept
as text) and ``99`` end of ephemeris.

Reference frame (H2): 0 geocentric true body-fixed, i.e. ITRF (the default and
the Lageos2 files'), 1 geocentric true-of-date inertial, 2 geocentric mean of
J2000 (EME2000); :attr:`Cpf.frame` names it. Positions are of the centre of
mass unless H2's centre-of-mass correction flag is 1 (then of the retroreflector
array). Epochs are UTC datetime64[ns] (MJD + seconds of day, exact to the ns).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.constants import MJD_ORIGIN, NS_PER_DAY
from parsers.errors import ParseError, ParseReport, check_mode, handle
from parsers.fields import Fields, numbered_lines, date_ns

FRAMES = {0: "ITRF", 1: "TOD", 2: "EME2000"}


@dataclass
class Cpf:
    """A CPF ephemeris: header fields, one row per ``10`` record, the frame of its positions."""

    path: str
    header: dict
    positions: pd.DataFrame  # epoch (UTC), mjd, sod_s, leap, direction, x_m, y_m, z_m, vx/vy/vz (m/s, NaN), line
    comments: list[str] = field(default_factory=list)
    report: ParseReport = field(default_factory=ParseReport)

    @property
    def frame(self) -> str:
        """'ITRF', 'TOD' or 'EME2000' (H2 reference frame 0, 1, 2)."""
        return FRAMES[self.header["frame"]]


def sniff(head: bytes) -> bool:
    """True when the first non-blank line is an H1 record of format CPF."""
    first = next((ln for ln in head.decode("latin-1").splitlines() if ln.strip()), "")
    return first[:2].upper() == "H1" and [w.upper() for w in first[2:].split()[:1]] == ["CPF"]


def read(path, errors: str = "raise") -> Cpf:
    """Read a CPF file; bad ``10``/``20``/``30`` records are reported and skipped with errors="report"."""
    check_mode(errors)
    path = Path(path)
    report = ParseReport()
    header, rows, comments = {}, [], []
    ended = False
    for number, text in numbered_lines(path):
        if not text.strip():
            continue
        kind = text[:2].upper()
        f = Fields(path, number, text, record=kind)
        try:
            if ended:
                raise f.error("record after the 99 end-of-ephemeris record")
            if kind in ("H1", "H2"):
                header.update(_h1(f) if kind == "H1" else _h2(f))
            elif kind in ("H3", "H4", "H5"):
                header[kind] = " ".join(f.fields[1:])
            elif kind == "H9":
                header["ended"] = True
            elif kind == "00":
                comments.append(text[2:].strip())
            elif kind == "10":
                _need_header(f, header)
                rows.append(_position(f))
            elif kind in ("20", "30"):
                _attach(f, rows)
            elif kind in ("40", "50", "60", "70"):
                continue  # transponder, offset from the main body, rotation angle, Earth orientation
            elif kind == "99":
                ended = True
            else:
                raise f.error(f"unknown CPF record type {text[:2]!r} (expected H1-H5, H9, 00, 10, 20, 30-70 or 99)")
        except ParseError as err:
            handle(err, errors, report)
    if "frame" not in header:
        handle(ParseError(path, "no H1/H2 header records: not a CPF ephemeris"), errors, report)
    cols = ["epoch", "mjd", "sod_s", "leap", "direction", "x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps", "line"]
    positions = pd.DataFrame(rows, columns=cols)
    return Cpf(str(path), header, positions, comments, report)


def _h1(f: Fields) -> dict:
    f.need(10, "CPF, version, source, year, month, day, hour, sequence, target")
    if f.str(1).upper() != "CPF":
        raise f.error(f"H1 must name the format CPF, not {f.str(1)!r}")
    version = f.int(2, "format version")
    sub = 1 if version >= 2 else 0  # v2: sub-daily sequence number before the target name
    return {"version": version, "source": f.str(3), "produced": date_ns(_with_zero_time(f, 4), 4, "production"),
            "sequence": f.int(8, "ephemeris sequence"),
            "sub_daily": f.int(9, "sub-daily sequence") if sub else -1, "target": f.str(9 + sub)}


def _with_zero_time(f: Fields, i: int) -> Fields:
    """The production year month day hour followed by minute and second 0, for :func:`date_ns`."""
    return Fields(f.path, f.number, f.text, f.record, fields=f.fields[:i + 4] + ["0", "0"])


def _h2(f: Fields) -> dict:
    f.need(21, "ILRS id, SIC, NORAD, start and end date-times, interval, TIV, class, frame, rotation, CoM")
    out = {"ilrs_id": f.int(1, "ILRS id"), "sic": f.int(2, "SIC"), "norad": f.int(3, "NORAD id"),
           "start": date_ns(f, 4, "start"), "end": date_ns(f, 10, "end"), "interval_s": f.int(16, "interval"),
           "tiv_compatible": f.int(17, "TIV compatibility"), "target_class": f.int(18, "target class"),
           "frame": f.int(19, "reference frame"), "rotation_type": f.int(20, "rotation angle type"),
           "com_applied": f.int(21, "centre-of-mass correction", -1), "location": f.int(22, "target location", -1)}
    if out["frame"] not in FRAMES:
        raise f.error(f"reference frame {out['frame']} is not 0 (ITRF), 1 (true of date) or 2 (J2000)")
    return out


def _need_header(f: Fields, header: dict) -> None:
    if "frame" not in header:
        raise f.error("position record before the H2 header (its frame is unknown)")


def _position(f: Fields) -> list:
    f.need(8, "direction, MJD, seconds of day, leap second, x, y, z")
    mjd = f.int(2, "MJD")
    sod_ns = f.seconds_ns(3, "seconds of day")
    if sod_ns > NS_PER_DAY:
        raise f.error(f"seconds of day {f.str(3)} beyond 86400")
    epoch = MJD_ORIGIN + np.timedelta64(mjd * NS_PER_DAY + sod_ns, "ns")
    return [epoch, mjd, sod_ns / 1e9, f.int(4, "leap second"), f.int(1, "direction"),
            *(f.float(5 + k, f"{c} (m)") for k, c in enumerate("xyz")), np.nan, np.nan, np.nan, f.number]


def _attach(f: Fields, rows: list) -> None:
    """Velocity (20) into the preceding position record; corrections (30) are checked and not kept."""
    if not rows:
        raise f.error(f"{f.record} record before any 10 position record")
    f.need(5, "direction and three components")
    values = [f.float(2 + k, f"component {k + 1}") for k in range(3)]
    if f.record == "20":
        rows[-1][8:11] = values


def describe(path) -> list[str]:
    """Lines for ``odpipe inspect``: target, frame, span, step and what was unreadable."""
    c = read(path, errors="report")
    p, h = c.positions, c.header
    lines = [f"target: {h.get('target', '?')} (ILRS {h.get('ilrs_id', '?')}), source {h.get('source', '?')}, "
             f"CPF v{h.get('version', '?')}", f"frame: {c.frame if 'frame' in h else '?'}", f"positions: {len(p)}"]
    if len(p):
        steps = np.unique(np.diff(p["epoch"].to_numpy()).astype(np.int64) / 1e9)
        lines += [f"span: {p['epoch'].min()} .. {p['epoch'].max()} UTC",
                  "steps (s): " + ", ".join(f"{s:g}" for s in steps[:5]),
                  f"velocities: {int(p['vx_mps'].notna().sum())}"]
    return lines + [f"unreadable records: {len(c.report)}"] + [f"  {e}" for e in list(c.report)[:5]]
