"""Atomic writes for the pipeline's products, tables, plots and reports.

The implementation is :mod:`parsers.atomic` (temporary file in the same folder,
fsync, rename, fsync of the folder), the project's one home for it: the format
writers of ``parsers`` use it too, and ``parsers`` may not import ``odpipe``.
"""

from parsers.atomic import (atomic_path, fsync_dir, save_figure, write_bytes, write_csv, write_parquet,
                            write_text)

__all__ = ["atomic_path", "fsync_dir", "save_figure", "write_bytes", "write_csv", "write_parquet", "write_text"]
