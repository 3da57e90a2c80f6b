"""Solid Earth tide displacement of a station (IERS Conventions 2010, §7.1.1).

Step 1: degree-2 and -3 in-phase displacement with the latitude dependence of
h2 and l2 (eqs. 7.5–7.6), the out-of-phase diurnal and semidiurnal parts
(eqs. 7.10–7.11) and the l(1) terms (eqs. 7.8–7.9). Step 2: frequency-dependent
corrections of Table 7.3a (diurnal band, 31 lines) and Table 7.3b (long-period,
5 lines). The permanent tide is not removed ("conventional tide free" ITRF).
Up to ~0.4 m radial; the result agrees with the IERS DEHANTTIDEINEL test cases
to 1e-16 m (tests/test_stations_tides.py).

Inputs in ITRS metres; output (…,3) displacement in ITRS metres.
"""

from __future__ import annotations

import numpy as np

from odpipe.constants import DAYS_PER_JULIAN_CENTURY, IERS2010_EARTH_RADIUS, J2000_NS, NS_PER_DAY, TT_MINUS_TAI_NS
from parsers.leap_seconds import tai_minus_utc_ns
from odpipe.time.scales import as_utc_ns

H20, L20, H3, L3 = 0.6078, 0.0847, 0.292, 0.015  # nominal Love and Shida numbers (TN36 §7.1.1)
MASS_RATIO_SUN = 332946.0482
MASS_RATIO_MOON = 0.0123000371

# Table 7.3a: multipliers of (s, h, p, N', ps) added to tau, then ΔR in-phase, ΔR out-of-phase,
# ΔT in-phase, ΔT out-of-phase (mm)
_DIURNAL = np.array([
    (-3, 0, 2, 0, 0, -0.01, 0.0, 0.0, 0.0), (-3, 2, 0, 0, 0, -0.01, 0.0, 0.0, 0.0),
    (-2, 0, 1, -1, 0, -0.02, 0.0, 0.0, 0.0), (-2, 0, 1, 0, 0, -0.08, 0.0, -0.01, 0.01),
    (-2, 2, -1, 0, 0, -0.02, 0.0, 0.0, 0.0), (-1, 0, 0, -1, 0, -0.10, 0.0, 0.0, 0.0),
    (-1, 0, 0, 0, 0, -0.51, 0.0, -0.02, 0.03), (-1, 2, 0, 0, 0, 0.01, 0.0, 0.0, 0.0),
    (0, -2, 1, 0, 0, 0.01, 0.0, 0.0, 0.0), (0, 0, -1, 0, 0, 0.02, 0.0, 0.0, 0.0),
    (0, 0, 1, 0, 0, 0.06, 0.0, 0.0, 0.0), (0, 0, 1, 1, 0, 0.01, 0.0, 0.0, 0.0),
    (0, 2, -1, 0, 0, 0.01, 0.0, 0.0, 0.0), (1, -3, 0, 0, 1, -0.06, 0.0, 0.0, 0.0),
    (1, -2, 0, -1, 0, 0.01, 0.0, 0.0, 0.0), (1, -2, 0, 0, 0, -1.23, -0.07, 0.06, 0.01),
    (1, -1, 0, 0, -1, 0.02, 0.0, 0.0, 0.0), (1, -1, 0, 0, 1, 0.04, 0.0, 0.0, 0.0),
    (1, 0, 0, -1, 0, -0.22, 0.01, 0.01, 0.0), (1, 0, 0, 0, 0, 12.00, -0.80, -0.67, -0.03),
    (1, 0, 0, 1, 0, 1.73, -0.12, -0.10, 0.0), (1, 0, 0, 2, 0, -0.04, 0.0, 0.0, 0.0),
    (1, 1, 0, 0, -1, -0.50, -0.01, 0.03, 0.0), (1, 1, 0, 0, 1, 0.01, 0.0, 0.0, 0.0),
    (0, 1, 0, 1, -1, -0.01, 0.0, 0.0, 0.0), (1, 2, -2, 0, 0, -0.01, 0.0, 0.0, 0.0),
    (1, 2, 0, 0, 0, -0.11, 0.01, 0.01, 0.0), (2, -2, 1, 0, 0, -0.01, 0.0, 0.0, 0.0),
    (2, 0, -1, 0, 0, -0.02, 0.0, 0.0, 0.0), (3, 0, 0, 0, 0, 0.0, 0.0, 0.0, 0.0),
    (3, 0, 0, 1, 0, 0.0, 0.0, 0.0, 0.0)])
# Table 7.3b: multipliers of (s, h, p, N', ps), then ΔR in, ΔT in, ΔR out, ΔT out (mm)
_LONG_PERIOD = np.array([
    (0, 0, 0, 1, 0, 0.47, 0.23, 0.16, 0.07), (0, 2, 0, 0, 0, -0.20, -0.12, -0.11, -0.05),
    (1, 0, -1, 0, 0, -0.11, -0.08, -0.09, -0.04), (2, 0, 0, 0, 0, -0.13, -0.11, -0.15, -0.07),
    (2, 0, 0, 1, 0, -0.05, -0.05, -0.06, -0.03)])


def doodson_angles(t_cent: np.ndarray, ut_hours: np.ndarray):
    """(tau, s, h, p, N', ps) in degrees at TT centuries past J2000 and UT hours of day."""
    t = t_cent
    s = 218.31664563 + (481267.88194 + (-0.0014663889 + 0.00000185139 * t) * t) * t
    tau = ut_hours * 15.0 + 280.4606184 + (36000.7700536 + (0.00038793 - 0.0000000258 * t) * t) * t - s
    s = s + (1.396971278 + (0.000308889 + (0.000000021 + 0.000000007 * t) * t) * t) * t
    h = 280.46645 + (36000.7697489 + (0.00030322222 + (0.000000020 - 0.00000000654 * t) * t) * t) * t
    p = 83.35324312 + (4069.01363525 + (-0.01032172222 + (-0.0000124991 + 0.00000005263 * t) * t) * t) * t
    zns = 234.95544499 + (1934.13626197 + (-0.00207561111 + (-0.00000213944 + 0.00000001650 * t) * t) * t) * t
    ps = 282.93734098 + (1.71945766667 + (0.00045688889 + (-0.00000001778 - 0.00000000334 * t) * t) * t) * t
    return tau, np.stack([s, h, p, zns, ps], axis=-1)


def solid_earth_tide(r_station, r_sun, r_moon, epoch_utc) -> np.ndarray:
    """Station displacement (…,3) m in ITRS from the solid Earth tide.

    ``r_station``, ``r_sun``, ``r_moon``: geocentric ITRS positions (m), broadcastable
    (…,3); ``epoch_utc``: datetime64 UTC (…).
    """
    x = np.asarray(r_station, float)
    rs = np.stack(np.broadcast_arrays(np.asarray(r_sun, float), np.asarray(r_moon, float)), axis=0)  # (2, …, 3)
    utc = as_utc_ns(epoch_utc)
    tt_cent = (utc + tai_minus_utc_ns(utc) + TT_MINUS_TAI_NS - J2000_NS) / NS_PER_DAY / DAYS_PER_JULIAN_CENTURY
    ut_hours = np.mod(utc, NS_PER_DAY) / 3.6e12

    r = np.linalg.norm(x, axis=-1)
    sinphi, cosphi = x[..., 2] / r, np.hypot(x[..., 0], x[..., 1]) / r
    lam = np.arctan2(x[..., 1], x[..., 0])
    sinla, cosla = np.sin(lam), np.cos(lam)
    e_r = np.stack([cosphi * cosla, cosphi * sinla, sinphi], -1)
    e_n = np.stack([-sinphi * cosla, -sinphi * sinla, cosphi], -1)
    e_e = np.stack([-sinla, cosla, np.zeros_like(sinla)], -1)

    rb = np.linalg.norm(rs, axis=-1)                       # (2, …)
    unit_b = rs / rb[..., None]
    mass = np.array([MASS_RATIO_SUN, MASS_RATIO_MOON]).reshape((2,) + (1,) * (rb.ndim - 1))
    fac2 = mass * IERS2010_EARTH_RADIUS * (IERS2010_EARTH_RADIUS / rb) ** 3
    fac3 = fac2 * (IERS2010_EARTH_RADIUS / rb)

    # step 1, in phase, degrees 2 and 3 (eqs. 7.5, 7.6) with latitude-dependent h2, l2
    sc = np.sum(unit_b * (x / r[..., None]), axis=-1)
    lat_term = 1.0 - 1.5 * cosphi**2
    h2, l2 = H20 - 0.0006 * lat_term, L20 + 0.0002 * lat_term
    p2 = 3.0 * (h2 / 2.0 - l2) * sc**2 - h2 / 2.0
    p3 = 2.5 * (H3 - 3.0 * L3) * sc**3 + 1.5 * (L3 - H3) * sc
    x2, x3 = 3.0 * l2 * sc, 1.5 * L3 * (5.0 * sc**2 - 1.0)
    radial_unit = x / r[..., None]
    disp = np.sum(fac2[..., None] * (x2[..., None] * unit_b + p2[..., None] * radial_unit)
                  + fac3[..., None] * (x3[..., None] * unit_b + p3[..., None] * radial_unit), axis=0)

    # step 1, out-of-phase (diurnal, semidiurnal) and l(1) terms, in local (r, n, e) components
    X, Y, Z = rs[..., 0], rs[..., 1], rs[..., 2]
    r2 = rb**2
    d1 = fac2 * Z * (X * sinla - Y * cosla) / r2          # diurnal-band combinations
    e1 = fac2 * Z * (X * cosla + Y * sinla) / r2
    sin2la, cos2la = 2 * sinla * cosla, cosla**2 - sinla**2
    a2 = fac2 * ((X**2 - Y**2) * sin2la - 2 * X * Y * cos2la) / r2  # semidiurnal combinations
    b2 = fac2 * ((X**2 - Y**2) * cos2la + 2 * X * Y * sin2la) / r2
    d1, e1, a2, b2 = (v.sum(axis=0) for v in (d1, e1, a2, b2))
    cos2phi = cosphi**2 - sinphi**2
    dhi_d, dli_d, dhi_s, dli_s, l1_d, l1_s = -0.0025, -0.0007, -0.0022, -0.0007, 0.0012, 0.0024
    dr = -3 * dhi_d * sinphi * cosphi * d1 - 0.75 * dhi_s * cosphi**2 * a2
    dn = (-3 * dli_d * cos2phi * d1 + 1.5 * dli_s * sinphi * cosphi * a2
          - 3 * l1_d * sinphi**2 * e1 - 1.5 * l1_s * sinphi * cosphi * b2)
    de = (-3 * dli_d * sinphi * e1 - 1.5 * dli_s * cosphi * b2
          + 3 * l1_d * sinphi * cos2phi * d1 - 1.5 * l1_s * sinphi**2 * cosphi * a2)

    # step 2: frequency dependence, diurnal band (Table 7.3a) and long period (Table 7.3b), mm
    tau, args = doodson_angles(tt_cent, ut_hours)
    theta = np.radians(tau[..., None] + args @ _DIURNAL[:, :5].T) + lam[..., None]
    sin_t, cos_t = np.sin(theta), np.cos(theta)
    dr += 1e-3 * 2 * sinphi * cosphi * (sin_t @ _DIURNAL[:, 5] + cos_t @ _DIURNAL[:, 6])
    dn += 1e-3 * cos2phi * (sin_t @ _DIURNAL[:, 7] + cos_t @ _DIURNAL[:, 8])
    de += 1e-3 * sinphi * (cos_t @ _DIURNAL[:, 7] - sin_t @ _DIURNAL[:, 8])
    theta = np.radians(args @ _LONG_PERIOD[:, :5].T)
    sin_t, cos_t = np.sin(theta), np.cos(theta)
    dr += 1e-3 * (1.5 * sinphi**2 - 0.5) * (cos_t @ _LONG_PERIOD[:, 5] + sin_t @ _LONG_PERIOD[:, 7])
    dn += 1e-3 * 2 * cosphi * sinphi * (cos_t @ _LONG_PERIOD[:, 6] + sin_t @ _LONG_PERIOD[:, 8])

    return disp + dr[..., None] * e_r + dn[..., None] * e_n + de[..., None] * e_e


def station_tide_displacement(r_station_itrs, t, ephemeris, gcrs_to_itrs=None) -> np.ndarray:
    """Solid-tide displacement (…,3) m in ITRS at epochs ``t``, Sun and Moon from ``ephemeris``.

    ``t``: UTC datetime64 or TDB s past J2000; ``gcrs_to_itrs``: rotation callable of TDB s (default
    the IAU 2006/2000A rotation with EOP, ``odpipe.frames.earth.gcrs_to_itrs``). Geocentric Sun/Moon
    are geometric (the light-time effect is < 1e-6 relative), rotated to ITRS, then :func:`solid_earth_tide`.
    """
    from odpipe.frames.earth import gcrs_to_itrs as full_rotation
    from odpipe.time.scales import tdb_to_utc, utc_to_tdb

    arr = np.asarray(t)
    utc, tdb = (arr, utc_to_tdb(arr)) if arr.dtype.kind == "M" else (tdb_to_utc(arr), arr.astype(float))
    m = (gcrs_to_itrs or full_rotation)(tdb)
    sun = np.einsum("...ij,...j->...i", m, ephemeris.position("sun", "earth", tdb))
    moon = np.einsum("...ij,...j->...i", m, ephemeris.position("moon", "earth", tdb))
    return solid_earth_tide(r_station_itrs, sun, moon, utc)
