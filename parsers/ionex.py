"""IONEX 1.0/1.1 ionosphere maps (Schaer, Gurtner & Feltens 1998).

``read_ionex(*paths)`` returns one :class:`IonexMaps` holding every TEC map of
the files (maps at the same epoch in several files must agree; e.g. the
split-1/2/3 files of one day combine to the day's file). Values are scaled by
each block's EXPONENT (which may change between and inside maps) and given in
TECU (1e16 el/m^2); missing values (9999) are NaN. Heights are km in the file
and m here; latitudes/longitudes stay in degrees as the grid is defined. The
header's mapping function, elevation cutoff and base radius are kept.
numpy/stdlib only.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from parsers.errors import ParseError, ParseReport, check_mode, finite, handle, integer, read_text

_NEEDED = ("EPOCH OF FIRST MAP", "EPOCH OF LAST MAP", "INTERVAL", "# OF MAPS IN FILE", "BASE RADIUS",
           "HGT1 / HGT2 / DHGT", "LAT1 / LAT2 / DLAT", "LON1 / LON2 / DLON")


@dataclass
class IonexMaps:
    """TEC/RMS/height maps on a lat/lon grid: arrays indexed [map, height, lat, lon]."""

    epochs: np.ndarray            # datetime64[ns] UTC, one per map, increasing
    lat_deg: np.ndarray           # grid latitudes (file order, e.g. 87.5 .. -87.5)
    lon_deg: np.ndarray           # grid longitudes (e.g. -180 .. 180)
    height_m: np.ndarray          # shell heights, m (one for 2-D maps)
    tec: np.ndarray               # TECU
    rms: np.ndarray | None        # TECU, or None when the files carry no RMS maps
    hgt: np.ndarray | None        # height maps, m, or None
    base_radius_m: float
    mapping_function: str         # 'NONE', 'COSZ', 'QFAC', ...
    elevation_cutoff_deg: float
    interval_s: float
    sources: list = field(default_factory=list)


def read_ionex(*paths, errors: str = "raise", report: ParseReport | None = None) -> IonexMaps:
    """Maps of one or more IONEX files combined in time (grids must agree).

    With ``errors="report"`` a map with a fault is left out and added to ``report``; header
    faults always raise.
    """
    check_mode(errors)
    parts = [_read_one(Path(p), errors, report) for p in paths]
    head = parts[0]
    for p in parts[1:]:
        for name in ("lat_deg", "lon_deg", "height_m"):
            if not np.array_equal(getattr(p, name), getattr(head, name)):
                raise ParseError(p.sources[0], f"{name} grid differs from {head.sources[0]}")
    epochs = np.concatenate([p.epochs for p in parts])
    uniq, first = np.unique(epochs, return_index=True)
    stacks = {}
    for name in ("tec", "rms", "hgt"):
        arrs = [getattr(p, name) for p in parts]
        if any(a is None for a in arrs):
            stacks[name] = None
            continue
        allm = np.concatenate(arrs)
        for e in uniq:
            same = np.flatnonzero(epochs == e)
            if same.size > 1 and not all(np.array_equal(allm[same[0]], allm[j], equal_nan=True) for j in same[1:]):
                raise ParseError(parts[0].sources[0], f"{name} maps at {e} differ between files")
        stacks[name] = allm[first]
    return IonexMaps(uniq, head.lat_deg, head.lon_deg, head.height_m, stacks["tec"], stacks["rms"], stacks["hgt"],
                     head.base_radius_m, head.mapping_function, head.elevation_cutoff_deg, head.interval_s,
                     [s for p in parts for s in p.sources])


def sniff(head: bytes) -> bool:
    """True when the first line is the IONEX VERSION / TYPE header record."""
    first = head.decode("latin-1").split("\n", 1)[0]
    return first[60:80].rstrip() == "IONEX VERSION / TYPE"


def read(path, errors: str = "raise") -> IonexMaps:
    """The maps of one file (the reader interface of :mod:`parsers.formats`)."""
    return read_ionex(path, errors=errors)


def describe(path) -> list[str]:
    """Lines for ``odpipe inspect``: maps, their epochs and interval, the grid, and the maps left out."""
    report = ParseReport()
    m = read_ionex(path, errors="report", report=report)
    lines = [f"TEC maps: {len(m.epochs)}" + (", with RMS maps" if m.rms is not None else "")]
    if len(m.epochs):
        lines.append(f"epochs: {np.datetime64(m.epochs[0], 's')} .. {np.datetime64(m.epochs[-1], 's')} UTC, "
                     f"every {m.interval_s:g} s")
    lines += [f"grid: latitude {m.lat_deg[0]:g} .. {m.lat_deg[-1]:g} deg ({m.lat_deg.size}), longitude "
              f"{m.lon_deg[0]:g} .. {m.lon_deg[-1]:g} deg ({m.lon_deg.size}), height "
              + ", ".join(f"{h / 1e3:g}" for h in m.height_m) + " km",
              f"mapping function: {m.mapping_function}, elevation cutoff {m.elevation_cutoff_deg:g} deg",
              f"maps left out: {len(report)}"]
    return lines + [f"  {e}" for e in list(report)[:5]]


MAX_GRID = 100_000  # points along one axis; more is not a map but a hostile header


def _grid(v1, v2, dv, path, line, name):
    if dv == 0:
        return np.array([v1])
    n = round((v2 - v1) / dv) + 1
    if not 1 <= n <= MAX_GRID or not np.isclose(v1 + (n - 1) * dv, v2):
        raise ParseError(path, f"{name} grid {v1} {v2} {dv} is not regular (or has more than {MAX_GRID} points)",
                         line=line, record=name)
    return v1 + dv * np.arange(n)


def _floats(text, n, path, line, label):
    vals = [finite(x, path, label, line=line, record=label) for x in text.split()]
    if len(vals) < n:
        raise ParseError(path, f"{label} needs {n} numbers", line=line, record=label)
    return vals


_EPOCH_RANGES = ((1900, 2200), (1, 12), (1, 31), (0, 24), (0, 59), (0, 60))


def _epoch(text, path, line, label):
    fields = text.split()
    if len(fields) < 6:
        raise ParseError(path, f"{label} needs 6 integers (year month day hour minute second)", line=line,
                         record=label)
    y, mo, d, h, mi, s = (integer(x, path, label, lo, hi, line=line, record=label)
                          for x, (lo, hi) in zip(fields, _EPOCH_RANGES))
    try:
        return np.datetime64(f"{y:04d}-{mo:02d}-{d:02d}", "ns") + np.timedelta64((h * 60 + mi) * 60 + s, "s")
    except ValueError:
        raise ParseError(path, f"invalid date in {label}", line=line, record=label) from None


_VALUE = re.compile(r" *-?\d{1,5}", re.ASCII)


def _read_one(path: Path, errors: str, report: ParseReport | None) -> IonexMaps:
    lines = read_text(path, "ascii").splitlines()
    head, i = {}, 0
    # ---- header
    while True:
        if i >= len(lines):
            raise ParseError(path, "no END OF HEADER", line=i)
        label, data = lines[i][60:].strip(), lines[i][:60]
        i += 1
        if label == "END OF HEADER":
            break
        if label and label != "COMMENT":
            head.setdefault(label.replace("_", " "), (data, i))
    if "IONEX VERSION / TYPE" not in head:
        raise ParseError(path, "missing IONEX VERSION / TYPE", line=1)
    for name in _NEEDED:
        if name not in head:
            raise ParseError(path, f"missing header record {name}", line=i, record=name)
    h = {k: _floats(v[0], 3 if "/" in k else 1, path, v[1], k) for k, v in head.items()
         if k in ("INTERVAL", "BASE RADIUS", "HGT1 / HGT2 / DHGT", "LAT1 / LAT2 / DLAT",
                  "LON1 / LON2 / DLON", "ELEVATION CUTOFF")}
    grids = [_grid(*h[k][:3], path, head[k][1], k[:3]) for k in ("HGT1 / HGT2 / DHGT", "LAT1 / LAT2 / DLAT",
                                                                  "LON1 / LON2 / DLON")]
    if grids[0].size * grids[1].size * grids[2].size > 10 * MAX_GRID:
        raise ParseError(path, f"grid of {grids[0].size} x {grids[1].size} x {grids[2].size} points is too large",
                         line=i, record="grid")
    first = _epoch(*head["EPOCH OF FIRST MAP"], path, "EPOCH OF FIRST MAP")
    _epoch(*head["EPOCH OF LAST MAP"], path, "EPOCH OF LAST MAP")
    exponent = _int_record(head, "EXPONENT", path, -1, -99, 99)
    nmaps = _int_record(head, "# OF MAPS IN FILE", path, None, 1, 1_000_000)
    maps = {"TEC": {}, "RMS": {}, "HEIGHT": {}}
    # ---- data blocks
    while i < len(lines):
        label = lines[i][60:].strip()
        i += 1
        if label == "END OF FILE":
            break
        if label.startswith("START OF") and label.endswith("MAP"):
            try:
                kind, epoch, grid, i = _map(lines, i, label, grids, exponent, path)
            except ParseError as err:
                handle(err, errors, report)
                i = _skip_map(lines, max(i, (err.line or 1) - 1), label)
                continue
            if epoch in maps[kind]:
                handle(ParseError(path, f"a second {kind} map at {epoch}", line=i, record=label), errors, report)
                continue
            maps[kind][epoch] = grid
        elif lines[i - 1].strip() and label not in ("COMMENT",):
            handle(ParseError(path, f"unexpected record {label or lines[i - 1].strip()[:20]!r} between maps",
                              line=i, record=label), errors, report)
    if not maps["TEC"]:
        raise ParseError(path, "no TEC map", line=i)
    epochs = np.array(sorted(maps["TEC"]), dtype="datetime64[ns]")
    if len(epochs) != nmaps or epochs[0] != first:
        handle(ParseError(path, f"header says {nmaps} maps from {first}, file has {len(epochs)} from {epochs[0]}",
                          line=head["# OF MAPS IN FILE"][1], record="# OF MAPS IN FILE"), errors, report)
    tec = np.stack([maps["TEC"][e] for e in epochs])
    rms = np.stack([maps["RMS"][e] for e in epochs]) if set(maps["RMS"]) == set(maps["TEC"]) else None
    hgt = np.stack([maps["HEIGHT"][e] for e in epochs]) * 1e3 if set(maps["HEIGHT"]) == set(maps["TEC"]) else None
    mf = head.get("MAPPING FUNCTION", ("NONE", 0))[0].strip() or "NONE"
    heights, lats, lons = grids
    return IonexMaps(epochs, lats, lons, heights * 1e3, tec, rms, hgt, h["BASE RADIUS"][0] * 1e3, mf,
                     h.get("ELEVATION CUTOFF", [0.0])[0], h["INTERVAL"][0], [str(path)])


def _int_record(head, name, path, default, lo, hi):
    if name not in head:
        return default
    text, line = head[name]
    return integer((text.split() or [""])[0], path, name, lo, hi, line=line, record=name)


def _skip_map(lines, i, label):
    """Index of the line after the END OF ... MAP that closes a map started with ``label``."""
    end = "END OF" + label[len("START OF"):]
    while i < len(lines):
        i += 1
        if lines[i - 1][60:].strip() in (end, "END OF FILE"):
            return i if lines[i - 1][60:].strip() == end else i - 1
    return i


def _map(lines, i, label, grids, exponent, path):
    """(kind, epoch, grid, next line index) of the map whose START record is line ``i`` (1-based)."""
    heights, lats, lons = grids
    kind = label[9:-4].strip()
    if kind not in ("TEC", "RMS", "HEIGHT"):
        raise ParseError(path, f"unknown map type {label}", line=i, record=label)
    number = integer((lines[i - 1][:60].split() or [""])[0], path, label, 1, 1_000_000, line=i, record=label)
    epoch, grid, exp = None, np.full((heights.size, lats.size, lons.size), np.nan), exponent
    filled = np.zeros(grid.shape, dtype=bool)
    while i < len(lines):
        raw = lines[i]
        label = raw[60:].strip()
        i += 1
        if label == "EPOCH OF CURRENT MAP":
            epoch = _epoch(raw[:60], path, i, label)
        elif label == "EXPONENT":
            exp = integer((raw[:60].split() or [""])[0], path, label, -99, 99, line=i, record=number)
        elif label == "LAT/LON1/LON2/DLON/H":
            if epoch is None:
                raise ParseError(path, "latitude band before EPOCH OF CURRENT MAP", line=i, record=number)
            lat, l1, l2, dl, hh = (finite(raw[k:k + 6], path, "LAT/LON1/LON2/DLON/H", line=i, record=number)
                                   for k in (2, 8, 14, 20, 26))
            row = _grid(l1, l2, dl, path, i, "LON")
            values, start = [], i
            while len(values) < row.size:
                if i >= len(lines) or any(ch.isalpha() for ch in lines[i][60:]):
                    raise ParseError(path, f"latitude band {lat} ends after {len(values)} of {row.size} values",
                                     line=i + 1, record=number)
                text = lines[i].rstrip()
                for k in range(0, len(text), 5):
                    field5 = text[k:k + 5]
                    if not _VALUE.fullmatch(field5):
                        raise ParseError(path, f"bad value {field5.strip()!r} in {kind} map {number}",
                                         line=i + 1, record=number)
                    values.append(int(field5))
                i += 1
            try:
                ih, ilat, ilon = _index(heights, hh), _index(lats, lat), _index(lons, row)
            except KeyError as err:
                raise ParseError(path, f"{err.args[0]} not on the header grid", line=start, record=number) from None
            v = np.asarray(values[:row.size], dtype=float)
            grid[ih, ilat, ilon] = np.where(v == 9999, np.nan, v * 10.0 ** exp)
            filled[ih, ilat, ilon] = True
        elif label.startswith("END OF") and label.endswith("MAP"):
            if label != f"END OF {kind} MAP" or epoch is None:
                raise ParseError(path, f"{label} closes a {kind} map without EPOCH OF CURRENT MAP" if epoch is None
                                 else f"{label} closes a {kind} map", line=i, record=number)
            if not filled.all():
                lat_missing = lats[~filled.all(axis=(0, 2))]
                raise ParseError(path, f"{kind} map {number} has no values at {(~filled).sum()} grid points "
                                 f"(latitudes {lat_missing[:4].tolist()}...)", line=i, record=number)
            return kind, epoch, grid, i
        elif raw.strip() and label != "COMMENT":
            raise ParseError(path, f"unexpected record {label or raw.strip()[:20]!r} in {kind} map", line=i,
                             record=number)
    raise ParseError(path, f"file ends inside {kind} map {number}", line=i, record=number)


def _index(grid, value):
    """Index (or indices) of ``value`` on a regular grid; KeyError when off the grid."""
    step = grid[1] - grid[0] if grid.size > 1 else 1.0
    with np.errstate(over="ignore"):
        f = np.rint((np.asarray(value, dtype=float) - grid[0]) / step)
    if not np.all((f >= 0) & (f < grid.size)):  # (also before a cast of inf to int)
        raise KeyError(f"{value}")
    k = f.astype(int)
    if not np.allclose(grid[k], value):
        raise KeyError(f"{value}")
    return k
