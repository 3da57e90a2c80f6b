"""Ionosphere delay from IONEX VTEC maps through a thin-shell single-layer model.

VTEC is interpolated bilinearly in latitude/longitude and linearly in time
between consecutive maps rotated with the Sun (IONEX 1.0 spec, Schaer et al.
1998, eq. 3: map i is read at longitude ``lon + 360 deg (t - T_i) / 1 day``).
The line of sight pierces the shell of radius R + H (R, H from the file); the
slant TEC is VTEC at the pierce point times ``1 / cos z'`` with
``sin z' = R / (R + H) sin z``. First-order delay ``40.3 TEC / f^2`` m: a group
delay for range, a phase advance (opposite sign) for Doppler and phase.
"""

from __future__ import annotations

import numpy as np

from odpipe.constants import SECONDS_PER_DAY
from parsers.ionex import IonexMaps

K_IONO = 40.3e16          # m^3/s^2 per TECU: delay = K_IONO * TEC[TECU] / f^2
_DEG_PER_S = 360.0 / SECONDS_PER_DAY


def group_delay(tec_tecu, frequency_hz):
    """Group (range) delay in m of a TEC in TECU at frequency f (Hz); phase delay is its negative."""
    return K_IONO * np.asarray(tec_tecu) / np.asarray(frequency_hz) ** 2


def pierce_point(latitude, longitude, azimuth, elevation, base_radius_m, shell_height_m):
    """(latitude, longitude, obliquity 1/cos z') of the line of sight's shell pierce point (rad)."""
    z = np.pi / 2 - np.asarray(elevation)
    sin_zp = base_radius_m / (base_radius_m + shell_height_m) * np.sin(z)
    zp = np.arcsin(sin_zp)
    psi = z - zp
    lat = np.arcsin(np.sin(latitude) * np.cos(psi) + np.cos(latitude) * np.sin(psi) * np.cos(azimuth))
    lon = longitude + np.arcsin(np.clip(np.sin(psi) * np.sin(azimuth) / np.cos(lat), -1.0, 1.0))
    return lat, lon, 1.0 / np.cos(zp)


class IonexModel:
    """VTEC and slant delays from IONEX maps (2-D maps: one shell height)."""

    def __init__(self, maps: IonexMaps, time_interpolation: str = "rotated"):
        """``time_interpolation``: 'rotated' (IONEX spec, default) or 'linear' (maps not rotated)."""
        if time_interpolation not in ("rotated", "linear"):
            raise ValueError("time_interpolation must be 'rotated' or 'linear'")
        self._rate = _DEG_PER_S if time_interpolation == "rotated" else 0.0
        if maps.height_m.size != 1:
            raise ValueError("3-D IONEX maps are not supported; need a single shell height")
        self.maps = maps
        self.source = ",".join(s.rsplit("/", 1)[-1] for s in maps.sources)
        self._t = (maps.epochs - maps.epochs[0]) / np.timedelta64(1, "s")
        lat, lon = maps.lat_deg, maps.lon_deg
        flip = lat[0] > lat[-1]
        grid = maps.tec[:, 0, ::-1, :] if flip else maps.tec[:, 0]
        self._lat = lat[::-1] if flip else lat
        # longitudes -180..180 in the file: drop the duplicate last meridian, wrap periodically
        if np.isclose(lon[-1] - lon[0], 360.0):
            lon, grid = lon[:-1], grid[:, :, :-1]
        self._lon0, self._dlon, self._nlon = lon[0], lon[1] - lon[0], lon.size
        self._grid = np.ascontiguousarray(grid)

    def covers(self, t_utc):
        """True where t lies within the maps' time span."""
        s = (np.asarray(t_utc, dtype="datetime64[ns]") - self.maps.epochs[0]) / np.timedelta64(1, "s")
        return (s >= self._t[0]) & (s <= self._t[-1])

    def vtec(self, latitude_deg, longitude_deg, t_utc):
        """Vertical TEC (TECU) at geographic latitude/longitude (deg) and UTC times; NaN outside the maps."""
        lat, lon = np.broadcast_arrays(np.asarray(latitude_deg, float), np.asarray(longitude_deg, float))
        s = (np.asarray(t_utc, dtype="datetime64[ns]") - self.maps.epochs[0]) / np.timedelta64(1, "s")
        s = np.broadcast_to(s, lat.shape)
        i = np.clip(np.searchsorted(self._t, s, side="right") - 1, 0, max(self._t.size - 2, 0))
        if self._t.size == 1:
            out = self._spatial(0, lat, lon)
        else:
            t0, t1 = self._t[i], self._t[i + 1]
            w = (s - t0) / (t1 - t0)
            e0 = self._spatial(i, lat, lon + self._rate * (s - t0))
            e1 = self._spatial(i + 1, lat, lon + self._rate * (s - t1))
            out = (1.0 - w) * e0 + w * e1
        return np.where((s >= self._t[0]) & (s <= self._t[-1]), out, np.nan)

    def _spatial(self, k, lat, lon):
        """Bilinear VTEC of map(s) k at lat/lon (deg)."""
        la = np.clip(lat, self._lat[0], self._lat[-1])
        j = np.clip(np.searchsorted(self._lat, la, side="right") - 1, 0, self._lat.size - 2)
        q = (la - self._lat[j]) / (self._lat[j + 1] - self._lat[j])
        x = np.mod(lon - self._lon0, 360.0) / self._dlon
        m = np.floor(x).astype(int)
        p = x - m
        m0, m1 = m % self._nlon, (m + 1) % self._nlon
        g = self._grid
        return ((1 - p) * (1 - q) * g[k, j, m0] + p * (1 - q) * g[k, j, m1]
                + (1 - p) * q * g[k, j + 1, m0] + p * q * g[k, j + 1, m1])

    def slant_tec(self, latitude, longitude, azimuth, elevation, t_utc):
        """Slant TEC (TECU) from a site along az/el (rad) at UTC times.

        The single layer is a sphere: give the site's geocentric latitude (rad) and longitude.
        """
        m = self.maps
        plat, plon, obliquity = pierce_point(latitude, longitude, azimuth, elevation,
                                             m.base_radius_m, m.height_m[0])
        return obliquity * self.vtec(np.degrees(plat), np.degrees(plon), t_utc)
