"""Ingest: read every tracking file of a run into one TrackingTable and one ramp table.

Each file's format is detected (:mod:`parsers.formats`); a ``.parquet`` file is a TrackingTable the
project wrote itself (:mod:`odpipe.preprocess.store`, ramps beside it), so any stage's output can
feed a run. In ``errors="report"`` mode a corrupt record is reported with its file and offset and
skipped; a file no reader recognises is reported and skipped; nothing else is lost. A CCSDS TDM's
received frequencies become DSN Doppler against its FREQ_OFFSET or TRANSMIT_FREQ lines
(:func:`odpipe.products.tdm.doppler_from_tdm`). Files that name no spacecraft (Orekit's ``.aer``
tables) have their rows given the run's. A process keeps the last few files it read (keyed by path,
size and modification time), so the arcs of a nightly that share a day's file parse it once per
worker.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from odpipe.preprocess import store as table_store
from odpipe.products.tdm import doppler_from_tdm
from parsers import ParseError, TrackingData
from parsers.formats import read_any
from parsers.ramps import RampStore
from parsers.table import empty_ramps


@dataclass
class Ingested:
    table: pd.DataFrame
    ramps: pd.DataFrame
    store: RampStore
    log: list[str] = field(default_factory=list)


_READ: dict = {}    # (path, size, mtime ns, errors) -> what _read returned; never modified by ingest
_KEEP = 8           # files kept per process


def _read(path: Path, errors: str) -> TrackingData:
    try:
        stat = Path(path).stat()
    except OSError:   # the readers say why, naming the file
        return _parse(path, errors)
    key = (str(Path(path).resolve()), stat.st_size, stat.st_mtime_ns, errors)
    if key not in _READ:
        data = _parse(path, errors)
        while len(_READ) >= _KEEP:
            _READ.pop(next(iter(_READ)))
        _READ[key] = data
    return _READ[key]


def _parse(path: Path, errors: str) -> TrackingData:
    if path.suffix == ".parquet":
        table, ramps = table_store.read(path)
        return TrackingData(table, ramps)
    return read_any(path, errors=errors)


def ingest(files: list[Path], errors: str = "report", spacecraft: str = "") -> Ingested:
    """Read ``files``; rows sorted by time tag (stable), index renumbered from 0; rows naming no
    spacecraft take ``spacecraft``."""
    tables, ramps, log = [], [], []
    for path in files:
        try:
            data = _read(path, errors)
        except ParseError as exc:
            if errors == "raise":
                raise
            log.append(f"SKIPPED {exc}")
            continue
        if not hasattr(data, "table"):
            log.append(f"SKIPPED {path}: not a tracking file")
            continue
        data, left = doppler_from_tdm(data)   # a TDM's received frequencies: DSN Doppler
        if left:
            log.append(f"{path.name}: {left} RECEIVE_FREQ rows kept as received frequency (no FREQ_OFFSET or"
                       " TRANSMIT_FREQ reference to make Doppler of)")
        tables.append(data.table)
        if data.ramps is not None and len(data.ramps):
            ramps.append(data.ramps)
        log.append(f"read {path.name}: {len(data.table)} rows, "
                   f"{0 if data.ramps is None else len(data.ramps)} ramp segments, {len(data.report)} records skipped")
        log += [f"  skipped: {err}" for err in data.report]
    if not tables:
        raise ValueError("no tracking data could be read from " + ", ".join(map(str, files)))
    table = pd.concat(tables, ignore_index=True).sort_values("epoch", kind="stable").reset_index(drop=True)
    if spacecraft:
        unnamed = table["spacecraft"].astype(str) == ""
        table.loc[unnamed, "spacecraft"] = spacecraft
        if unnamed.any():
            log.append(f"{int(unnamed.sum())} rows naming no spacecraft given the run's, {spacecraft}")
    ramp_table = pd.concat(ramps, ignore_index=True) if ramps else empty_ramps()
    store = RampStore(ramp_table)
    if len(store.findings):
        counts = store.findings.groupby("kind").size() if "kind" in store.findings else {}
        log.append("ramp findings: " + ", ".join(f"{k} {n}" for k, n in dict(counts).items()))
    return Ingested(table, ramp_table, store, log)
