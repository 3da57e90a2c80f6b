"""Readers and writers of tracking and calibration formats (numpy/pandas, and odpipe.constants only).

Every tracking reader module exposes ``sniff(head: bytes) -> bool`` (does this
file look like my format?) and ``read(path, errors="raise") -> TrackingData``
(see :mod:`parsers.table`); every malformed input raises :class:`ParseError`
naming file, offset or line and record. With ``errors="report"`` a corrupt
record is added to ``TrackingData.report`` and reading goes on.

The same contract holds for every reader (tracking, media calibration, IONEX,
maneuver files, OEM): nothing but ParseError comes out of malformed input, and

* an empty (or blank) file is a ParseError in both modes: there is no record to keep;
  a file with its format's header and no records is an empty, valid file;
* text that is not the format's encoding (ASCII, UTF-8) is a ParseError naming the byte;
* numbers are finite and plausible: 1e400, NaN where a number is required, 5000-digit
  integers, year 0 (which datetime64[ns] would silently wrap) and grids of absurd size
  are ParseErrors of their record;
* a tracking value that is not finite (NaN, inf) keeps its row with the INVALID bit of
  ``flags``, and a duplicated UTDF or TRK-2-34 record keeps its rows with DUPLICATE
  (:mod:`parsers.table`): flagged, never dropped, never silent.

``tests/fuzzing.py`` holds every reader to this with seeded hostile inputs.
"""

from parsers.errors import ParseError, ParseReport
from parsers.table import TrackingData

__all__ = ["ParseError", "ParseReport", "TrackingData"]
