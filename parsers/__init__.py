"""Readers and writers of tracking and calibration formats (numpy/pandas only).

Every tracking reader module exposes ``sniff(head: bytes) -> bool`` (does this
file look like my format?) and ``read(path, errors="raise") -> TrackingData``
(see :mod:`parsers.table`); every malformed input raises :class:`ParseError`
naming file, offset or line and record. With ``errors="report"`` a corrupt
record is added to ``TrackingData.report`` and reading goes on.
"""

from parsers.errors import ParseError, ParseReport
from parsers.table import TrackingData

__all__ = ["ParseError", "ParseReport", "TrackingData"]
