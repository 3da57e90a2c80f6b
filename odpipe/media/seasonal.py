"""DSN seasonal troposphere model: the base the TRK-2-23 .TRO adjustments are added to.

Per complex, zenith dry and wet delays (m) as a yearly Fourier series
(period 31557600 s, epoch 1972-01-01 00:00 UTC), written here as TRK-2-23
``BY TRIG`` cards so the same evaluator serves both. Coefficients: DSN
820-013 TRK-2-23 (Rev. C, 2008) seasonal model, as reproduced by Tudat's
``getDsnDefaultTroposphericSeasonalModelCspFile``. Operations fit a
polynomial to the daily deviations from this model (the .TRO NRMPOW cards).
"""

from __future__ import annotations

from parsers.trk223 import CalibrationSet, parse_text

_CARDS = """\
ADJUST(DOPRNG) BY TRIG(31557600., 0.0870, -0.0360, -0.0336, 0.0002, 0.0200, 0.0008, -0.0021, -0.0036, -0.0002)
  MODEL(WET NUPART) FROM(72/01/01,00:00) DSN(C10).
ADJUST(DOPRNG) BY TRIG(31557600., 2.0521, 0.0082, -0.0005, -0.0004, 0.0033, -0.0015, 0.0005, -0.0011, 0.0036)
  MODEL(DRY NUPART) FROM(72/01/01,00:00) DSN(C10).
ADJUST(DOPRNG) BY TRIG(31557600., 0.1149, 0.0255, 0.0020, 0.0010, 0.0026, 0.0036, -0.0001, 0.0007, 0.0012)
  MODEL(WET NUPART) FROM(72/01/01,00:00) DSN(C40).
ADJUST(DOPRNG) BY TRIG(31557600., 2.1579, -0.0032, -0.0002, 0.0012, 0.0017, -0.0043, 0.0052, 0.0016, -0.0021)
  MODEL(DRY NUPART) FROM(72/01/01,00:00) DSN(C40).
ADJUST(DOPRNG) BY TRIG(31557600., 0.1255, -0.0284, -0.0273, -0.0094, 0.0005, -0.0031, -0.0003, -0.0034, -0.0013)
  MODEL(WET NUPART) FROM(72/01/01,00:00) DSN(C60).
ADJUST(DOPRNG) BY TRIG(31557600., 2.1094, 0.0037, -0.0010, 0.0036, 0.0019, -0.0006, 0.0021, 0.0018, -0.0004)
  MODEL(DRY NUPART) FROM(72/01/01,00:00) DSN(C60).
"""


def dsn_seasonal() -> CalibrationSet:
    """The DSN seasonal zenith troposphere model as a CalibrationSet (source 'DSN-seasonal')."""
    return CalibrationSet(parse_text(_CARDS, "DSN-seasonal"))
