"""Modified Saastamoinen radio troposphere: the slant delay itself, no separate mapping function.

Xu (2007), GPS - Theory, Algorithms and Applications (2nd ed., Springer), sec. 5.4:
``delay = 0.002277 / cos z * (P + (1255 / T + 0.05) e - B tan^2 z) + dR`` (m; P, e, B in hPa, T in K,
z the zenith angle), B(h) tabulated against station height and dR(h, z) against height and zenith
angle (Xu's tables; dR linearly interpolated in both). This is Orekit's ModifiedSaastamoinenModel,
the radio troposphere of Orekit's orbit-determination tests, with its conventions: heights clipped
to 0..5000 m, elevations below 0.05 rad taken as 0.05 rad, dR 0 at the zenith and held at its 80 deg
value beyond 80 deg (Xu tabulates 60..80 deg).

Orekit's standard atmosphere (its TroposphericModelUtils.STANDARD_ATMOSPHERE): 1013.25 hPa, 20 degC,
50 % at 0 m with the CIPM-2007 vapour pressure; carried to the station height by the Berg laws
(:func:`odpipe.media.saastamoinen.carried_up`) with the relative humidity converted through the
saturation law Orekit names Wang (1988), ``exp(-37.2465 + 0.213166 T - 2.56908e-4 T^2)`` hPa.
Inputs SI (Pa, K, m, rad); delays in m, one way.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from odpipe.media.mendes_pavlis import vapour_pressure
from odpipe.media.saastamoinen import carried_up

MIN_ELEVATION = 0.05                 # rad
H_MAX = 5000.0                       # m, top of the tables
_B_H = np.array([0.0, 500.0, 1000.0, 1500.0, 2000.0, 2500.0, 3000.0, 4000.0, 5000.0])
_B_HPA = np.array([1.156, 1.079, 1.006, 0.938, 0.874, 0.813, 0.757, 0.654, 0.563])
_DR_H = np.array([0.0, 500.0, 1000.0, 1500.0, 2000.0, 3000.0, 4000.0, 5000.0])
_DR_Z = np.radians([0.0, 60.0, 66.0, 70.0, 73.0, 75.0, 76.0, 77.0, 78.0, 78.5, 79.0, 79.5, 79.75, 80.0, 90.0])
_DR_M = np.array([
    [0.000, 0.003, 0.006, 0.012, 0.020, 0.031, 0.039, 0.050, 0.065, 0.075, 0.087, 0.102, 0.111, 0.121, 0.121],
    [0.000, 0.003, 0.006, 0.011, 0.018, 0.028, 0.035, 0.045, 0.059, 0.068, 0.079, 0.093, 0.101, 0.110, 0.110],
    [0.000, 0.002, 0.005, 0.010, 0.017, 0.025, 0.032, 0.041, 0.054, 0.062, 0.072, 0.085, 0.092, 0.100, 0.100],
    [0.000, 0.002, 0.005, 0.009, 0.015, 0.023, 0.029, 0.037, 0.049, 0.056, 0.065, 0.077, 0.083, 0.091, 0.091],
    [0.000, 0.002, 0.004, 0.008, 0.013, 0.021, 0.026, 0.033, 0.044, 0.051, 0.059, 0.070, 0.076, 0.083, 0.083],
    [0.000, 0.002, 0.003, 0.006, 0.011, 0.017, 0.021, 0.027, 0.036, 0.042, 0.049, 0.058, 0.063, 0.068, 0.068],
    [0.000, 0.001, 0.003, 0.005, 0.009, 0.014, 0.017, 0.022, 0.030, 0.034, 0.040, 0.047, 0.052, 0.056, 0.056],
    [0.000, 0.001, 0.002, 0.004, 0.007, 0.011, 0.014, 0.018, 0.024, 0.028, 0.033, 0.039, 0.043, 0.047, 0.047]])
_DR = RegularGridInterpolator((_DR_H, _DR_Z), _DR_M)
OREKIT_P0_PA, OREKIT_T0_K, OREKIT_RH0 = 101325.0, 293.15, 0.5   # Orekit's standard atmosphere at 0 m


def slant_delay(elevation, height_m, pressure_pa, temperature_k, vapour_pa):
    """One-way delay (m) at an elevation (rad) from a station ``height_m`` high with its surface
    pressure, temperature and water-vapour pressure (Pa, K, Pa)."""
    h = np.clip(np.asarray(height_m, dtype=float), 0.0, H_MAX)
    z = np.pi / 2 - np.maximum(np.asarray(elevation, dtype=float), MIN_ELEVATION)
    z, h = np.broadcast_arrays(z, h)
    b_hpa = np.interp(h, _B_H, _B_HPA)
    wet = (1255.0 / np.asarray(temperature_k) + 0.05) * np.asarray(vapour_pa) * 1e-2
    dr = _DR(np.stack([h.ravel(), np.abs(z).ravel()], axis=-1)).reshape(z.shape)
    return 0.002277 / np.cos(z) * (np.asarray(pressure_pa) * 1e-2 + wet - b_hpa * np.tan(z) ** 2) + dr


def wang_saturation(temperature_k):
    """Saturation water-vapour pressure (Pa) of the law Orekit names Wang (1988)."""
    t = np.asarray(temperature_k, dtype=float)
    return 100.0 * np.exp(-37.2465 + 0.213166 * t - 2.56908e-4 * t * t)


def orekit_standard_atmosphere(height_m):
    """(P Pa, T K, e Pa) of Orekit's standard atmosphere at a height (clipped to 0..5000 m)."""
    h = np.clip(np.asarray(height_m, dtype=float), 0.0, H_MAX)
    e0 = vapour_pressure(100.0 * OREKIT_RH0, OREKIT_T0_K, OREKIT_P0_PA)
    p, t, rh = carried_up(OREKIT_P0_PA, OREKIT_T0_K, e0 / wang_saturation(OREKIT_T0_K), h)
    return p, t, rh * wang_saturation(t)


def standard_slant_delay(elevation, height_m):
    """One-way delay (m) of Orekit's standard atmosphere at a station height (m) and elevation (rad)."""
    return slant_delay(elevation, height_m, *orekit_standard_atmosphere(height_m))
