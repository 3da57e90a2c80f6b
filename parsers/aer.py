"""Reader of the measurement tables of Orekit's orbit-determination tutorial and tests (``.aer``).

One measurement per line, blank-separated; ``#`` starts a comment line::

    2010-11-02T03:00:13.3851   RANGE       Uralla         38014.9488
    2010-11-02T03:00:50.5716   AZ_EL       Kumsan           211.1446   43.4099

Fields: ISO-8601 epoch (UTC), measurement type, station name, value(s).
``RANGE``: two-way range in km; ``RANGE_RATE``: two-way range rate in km/s;
``AZ_EL``: azimuth (from north through east) and elevation in degrees.
(Orekit's OrbitDeterminationTest reads these files: km and km/s times 1000,
degrees to radians, the epoch in UTC, ranges and range rates two-way, every
measurement dated at reception.)

TrackingTable rows: ``range`` (m, one-way equivalent c/2 * round-trip time, as
every ``range`` row in unit m), ``range_rate`` (m/s) and ``angle_az`` /
``angle_el`` (rad, two rows per AZ_EL line), all tagged 'receive' at the
station named in the line (station_tx too for the two-way types). The
file names no spacecraft: ``spacecraft`` is the ``spacecraft`` argument.
Extra column ``line`` (1-based); ``record`` is the 0-based line index.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from parsers import table as tt
from parsers.errors import ParseError, ParseReport, check_mode, handle
from parsers.fields import Fields, numbered_lines
from parsers.table import TrackingData

# type -> (number of values, [(observable, unit, scale to SI), ...] one per value, two-way)
TYPES = {"RANGE": (1, [("range", "m", 1000.0)], True),
         "RANGE_RATE": (1, [("range_rate", "m/s", 1000.0)], True),
         "AZ_EL": (2, [("angle_az", "rad", np.pi / 180), ("angle_el", "rad", np.pi / 180)], False)}
_EPOCH = re.compile(r"\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}(\.\d+)?Z?")


def sniff(head: bytes) -> bool:
    """True when the first line that is not a comment is 'epoch TYPE station value...' of a known TYPE."""
    text = head.decode("latin-1")
    first = next((ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")), "")
    f = first.split()
    return len(f) >= 4 and bool(_EPOCH.fullmatch(f[0])) and f[1] in TYPES


def read(path, errors: str = "raise", spacecraft: str = "") -> TrackingData:
    """Read an ``.aer`` file into a TrackingData; ``spacecraft`` fills the column the file lacks."""
    check_mode(errors)
    path = Path(path)
    report = ParseReport()
    rows = []
    for number, text in numbered_lines(path):
        if not text.strip() or text.lstrip().startswith("#"):
            continue
        try:
            rows.extend(_line(Fields(path, number, text)))
        except ParseError as err:
            handle(err, errors, report)
    if not rows:
        handle(ParseError(path, "no measurement lines (epoch TYPE station value...)"), errors, report)
        return TrackingData(table=tt.empty({"line": "int64"}), ramps=tt.empty_ramps(), report=report)
    epoch, obs, value, unit, station, two_way, line = (np.array(c) for c in zip(*rows))
    order = np.argsort(epoch, kind="stable")
    t = lambda a: a[order]  # noqa: E731
    table = tt.build(len(rows), epoch=t(epoch), tag="receive", observable=t(obs).astype(object),
                     value=t(value), unit=t(unit).astype(object), count_time=0.0,
                     station_tx=np.where(t(two_way), t(station), "").astype(object),
                     station_rx=t(station).astype(object), spacecraft=spacecraft, source=str(path),
                     record=t(line) - 1, flags=0, line=t(line))
    return TrackingData(table=table, ramps=tt.empty_ramps(), report=report,
                        meta={"stations": sorted(set(station.tolist()))})


def _line(f: Fields) -> list[tuple]:
    """(epoch, observable, value, unit, station, two_way, line) for each value of one measurement line."""
    f.need(3, "epoch, type, station")
    if not _EPOCH.fullmatch(f.str(0)):
        raise f.error(f"epoch {f.str(0)!r} is not ISO-8601 YYYY-MM-DDThh:mm:ss[.s]")
    kind = f.str(1)
    if kind not in TYPES:
        raise f.error(f"unknown measurement type {kind!r} (expected one of {', '.join(TYPES)})")
    n, values, two_way = TYPES[kind]
    f.record = kind
    if len(f) != 3 + n:
        raise f.error(f"{kind} needs {3 + n} fields (epoch, type, station, {n} value(s)), found {len(f)}")
    try:
        epoch = np.datetime64(f.str(0).rstrip("Z"), "ns")
    except ValueError:
        raise f.error(f"epoch {f.str(0)!r} is not a calendar date and time") from None
    return [(epoch, obs, f.float(3 + k, f"{kind} value {k + 1}") * scale, unit, f.str(2), two_way, f.number)
            for k, (obs, unit, scale) in enumerate(values)]
