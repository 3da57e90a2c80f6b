"""Niell (1996) hydrostatic and wet tropospheric mapping functions.

Niell, A. E. (1996), "Global mapping functions for the atmosphere delay at
radio wavelengths", J. Geophys. Res. 101(B2), 3227-3246, Tables 3 and 4.
Coefficients are tabulated at |latitude| 15, 30, 45, 60, 75 deg and linearly
interpolated (held constant outside); the hydrostatic ones vary with season
as ``avg - amp cos(2 pi (doy - 28) / 365.25)`` (half a year shifted in the
southern hemisphere) and carry a height correction.
"""

from __future__ import annotations

import numpy as np

from odpipe.constants import DAYS_PER_JULIAN_YEAR

_LAT = np.radians([15.0, 30.0, 45.0, 60.0, 75.0])
_HYD_AVG = np.array([
    [1.2769934e-3, 1.2683230e-3, 1.2465397e-3, 1.2196049e-3, 1.2045996e-3],
    [2.9153695e-3, 2.9152299e-3, 2.9288445e-3, 2.9022565e-3, 2.9024912e-3],
    [62.610505e-3, 62.837393e-3, 63.721774e-3, 63.824265e-3, 64.258455e-3]])
_HYD_AMP = np.array([
    [0.0, 1.2709626e-5, 2.6523662e-5, 3.4000452e-5, 4.1202191e-5],
    [0.0, 2.1414979e-5, 3.0160779e-5, 7.2562722e-5, 11.723375e-5],
    [0.0, 9.0128400e-5, 4.3497037e-5, 84.795348e-5, 170.37206e-5]])
_HEIGHT = (2.53e-5, 5.49e-3, 1.14e-3)
_WET = np.array([
    [5.8021897e-4, 5.6794847e-4, 5.8118019e-4, 5.9727542e-4, 6.1641693e-4],
    [1.4275268e-3, 1.5138625e-3, 1.4572752e-3, 1.5007428e-3, 1.7599082e-3],
    [4.3472961e-2, 4.6729510e-2, 4.3908931e-2, 4.4626982e-2, 5.4736038e-2]])


def continued_fraction(elevation, a, b, c):
    """Marini continued fraction normalized to 1 at zenith (elevation in rad)."""
    s = np.sin(elevation)
    return (1.0 + a / (1.0 + b / (1.0 + c))) / (s + a / (s + b / (s + c)))


def _at_latitude(table, lat):
    phi = np.abs(np.asarray(lat, dtype=float))
    return [np.interp(phi, _LAT, row) for row in table]


def hydrostatic(elevation, latitude, height_m, doy):
    """Niell hydrostatic mapping function (elevation, geodetic latitude in rad; height m; day of year)."""
    lat = np.asarray(latitude, dtype=float)
    phase = np.where(lat < 0, DAYS_PER_JULIAN_YEAR / 2, 0.0)
    season = np.cos(2 * np.pi * (np.asarray(doy, dtype=float) - 28.0 + phase) / DAYS_PER_JULIAN_YEAR)
    avg, amp = _at_latitude(_HYD_AVG, lat), _at_latitude(_HYD_AMP, lat)
    a, b, c = (m - s * season for m, s in zip(avg, amp))
    dm = (1.0 / np.sin(elevation) - continued_fraction(elevation, *_HEIGHT)) * np.asarray(height_m) * 1e-3
    return continued_fraction(elevation, a, b, c) + dm


def wet(elevation, latitude):
    """Niell wet mapping function (elevation, geodetic latitude in rad)."""
    return continued_fraction(elevation, *_at_latitude(_WET, latitude))
