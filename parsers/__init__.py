"""Readers and writers of tracking and calibration formats (numpy/pandas only).

Every tracking reader returns a TrackingTable (see :mod:`parsers.table`);
every malformed input raises :class:`ParseError` naming file, offset or line
and record.
"""

from parsers.errors import ParseError, ParseReport
from parsers import table

__all__ = ["ParseError", "ParseReport", "table"]
