"""Tropospheric bending of a ground antenna's elevation: ITU-R P.834-7 (2015) section 1, reference atmosphere.

The apparent elevation of a target seen at free-space elevation theta0 (deg) from a station at height h (km)
is theta0 + tau0, with (eq. 14)

    tau0 = 1 / (1.728 + 0.5411 theta0 + 0.03723 theta0^2 + h (0.1815 + 0.06272 theta0 + 0.01138 theta0^2)
                + h^2 (0.01727 + 0.008288 theta0))   deg.

Below the free-space elevation where theta0 + tau0 is least (near the station's lowest visible elevation,
eq. 10-11) the bending is held at its value there, as Orekit's EarthITU453AtmosphereRefraction does, so a
target under the horizon is not bent back into view. Angles in rad, heights in m.
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache

import numpy as np
from scipy.optimize import minimize_scalar

from .computed import Computed, EventPartial

EARTH_RADIUS_M = 6370e3                        # P.834-7's Earth radius
N_SURFACE, N_SCALE_M = 315e-6, 1e3 / 0.1361    # reference refractivity n(h) - 1 = a exp(-h / H) (eq. 8)
_A = (1.728, 0.5411, 0.03723)
_B = (0.1815, 0.06272, 0.01138)
_C = (0.01727, 0.008288)


def _denominator(deg, km):
    return (_A[0] + _A[1] * deg + _A[2] * deg**2 + km * (_B[0] + _B[1] * deg + _B[2] * deg**2)
            + km**2 * (_C[0] + _C[1] * deg))


def bending(elevation, height_m):
    """tau0 (rad) of eq. 14 at free-space elevations (rad) from a station at ``height_m``, unbounded."""
    return np.radians(1.0 / _denominator(np.degrees(elevation), np.asarray(height_m) * 1e-3))


def minimal_elevation(height_m):
    """Lowest elevation (rad) a station at ``height_m`` sees, eq. 10: -acos(R/(R+h) n(0)/n(h))."""
    h = np.asarray(height_m, dtype=float)
    n_ratio = (1 + N_SURFACE) / (1 + N_SURFACE * np.exp(-h / N_SCALE_M))
    return -np.arccos(EARTH_RADIUS_M / (EARTH_RADIUS_M + h) * n_ratio)


@lru_cache(maxsize=256)
def _held_below(height_m: float) -> float:
    """Free-space elevation (rad) where elevation + bending is least, searched over [-6, 45] deg."""
    best = minimize_scalar(lambda e: e + bending(e, height_m), bounds=(-np.pi / 30, np.pi / 4), method="bounded",
                           options={"xatol": 1e-12})
    return float(best.x)


def refraction(elevation, height_m: float):
    """(bending rad, d bending / d elevation) at free-space elevations (rad) from one station height (m)."""
    e = np.asarray(elevation, dtype=float)
    floor = _held_below(float(height_m))
    held = e < floor
    ee = np.where(held, floor, e)
    deg, km = np.degrees(ee), height_m * 1e-3
    tau = bending(ee, height_m)
    d_den = _A[1] + 2 * _A[2] * deg + km * (_B[1] + 2 * _B[2] * deg) + km**2 * _C[1]   # per deg
    slope = -d_den / _denominator(deg, km) ** 2                                          # deg per deg
    return tau, np.where(held, 0.0, slope)


def refracted(comp: Computed, height_m: float) -> Computed:
    """An elevation :class:`Computed` (rad, free space) turned apparent: value + bending, partials scaled."""
    tau, slope = refraction(comp.value, height_m)
    gain = 1.0 + slope
    events = [EventPartial(e.role, e.t, e.d_pos * gain[:, None], None if e.d_vel is None else e.d_vel * gain[:, None])
              for e in comp.events]
    return replace(comp, value=comp.value + tau, events=events)
