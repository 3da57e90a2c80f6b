"""TrackingTable files: Parquet, with the ramp table beside it in ``<name>.ramps.parquet``.

Writes are atomic (temporary file in the same folder, then rename).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import pandas as pd

from parsers.table import validate


def ramps_path(path) -> Path:
    """Where the ramps of table file ``path`` live."""
    path = Path(path)
    return path.with_name(path.name.removesuffix(".parquet") + ".ramps.parquet")


def _atomic_parquet(df: pd.DataFrame, path: Path) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}-")
    os.close(fd)
    try:
        df.to_parquet(tmp, index=False)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def write(path, table: pd.DataFrame, ramps: pd.DataFrame | None = None) -> list[Path]:
    """Write the table (and its ramps, when any) atomically; returns the files written."""
    validate(table)
    path = Path(path)
    _atomic_parquet(table.reset_index(drop=True), path)
    written = [path]
    if ramps is not None and len(ramps):
        _atomic_parquet(ramps.reset_index(drop=True), ramps_path(path))
        written.append(ramps_path(path))
    return written


def read(path) -> tuple[pd.DataFrame, pd.DataFrame | None]:
    """(table, ramps or None) from a table file written by :func:`write`."""
    table = pd.read_parquet(path)
    validate(table)
    rp = ramps_path(path)
    return table, (pd.read_parquet(rp) if rp.exists() else None)
