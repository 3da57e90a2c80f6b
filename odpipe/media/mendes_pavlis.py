"""Mendes-Pavlis optical troposphere: the IERS Conventions (2010) model for laser ranging.

Petit & Luzum (eds.), IERS Technical Note 36, ch. 9.2: zenith delays of Mendes & Pavlis (2004,
GRL 31, L14602) and the FCULa mapping function of Mendes et al. (2002, GRL 29(10), 1414), the
latter the same for both components. Water vapour pressure from relative humidity with the
CIPM-2007 saturation pressure and enhancement factor (Picard et al. 2008, Metrologia 45, 149),
as the Conventions recommend (Giacomo 1982). Inputs SI (Pa, K, m, rad); wavelengths in nm;
delays in m, one way.
"""

from __future__ import annotations

import numpy as np

from odpipe.media.niell import continued_fraction

XC_PPM = 375.0                                          # CO2 content of the Conventions
K0, K1, K2, K3 = 238.0185, 19990.975, 57.362, 579.55174  # um^-2, dispersion of dry air
W0, W1, W2, W3 = 295.235, 2.6422, -0.032380, 0.004028   # 1, um^2, um^4, um^6, dispersion of water vapour
# FCULa: a_i = a_i0 + a_i1 t(degC) + a_i2 cos(latitude) + a_i3 height(m) (Mendes et al. 2002)
FCULA = np.array([[12100.8e-7, 1729.5e-9, 319.1e-7, -1847.8e-11],
                  [30496.5e-7, 234.6e-8, -103.5e-6, -185.6e-10],
                  [6877.7e-5, 197.2e-7, -345.8e-5, 106.0e-9]])


def vapour_pressure(humidity_pct, temperature_k, pressure_pa):
    """Water vapour partial pressure (Pa) from relative humidity (%), temperature (K), pressure (Pa)."""
    t = np.asarray(temperature_k, dtype=float)
    saturation = np.exp(1.2378847e-5 * t**2 - 1.9121316e-2 * t + 33.93711047 - 6.3431645e3 / t)
    enhancement = 1.00062 + 3.14e-8 * np.asarray(pressure_pa) + 5.6e-7 * (t - 273.15) ** 2
    return np.asarray(humidity_pct) / 100.0 * enhancement * saturation


def _site(latitude, height_m):
    return 1.0 - 0.00266 * np.cos(2.0 * np.asarray(latitude)) - 0.28e-6 * np.asarray(height_m)


def dispersion(wavelength_nm):
    """(f_h, f_nh): hydrostatic and non-hydrostatic dispersion factors at a wavelength (nm)."""
    s2 = (1e3 / np.asarray(wavelength_nm, dtype=float)) ** 2              # wave number squared, um^-2
    f_h = 0.01 * (1.0 + 0.534e-6 * (XC_PPM - 450.0)) * (K1 * (K0 + s2) / (K0 - s2) ** 2
                                                        + K3 * (K2 + s2) / (K2 - s2) ** 2)
    f_nh = 0.003101 * (W0 + 3 * W1 * s2 + 5 * W2 * s2**2 + 7 * W3 * s2**3)
    return f_h, f_nh


def zenith_delays(pressure_pa, vapour_pa, latitude, height_m, wavelength_nm):
    """(hydrostatic, non-hydrostatic) zenith delays (m): geodetic latitude rad, ellipsoidal height m."""
    f_h, f_nh = dispersion(wavelength_nm)
    site = _site(latitude, height_m)
    dry = 2.416579e-3 * f_h * np.asarray(pressure_pa) * 1e-2 / site
    wet = 1e-4 * (5.316 * f_nh - 3.759 * f_h) * np.asarray(vapour_pa) * 1e-2 / site
    return dry, wet


def mapping(elevation, latitude, height_m, temperature_k):
    """FCULa mapping function (elevation, geodetic latitude rad; height m; surface temperature K)."""
    x = np.stack(np.broadcast_arrays(np.ones_like(np.asarray(elevation, dtype=float)),
                                     np.asarray(temperature_k, dtype=float) - 273.15,
                                     np.cos(latitude), np.asarray(height_m, dtype=float)), -1)
    a1, a2, a3 = (x @ row for row in FCULA)
    return continued_fraction(elevation, a1, a2, a3)


def slant_delay(elevation, latitude, height_m, pressure_pa, temperature_k, humidity_pct, wavelength_nm):
    """One-way optical path delay (m) at an elevation (rad) from surface meteorology."""
    e = vapour_pressure(humidity_pct, temperature_k, pressure_pa)
    dry, wet = zenith_delays(pressure_pa, e, latitude, height_m, wavelength_nm)
    return (dry + wet) * mapping(elevation, latitude, height_m, temperature_k)
