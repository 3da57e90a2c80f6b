"""Saastamoinen zenith delays from surface meteorology, and a standard atmosphere.

Hydrostatic: Saastamoinen (1972) in the form of Davis et al. (1985),
``ZHD = 0.0022768 P / (1 - 0.00266 cos 2phi - 0.28e-6 h)`` (P in hPa, h in m);
wet: Saastamoinen (1972), ``ZWD = 0.002277 (1255/T + 0.05) e`` (T in K, e in hPa),
as summarized by Estefan & Sovers (1994), JPL Publication 94-24, eqs. 12-18.
Inputs here are SI (Pa, K, m, rad); delays in m.
"""

from __future__ import annotations

import numpy as np

P0_PA = 101325.0      # standard sea-level pressure
T0_K = 291.15         # 18 degC, the standard atmosphere used for GNSS defaults
RH0 = 0.5             # relative humidity at sea level


def zenith_hydrostatic(pressure_pa, latitude, height_m):
    """Zenith hydrostatic delay (m) from surface pressure (Pa), geodetic latitude (rad), height (m)."""
    g = 1.0 - 0.00266 * np.cos(2.0 * np.asarray(latitude)) - 0.28e-6 * np.asarray(height_m)
    return 0.0022768 * np.asarray(pressure_pa) * 1e-2 / g


def zenith_wet(vapour_pressure_pa, temperature_k):
    """Zenith wet delay (m) from water-vapour partial pressure (Pa) and temperature (K)."""
    return 0.002277 * (1255.0 / np.asarray(temperature_k) + 0.05) * np.asarray(vapour_pressure_pa) * 1e-2


def saturation_vapour_pressure(temperature_k):
    """Pa; Bean & Dutton (1966) form used by Estefan & Sovers (1994) eq. 16."""
    t = np.asarray(temperature_k, dtype=float)
    return 611.0 * 10.0 ** (7.5 * (t - 273.15) / (t - 35.85))


def carried_up(p0_pa, t0_k, rh0, dh_m):
    """(P Pa, T K, relative humidity) ``dh_m`` above a level where they are (p0, t0, rh0): the height
    laws of Berg (1948) as given by Xu (2007), GPS - Theory, Algorithms and Applications, sec. 5.4."""
    dh = np.asarray(dh_m, dtype=float)
    return p0_pa * (1.0 - 2.26e-5 * dh) ** 5.225, t0_k - 0.0065 * dh, rh0 * np.exp(-6.396e-4 * dh)


def standard_atmosphere(height_m):
    """(P Pa, T K, e Pa) of the standard atmosphere at a height (1013.25 hPa, 18 degC, 50 % at 0 m)."""
    p, t, rh = carried_up(P0_PA, T0_K, RH0, height_m)
    return p, t, rh * saturation_vapour_pressure(t)


def standard_zenith_delays(latitude, height_m):
    """(dry, wet) zenith delays (m) of the standard atmosphere at a site: the no-data fallback."""
    p, t, e = standard_atmosphere(height_m)
    return zenith_hydrostatic(p, latitude, height_m), zenith_wet(e, t)
