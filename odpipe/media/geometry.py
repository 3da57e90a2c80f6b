"""Station-centred geometry the media models need: geodetic coordinates and azimuth/elevation.

WGS84 ellipsoid; positions in ITRS metres; angles in rad (azimuth from north
through east).
"""

from __future__ import annotations

import numpy as np

WGS84_A = 6378137.0
WGS84_F = 1.0 / 298.257223563
_E2 = WGS84_F * (2.0 - WGS84_F)


def geodetic(r_itrs):
    """(latitude, longitude, height m) of ITRS positions (..., 3) on WGS84 (iterated to < 1e-12 rad)."""
    r = np.asarray(r_itrs, dtype=float)
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    p = np.hypot(x, y)
    lat = np.arctan2(z, p * (1.0 - _E2))
    for _ in range(6):
        n = WGS84_A / np.sqrt(1.0 - _E2 * np.sin(lat) ** 2)
        h = p / np.cos(lat) - n
        lat = np.arctan2(z, p * (1.0 - _E2 * n / (n + h)))
    n = WGS84_A / np.sqrt(1.0 - _E2 * np.sin(lat) ** 2)
    return lat, np.arctan2(y, x), p / np.cos(lat) - n


def azimuth_elevation(station_itrs, target_itrs):
    """(azimuth, elevation) rad of targets seen from stations, both ITRS (..., 3) m."""
    s = np.asarray(station_itrs, dtype=float)
    d = np.asarray(target_itrs, dtype=float) - s
    lat, lon, _ = geodetic(s)
    sl, cl, sp, cp = np.sin(lon), np.cos(lon), np.sin(lat), np.cos(lat)
    east = -sl * d[..., 0] + cl * d[..., 1]
    north = -sp * cl * d[..., 0] - sp * sl * d[..., 1] + cp * d[..., 2]
    up = cp * cl * d[..., 0] + cp * sl * d[..., 1] + sp * d[..., 2]
    return np.mod(np.arctan2(east, north), 2 * np.pi), np.arctan2(up, np.hypot(east, north))
