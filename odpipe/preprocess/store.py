"""TrackingTable files: Parquet, with the ramp table beside it in ``<name>.ramps.parquet``.

Writes are atomic (:mod:`parsers.atomic`).
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from parsers.atomic import write_parquet
from parsers.table import validate


def ramps_path(path) -> Path:
    """Where the ramps of table file ``path`` live."""
    path = Path(path)
    return path.with_name(path.name.removesuffix(".parquet") + ".ramps.parquet")


def write(path, table: pd.DataFrame, ramps: pd.DataFrame | None = None) -> list[Path]:
    """Write the table (and its ramps, when any) atomically; returns the files written."""
    validate(table)
    path = Path(path)
    write_parquet(path, table.reset_index(drop=True), index=False)
    written = [path]
    if ramps is not None and len(ramps):
        write_parquet(ramps_path(path), ramps.reset_index(drop=True), index=False)
        written.append(ramps_path(path))
    return written


def read(path) -> tuple[pd.DataFrame, pd.DataFrame | None]:
    """(table, ramps or None) from a table file written by :func:`write`."""
    table = pd.read_parquet(path)
    validate(table)
    rp = ramps_path(path)
    return table, (pd.read_parquet(rp) if rp.exists() else None)
