"""CCSDS TDM 2.0 (503.0-B-2) keywords: metadata value kinds, and data types with their units.

Each data keyword maps to (observable, SI unit after the parser, factor from the TDM unit
to that unit). RANGE depends on RANGE_UNITS (km -> m; s and RU kept); ANGLE_1/2 take the
observable name from ANGLE_TYPE. Frequencies stay as written (FREQ_OFFSET is not added;
it travels in the ``freq_offset`` column).
"""

from __future__ import annotations

import math

HEADER = ("CREATION_DATE", "ORIGINATOR", "MESSAGE_ID")

_NUMBERED = {f"{k}_{i}" for k in ("PARTICIPANT", "EPHEMERIS_NAME", "TRANSMIT_DELAY", "RECEIVE_DELAY")
             for i in range(1, 6)}
NUMBER = {"TURNAROUND_NUMERATOR", "TURNAROUND_DENOMINATOR", "INTEGRATION_INTERVAL", "FREQ_OFFSET", "RANGE_MODULUS",
          "INTERPOLATION_DEGREE", "DOPPLER_COUNT_BIAS", "DOPPLER_COUNT_SCALE", "CORRECTION_ANGLE_1",
          "CORRECTION_ANGLE_2", "CORRECTION_DOPPLER", "CORRECTION_MAG", "CORRECTION_RANGE", "CORRECTION_RCS",
          "CORRECTION_RECEIVE", "CORRECTION_TRANSMIT", "CORRECTION_ABERRATION_YEARLY",
          "CORRECTION_ABERRATION_DIURNAL"} | {k for k in _NUMBERED if "DELAY" in k}
TIME = {"START_TIME", "STOP_TIME"}
PATH = {"PATH", "PATH_1", "PATH_2"}
CHOICE = {
    "TIME_SYSTEM": {"UTC", "TAI", "TT", "GPS", "TDB", "TCB", "TCG", "UT1", "GMST", "MET", "MRT", "SCLK"},
    "MODE": {"SEQUENTIAL", "SINGLE_DIFF"},
    "TIMETAG_REF": {"TRANSMIT", "RECEIVE"},
    "INTEGRATION_REF": {"START", "MIDDLE", "END"},
    "RANGE_MODE": {"COHERENT", "CONSTANT", "ONE_WAY"},
    "RANGE_UNITS": {"km", "s", "RU"},
    "ANGLE_TYPE": {"AZEL", "RADEC", "XEYN", "XSYE"},
    "DATA_QUALITY": {"RAW", "VALIDATED", "DEGRADED"},
    "CORRECTIONS_APPLIED": {"YES", "NO"},
    "DOPPLER_COUNT_ROLLOVER": {"YES", "NO"},
}
TEXT = {"TRACK_ID", "DATA_TYPES", "TRANSMIT_BAND", "RECEIVE_BAND", "REFERENCE_FRAME", "INTERPOLATION"} | {
    k for k in _NUMBERED if "DELAY" not in k}
METADATA = NUMBER | TIME | PATH | set(CHOICE) | TEXT
# the order of 503.0-B-2's metadata table (its all-keywords example follows it); numbered keywords by n
ORDER = ("TRACK_ID", "DATA_TYPES", "TIME_SYSTEM", "START_TIME", "STOP_TIME",
         *(f"PARTICIPANT_{i}" for i in range(1, 6)), "MODE", "PATH", "PATH_1", "PATH_2",
         *(f"EPHEMERIS_NAME_{i}" for i in range(1, 6)), "TRANSMIT_BAND", "RECEIVE_BAND", "TURNAROUND_NUMERATOR",
         "TURNAROUND_DENOMINATOR", "TIMETAG_REF", "INTEGRATION_INTERVAL", "INTEGRATION_REF", "FREQ_OFFSET",
         "RANGE_MODE", "RANGE_MODULUS", "RANGE_UNITS", "ANGLE_TYPE", "REFERENCE_FRAME", "INTERPOLATION",
         "INTERPOLATION_DEGREE", "DOPPLER_COUNT_BIAS", "DOPPLER_COUNT_SCALE", "DOPPLER_COUNT_ROLLOVER",
         *(f"TRANSMIT_DELAY_{i}" for i in range(1, 6)), *(f"RECEIVE_DELAY_{i}" for i in range(1, 6)),
         "DATA_QUALITY", "CORRECTION_ANGLE_1", "CORRECTION_ANGLE_2", "CORRECTION_DOPPLER", "CORRECTION_MAG",
         "CORRECTION_RANGE", "CORRECTION_RCS", "CORRECTION_RECEIVE", "CORRECTION_TRANSMIT",
         "CORRECTION_ABERRATION_YEARLY", "CORRECTION_ABERRATION_DIURNAL", "CORRECTIONS_APPLIED")

_DEG = math.pi / 180.0
_FIXED = {
    "CARRIER_POWER": ("carrier_power", "dBW", 1.0),
    "CLOCK_BIAS": ("clock_bias", "s", 1.0),
    "CLOCK_DRIFT": ("clock_drift", "s/s", 1.0),
    "DOPPLER_COUNT": ("doppler_count", "cycles", 1.0),
    "DOPPLER_INSTANTANEOUS": ("range_rate", "m/s", 1000.0),
    "DOPPLER_INTEGRATED": ("range_rate", "m/s", 1000.0),
    "DOR": ("dor", "s", 1.0),
    "MAG": ("magnitude", "mag", 1.0),
    "PC_N0": ("pc_n0", "dBHz", 1.0),
    "PR_N0": ("pr_n0", "dBHz", 1.0),
    "PRESSURE": ("pressure", "Pa", 100.0),
    "RCS": ("rcs", "m2", 1.0),
    "RECEIVE_FREQ": ("receive_freq", "Hz", 1.0),
    "RHUMIDITY": ("relative_humidity", "1", 0.01),
    "STEC": ("stec", "TECU", 1.0),
    "TEMPERATURE": ("temperature", "K", 1.0),
    "TROPO_DRY": ("tropo_dry", "m", 1.0),
    "TROPO_WET": ("tropo_wet", "m", 1.0),
    "VLBI_DELAY": ("vlbi_delay", "s", 1.0),
}
_PER_PARTICIPANT = {
    "RECEIVE_FREQ": ("receive_freq", "Hz", 1.0),
    "TRANSMIT_FREQ": ("transmit_freq", "Hz", 1.0),
    "TRANSMIT_FREQ_RATE": ("transmit_freq_rate", "Hz/s", 1.0),
    "RECEIVE_PHASE_CT": ("receive_phase_count", "cycles", 1.0),
    "TRANSMIT_PHASE_CT": ("transmit_phase_count", "cycles", 1.0),
}
DATA = dict(_FIXED)
DATA.update({f"{k}_{i}": v for k, v in _PER_PARTICIPANT.items() for i in range(1, 6)})
DATA["RANGE"] = ("range", None, None)
DATA["ANGLE_1"] = ("angle_1", "rad", _DEG)
DATA["ANGLE_2"] = ("angle_2", "rad", _DEG)

RANGE_UNITS = {"km": ("m", 1000.0), "s": ("s", 1.0), "RU": ("RU", 1.0)}
ANGLE_NAMES = {"AZEL": ("angle_az", "angle_el"), "RADEC": ("angle_ra", "angle_dec"),
               "XEYN": ("angle_x", "angle_y"), "XSYE": ("angle_x", "angle_y")}
INTEGRATED = {"DOPPLER_INTEGRATED", "DOPPLER_COUNT"} | {f"RECEIVE_FREQ_{i}" for i in range(1, 6)} | {"RECEIVE_FREQ"}


def participant(keyword: str) -> int | None:
    """Participant number n of a ``..._n`` data keyword (None otherwise)."""
    head, _, n = keyword.rpartition("_")
    return int(n) if head in _PER_PARTICIPANT and n.isdigit() else None


def unit_and_factor(keyword: str, range_units: str) -> tuple[str, float]:
    """SI unit and factor (TDM unit -> SI) of ``keyword`` in a segment with ``range_units``."""
    if keyword == "RANGE":
        return RANGE_UNITS[range_units]
    _, unit, factor = DATA[keyword]
    return unit, factor
