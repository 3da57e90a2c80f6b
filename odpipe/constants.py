"""Physical and time constants, each defined once, in SI units (m, s, rad, m^3/s^2) with its source.

Every layer may import this module, ``parsers`` too (tests/test_layers.py); it imports no other module of
the project. Earth's equatorial radius has several values, one per model: each is named for its model and
used where that model is meant. A gravity field's reference radius and GM come from its file, not from here.
"""

import numpy as np

# --- time ---------------------------------------------------------------------------------------------------
SECONDS_PER_DAY = 86400.0                      # s in a day of TT, TDB or UT1 (and a UTC day without leap second)
NS_PER_S = 1_000_000_000                       # datetime64[ns] ticks per second
NS_PER_DAY = 86_400 * NS_PER_S                 # datetime64[ns] ticks per day
DAYS_PER_JULIAN_YEAR = 365.25                  # d (IAU)
DAYS_PER_JULIAN_CENTURY = 36525.0              # d (IAU)
J2000 = np.datetime64("2000-01-01T12:00:00", "ns")   # J2000.0 on any time scale's own calendar (TT, TDB, ...)
J2000_NS = int(J2000.astype(np.int64))         # ns since 1970-01-01 on that calendar
J2000_JD = 2451545.0                           # Julian date of J2000.0
MJD_J2000 = 51544.5                            # Modified Julian date of J2000.0 (JD - 2400000.5)
MJD_ORIGIN = np.datetime64("1858-11-17", "ns")  # MJD 0.0
MJD_UNIX = 40587                               # MJD of 1970-01-01, the datetime64 origin
TT_MINUS_TAI_NS = 32_184_000_000               # TT - TAI = 32.184 s (IAU 1991)
GPS_MINUS_TAI_NS = -19 * NS_PER_S              # GPS - TAI = -19 s (IS-GPS-200)
GPS_ORIGIN_NS = int(np.datetime64("1980-01-06T00:00:00", "ns").astype(np.int64))   # GPS week 0 (GPS calendar)

# --- light, angles, the solar system -----------------------------------------------------------------------------
C_LIGHT = 299_792_458.0                        # m/s, speed of light in vacuum (SI, exact)
ARCSEC = np.pi / (180.0 * 3600.0)              # rad per arcsecond
AU = 149_597_870_700.0                         # m, astronomical unit (IAU 2012 Resolution B2, exact)

# --- Earth ------------------------------------------------------------------------------------------------------
WGS84_A = 6_378_137.0                          # m, WGS 84 ellipsoid semi-major axis (NIMA TR8350.2)
WGS84_F = 1.0 / 298.257223563                  # WGS 84 flattening (NIMA TR8350.2)
IERS2010_EARTH_RADIUS = 6_378_136.6            # m, a_E of the IERS Conventions 2010 (TN36, Table 1.1)
EGM96_RADIUS = 6_378_136.3                     # m, EGM96 reference radius (Lemoine et al. 1998)
EGM96_GM = 3.986004415e14                      # m^3/s^2, EGM96 GM of the Earth (Lemoine et al. 1998)
EARTH_ROTATION_RATE = 7.292115e-5              # rad/s, nominal mean rate (IERS Conventions 2010, Table 1.1)
ERA_RATE = 2.0 * np.pi * 1.00273781191135448 / SECONDS_PER_DAY   # rad per UT1 s, Earth rotation angle (TN36 eq. 5.15)

# --- Moon -------------------------------------------------------------------------------------------------------
MOON_RADIUS = 1_737_400.0                      # m, mean radius (IAU WGCCRE 2009, Archinal et al. 2011)
