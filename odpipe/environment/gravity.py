"""Spherical-harmonic gravity fields and their file readers.

A :class:`GravityField` holds GM (m^3/s^2), the reference radius (m) and fully
normalized coefficients ``C[n, m]``, ``S[n, m]`` (4-pi normalization, geodesy
convention, no Condon-Shortley phase). :func:`read_gravity` reads

* ICGEM ``.gfc`` (1.0 and 2.0; Fortran ``D`` exponents; time-variable
  ``gfct``/``trnd``/``dot``/``acos``/``asin`` terms evaluated at ``epoch``,
  rejected when no epoch is given),
* GMAT ``.cof`` (``POTFIELD``/``RECOEF`` fixed-width records),
* PDS SHADR ``.tab`` (comma-separated, km and km^3/s^2),
* EGM format (Orekit ``egm96_to5``: ``n m C S sigC sigS``; GM and radius are
  not in the file and default to the EGM96 values),
* plain tables (first line ``GM R [source]``, then ``n m C S``; tudat style),

gzip-compressed or not. Malformed input raises :class:`parsers.ParseError`
naming the file and line.
"""

from __future__ import annotations

import gzip
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from odpipe.constants import DAYS_PER_JULIAN_YEAR, EGM96_GM, EGM96_RADIUS, SECONDS_PER_DAY
from parsers import ParseError


@dataclass
class GravityField:
    """Fully normalized spherical-harmonic field.

    ``C``, ``S``: (nmax+1, nmax+1) arrays indexed [n, m]; ``gm`` m^3/s^2;
    ``radius`` m; ``tide_system`` as the file states it ('tide_free',
    'zero_tide', 'unknown'); ``source`` the file; ``notes`` free text.
    """

    gm: float
    radius: float
    C: np.ndarray
    S: np.ndarray
    name: str = ""
    tide_system: str = "unknown"
    source: str = ""
    notes: list[str] = field(default_factory=list)

    @property
    def max_degree(self) -> int:
        return self.C.shape[0] - 1

    def truncated(self, nmax: int) -> "GravityField":
        """The same field cut to degree and order ``nmax``."""
        if nmax > self.max_degree:
            raise ValueError(f"{self.name}: degree {nmax} > max degree {self.max_degree}")
        return GravityField(self.gm, self.radius, self.C[: nmax + 1, : nmax + 1].copy(),
                            self.S[: nmax + 1, : nmax + 1].copy(), self.name,
                            self.tide_system, self.source, list(self.notes))

    def jn(self, n: int) -> float:
        """Unnormalized zonal J_n = -C_n0 * sqrt(2n+1)."""
        return -self.C[n, 0] * np.sqrt(2 * n + 1)


_FLOAT = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?"
_FLOAT_RE = re.compile(_FLOAT)


def _num(text: str, path, line: int) -> float:
    try:
        return float(text.replace("D", "E").replace("d", "e"))
    except ValueError:
        raise ParseError(path, f"not a number: {text!r}", line=line) from None


def _lines(path: Path) -> list[str]:
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt", encoding="latin-1") as f:
        return f.read().splitlines()


class _Coefficients:
    """Growing C/S store with the checks every format shares."""

    def __init__(self, path):
        self.path = path
        self.rows: dict[tuple[int, int], list[float]] = {}

    def add(self, n, m, c, s, line, accumulate=False):
        if n < 0 or m < 0 or m > n:
            raise ParseError(self.path, f"invalid degree/order n={n} m={m}", line=line)
        if m == 0 and s != 0.0:
            raise ParseError(self.path, f"S[{n},0] = {s} must be zero", line=line)
        if accumulate and (n, m) in self.rows:
            self.rows[(n, m)][0] += c
            self.rows[(n, m)][1] += s
        else:
            self.rows[(n, m)] = [c, s]

    def field(self, gm, radius, nmax=None, **kw) -> GravityField:
        if not self.rows:
            raise ParseError(self.path, "no coefficients found")
        top = max(n for n, _ in self.rows)
        nmax = top if nmax is None else nmax
        C = np.zeros((nmax + 1, nmax + 1))
        S = np.zeros((nmax + 1, nmax + 1))
        for (n, m), (c, s) in self.rows.items():
            if n <= nmax:
                C[n, m], S[n, m] = c, s
        C[0, 0] = 1.0
        return GravityField(float(gm), float(radius), C, S, source=str(self.path), **kw)


def _icgem_date_days(text: str, path, line: int) -> float:
    """ICGEM epoch 'yyyymmdd[.hhmm]' -> days past J2000 (civil, to the minute)."""
    value = _num(text, path, line)
    day = int(value)
    frac = round((value - day) * 1e4)
    y, mo, d = day // 10000, (day // 100) % 100, day % 100
    try:
        dt = np.datetime64(f"{y:04d}-{mo:02d}-{d:02d}")
    except ValueError:
        raise ParseError(path, f"bad ICGEM date {text!r}", line=line) from None
    days = (dt - np.datetime64("2000-01-01")).astype(float) - 0.5
    return days + (frac // 100) / 24.0 + (frac % 100) / 1440.0


def _read_icgem(path: Path, lines: list[str], epoch: float | None) -> GravityField:
    head: dict[str, str] = {}
    i = 0
    while i < len(lines) and not lines[i].startswith("begin_of_head"):
        i += 1
    if i == len(lines):
        i = 0  # header keywords may appear without begin_of_head
    while i < len(lines) and not lines[i].startswith("end_of_head"):
        parts = lines[i].split(None, 1)
        if len(parts) == 2:
            head.setdefault(parts[0].lower(), parts[1].strip())
        i += 1
    if i == len(lines):
        raise ParseError(path, "no end_of_head line")
    gm_text = head.get("earth_gravity_constant", head.get("gravity_constant"))
    if gm_text is None or "radius" not in head:
        raise ParseError(path, "header lacks gravity_constant or radius")
    gm = _num(gm_text.split()[0], path, None)
    radius = _num(head["radius"].split()[0], path, None)
    norm = head.get("norm", "fully_normalized").split()[0]
    if norm != "fully_normalized":
        raise ParseError(path, f"normalization {norm!r} not supported (fully_normalized only)")
    version2 = head.get("format", "").split()[:1] == ["icgem2.0"]
    t_days = None if epoch is None else epoch / SECONDS_PER_DAY
    coeffs = _Coefficients(path)
    last_t0: dict[tuple[int, int], float] = {}
    for k in range(i + 1, len(lines)):
        parts = lines[k].split()
        if not parts:
            continue
        key, lineno = parts[0].lower(), k + 1
        if key not in ("gfc", "gfct", "trnd", "dot", "acos", "asin"):
            raise ParseError(path, f"unknown record key {parts[0]!r}", line=lineno)
        if len(parts) < 5:
            raise ParseError(path, f"{key} record has {len(parts)} fields", line=lineno)
        try:
            n, m = int(parts[1]), int(parts[2])
        except ValueError:
            raise ParseError(path, "degree/order not integers", line=lineno) from None
        c, s = _num(parts[3], path, lineno), _num(parts[4], path, lineno)
        if key == "gfc":
            coeffs.add(n, m, c, s, lineno)
            continue
        if t_days is None:
            raise ParseError(path, f"time-variable '{key}' term: give an epoch to evaluate the field",
                             line=lineno)
        extra = parts[7:]
        if version2:
            if len(extra) < 2:
                raise ParseError(path, f"{key} record lacks t0 t1", line=lineno)
            t0 = _icgem_date_days(extra[0], path, lineno)
            t1 = _icgem_date_days(extra[1], path, lineno)
            if not (t0 <= t_days < t1):
                continue
            period = extra[2] if len(extra) > 2 else None
        else:
            if key == "gfct":
                if not extra:
                    raise ParseError(path, "gfct record lacks t0", line=lineno)
                last_t0[(n, m)] = _icgem_date_days(extra[0], path, lineno)
            if (n, m) not in last_t0:
                raise ParseError(path, f"{key} before its gfct", line=lineno)
            t0 = last_t0[(n, m)]
            period = extra[0] if key in ("acos", "asin") and extra else None
        dt_years = (t_days - t0) / DAYS_PER_JULIAN_YEAR
        if key == "gfct":
            factor = 1.0
        elif key in ("trnd", "dot"):
            factor = dt_years
        else:
            if period is None:
                raise ParseError(path, f"{key} record lacks its period", line=lineno)
            arg = 2.0 * np.pi * dt_years / _num(period, path, lineno)
            factor = np.cos(arg) if key == "acos" else np.sin(arg)
        coeffs.add(n, m, c * factor, s * factor, lineno, accumulate=True)
    nmax = int(head["max_degree"].split()[0]) if "max_degree" in head else None
    return coeffs.field(gm, radius, nmax, name=head.get("modelname", path.name),
                        tide_system=head.get("tide_system", "unknown").split()[0])


def _read_cof(path: Path, lines: list[str]) -> GravityField:
    gm = radius = None
    coeffs = _Coefficients(path)
    for k, line in enumerate(lines):
        lineno = k + 1
        if line.startswith("POTFIELD"):
            nums = _FLOAT_RE.findall(line[17:])
            if len(nums) < 2:
                raise ParseError(path, "POTFIELD lacks GM and radius", line=lineno)
            gm, radius = _num(nums[0], path, lineno), _num(nums[1], path, lineno)
        elif line.startswith("RECOEF"):
            try:
                n, m = int(line[6:11]), int(line[11:14])
            except ValueError:
                raise ParseError(path, "degree/order not integers", line=lineno) from None
            nums = _FLOAT_RE.findall(line[14:])
            if len(nums) not in (1, 2) or "".join(nums).replace(" ", "") != line[14:].replace(" ", ""):
                raise ParseError(path, f"bad RECOEF values {line[14:]!r}", line=lineno)
            c = _num(nums[0], path, lineno)
            s = _num(nums[1], path, lineno) if len(nums) == 2 else 0.0
            coeffs.add(n, m, c, s, lineno)
        elif line.startswith("END"):
            break
        elif line.strip() and not line.startswith(("COMMENT", "CCCC")):
            raise ParseError(path, f"unknown record {line[:8]!r}", line=lineno)
    if gm is None:
        raise ParseError(path, "no POTFIELD record")
    return coeffs.field(gm, radius, name=path.stem)


def _read_table_rows(path, lines, start, coeffs, min_fields, sep=None):
    for k in range(start, len(lines)):
        text = lines[k].strip()
        if not text:
            continue
        parts = [p for p in (text.split(sep) if sep else text.split()) if p.strip() != ""]
        lineno = k + 1
        if len(parts) < min_fields:
            raise ParseError(path, f"{len(parts)} fields, expected at least {min_fields}", line=lineno)
        try:
            n, m = int(parts[0]), int(parts[1])
        except ValueError:
            raise ParseError(path, "degree/order not integers", line=lineno) from None
        coeffs.add(n, m, _num(parts[2].strip(), path, lineno), _num(parts[3].strip(), path, lineno),
                   lineno)


def _read_egm(path: Path, lines: list[str], gm: float, radius: float) -> GravityField:
    coeffs = _Coefficients(path)
    _read_table_rows(path, lines, 0, coeffs, 6)
    return coeffs.field(gm, radius, name=path.name)


def _read_plain(path: Path, lines: list[str]) -> GravityField:
    head = lines[0].split()
    gm, radius = _num(head[0], path, 1), _num(head[1], path, 1)
    coeffs = _Coefficients(path)
    _read_table_rows(path, lines, 1, coeffs, 4)
    return coeffs.field(gm, radius, name=path.stem)


def _read_shadr(path: Path, lines: list[str]) -> GravityField:
    head = [p.strip() for p in lines[0].split(",")]
    if len(head) < 6:
        raise ParseError(path, "SHADR header needs radius, GM, sigma GM, degree, order, normalization",
                         line=1)
    radius = _num(head[0], path, 1) * 1e3
    gm = _num(head[1], path, 1) * 1e9
    if int(_num(head[5], path, 1)) != 1:
        raise ParseError(path, "SHADR normalization state must be 1 (fully normalized)", line=1)
    coeffs = _Coefficients(path)
    _read_table_rows(path, lines, 1, coeffs, 4, sep=",")
    return coeffs.field(gm, radius, nmax=int(_num(head[3], path, 1)), name=path.stem)


def sniff_format(path: Path, lines: list[str]) -> str:
    """Name of the format of ``lines``: icgem, cof, shadr, egm or plain."""
    text = "\n".join(lines[:400])
    if "end_of_head" in text:
        return "icgem"
    if "POTFIELD" in text:
        return "cof"
    first = lines[0] if lines else ""
    if first.count(",") >= 5:
        return "shadr"
    if len(first.split()) >= 2 and not re.fullmatch(r"\d+", first.split()[0]):
        return "plain"
    return "egm"


_READ: dict = {}  # (path, size, mtime, fmt, gm, radius) -> (epoch of an ICGEM file's terms, field) read here
_READ_KEPT = 4
_ANY_EPOCH = object()  # the field of a format without time-variable terms, whatever the epoch asked


def read_gravity(path, *, epoch: float | None = None, fmt: str | None = None,
                 gm: float = EGM96_GM, radius: float = EGM96_RADIUS) -> GravityField:
    """Read a gravity field file (format sniffed unless ``fmt`` given).

    ``epoch``: TDB seconds past J2000 at which time-variable ICGEM terms are
    evaluated. ``gm``/``radius`` apply only to the EGM format (not in the file).
    A process keeps the last few fields it read (keyed by path, size, modification
    time and the arguments; the epoch for ICGEM files only) and returns the same object
    again: a batch worker parses a field once for all its arcs, and the field's packed
    kernel table is then reused (:mod:`odpipe.dynamics.gravity_fields`). Fields are never
    modified in place.
    """
    path = Path(path)
    stat = path.stat()
    key = (str(path.resolve()), stat.st_size, stat.st_mtime_ns, fmt, gm, radius)
    held = _READ.get(key)
    if held is not None and held[0] in (_ANY_EPOCH, epoch):
        return held[1]
    lines = _lines(path)
    if not lines:
        raise ParseError(path, "empty file")
    fmt = fmt or sniff_format(path, lines)
    field = _parse(path, lines, fmt, epoch, gm, radius)
    _READ.pop(key, None)
    while len(_READ) >= _READ_KEPT:
        _READ.pop(next(iter(_READ)))
    _READ[key] = (epoch if fmt == "icgem" else _ANY_EPOCH, field)
    return field


def _parse(path: Path, lines: list[str], fmt: str, epoch, gm, radius) -> GravityField:
    if fmt == "icgem":
        return _read_icgem(path, lines, epoch)
    if fmt == "cof":
        return _read_cof(path, lines)
    if fmt == "shadr":
        return _read_shadr(path, lines)
    if fmt == "egm":
        return _read_egm(path, lines, gm, radius)
    if fmt == "plain":
        return _read_plain(path, lines)
    raise ValueError(f"unknown gravity format {fmt!r}")
