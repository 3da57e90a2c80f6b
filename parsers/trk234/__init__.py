"""DSN TRK-2-34 (820-013, Tracking and Navigation Files, SFDU binary) reader and writer.

``read(path)`` returns :class:`parsers.TrackingData`: the navigation observables as a
TrackingTable (see :mod:`parsers.trk234.observables`), the uplink ramps (format 9) as a
ramp table, and in ``meta["blocks"]`` every SFDU with all its fields (one
:class:`Block` of packed records per format code), which :func:`write` turns back into the
same bytes. :func:`new_block` makes SFDUs from scratch. A duplicated record's rows are kept
with the DUPLICATE flag, rows without a finite value with INVALID (:mod:`parsers.table`);
an empty file is a ParseError in both modes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from parsers import table as tt
from parsers.errors import ParseError, ParseReport, check_mode
from parsers.table import TrackingData
from parsers.trk234 import layout
from parsers.trk234.observables import ramp_table, tracking_table
from parsers.trk234.sfdu import Block, split
from parsers.trk234.writer import new_block, write

__all__ = ["Block", "new_block", "read", "sniff", "write", "layout"]


def sniff(head: bytes) -> bool:
    """True when ``head`` starts with a TRK-2-34 SFDU label (NJPL2I00C123..C127)."""
    return len(head) >= 12 and head[:4] == b"NJPL" and head[8:12] in {k.encode() for k in layout.SECONDARY}


def read(path, errors: str = "raise") -> TrackingData:
    """Read a TRK-2-34 file; ``errors="report"`` skips corrupt SFDUs into ``report``."""
    check_mode(errors)
    path = Path(path)
    report = ParseReport()
    buf = path.read_bytes()
    if not buf:
        raise ParseError(path, "empty file", offset=0)
    blocks = split(buf, path, errors, report)
    counts = {b.format_code: 0 for b in blocks}
    for b in blocks:
        counts[b.format_code] += len(b.records)
    spacecraft = sorted({int(s) for b in blocks for s in np.unique(b.records["scft_id"])})
    meta = {"format": "TRK-2-34", "sfdu_counts": counts, "spacecraft": spacecraft, "blocks": blocks}
    table, ramps = tt.flag_duplicates(tracking_table(blocks, path.name)), ramp_table(blocks, path.name)
    return TrackingData(mark_ramped(table, ramps), ramps, report, meta)


def mark_ramped(table, ramps):
    """Rows uplinked by a station with ramp records in the file follow the ramp table: ``ramped``
    True and ``uplink_hz`` NaN (the contract's form); the record's own frequency at the time tag
    is kept in ``uplink_hz_record``."""
    ramped = table["station_tx"].isin(set(ramps["station"])).to_numpy() & (table["station_tx"] != "").to_numpy()
    table["uplink_hz_record"] = table["uplink_hz"]
    table.loc[ramped, "ramped"] = True
    table.loc[ramped, "uplink_hz"] = np.nan
    return table
