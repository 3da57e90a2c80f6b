"""Ocean-loading displacement of a station from its BLQ coefficients (IERS Conventions 2010, §7.1.2).

The 11 main constituents only (M2 S2 N2 K2 K1 O1 P1 Q1 Mf Mm Ssa), eq. 7.16:
Δc = Σ_j f_j A_cj cos(χ_j(t) + u_j - φ_cj) for c = up, west, south, with χ_j the
astronomical argument of constituent j in the Schwiderski convention of the BLQ
files (Doodson number applied to τ, s, h, p plus 0° for the semidiurnal and
long-period tides, +90° for K1, -90° for O1, P1, Q1) and the 18.6-year nodal
factors f_j, u_j of the lunar tides (Pugh 1987, Table 4.3). HARDISP's spline of
the admittance over 342 constituents is not done: against its Onsala test case
(24 hours) the result differs by 0.26 mm rms radial, 0.12 west, 0.08 south and
0.46 mm at most, on a radial signal of ±8.6 mm, i.e. ~3% of the signal
(without the nodal factors: 0.41 mm rms, 0.64 mm max; tests/test_ocean_loading.py).

Output: ITRS displacement (…,3) m; BLQ up, west, south turned to ITRS at the
station's WGS84 latitude and longitude.
"""

from __future__ import annotations

import numpy as np

from odpipe.constants import DAYS_PER_JULIAN_CENTURY, J2000_NS, NS_PER_DAY, TT_MINUS_TAI_NS
from odpipe.environment.solid_tides import doodson_angles
from parsers.leap_seconds import tai_minus_utc_ns
from odpipe.time.scales import as_utc_ns

# Doodson multipliers of (tau, s, h, p) and Schwiderski phase offset (deg), BLQ column order
_ARGUMENTS = np.array([
    (2, 0, 0, 0, 0.0), (2, 2, -2, 0, 0.0), (2, -1, 0, 1, 0.0), (2, 2, 0, 0, 0.0),      # M2 S2 N2 K2
    (1, 1, 0, 0, 90.0), (1, -1, 0, 0, -90.0), (1, 1, -2, 0, -90.0), (1, -2, 0, 1, -90.0),  # K1 O1 P1 Q1
    (0, 2, 0, 0, 0.0), (0, 1, 0, -1, 0.0), (0, 0, 2, 0, 0.0)])                         # Mf Mm Ssa


def _nodal(node_deg: np.ndarray):
    """Nodal factors f (…,11) and phase corrections u (…,11, deg) at the Moon's ascending-node longitude."""
    n = np.radians(node_deg)[..., None] * np.array([1.0, 2.0, 3.0])
    c, s = np.cos(n), np.sin(n)
    one, zero = np.ones_like(node_deg), np.zeros_like(node_deg)
    f_m2 = 1.0004 - 0.0373 * c[..., 0] + 0.0002 * c[..., 1]
    f_o1 = 1.0089 + 0.1871 * c[..., 0] - 0.0147 * c[..., 1] + 0.0014 * c[..., 2]
    f = np.stack([f_m2, one, f_m2,
                  1.0241 + 0.2863 * c[..., 0] + 0.0083 * c[..., 1] - 0.0015 * c[..., 2],
                  1.0060 + 0.1150 * c[..., 0] - 0.0088 * c[..., 1] + 0.0006 * c[..., 2],
                  f_o1, one, f_o1, 1.043 + 0.414 * c[..., 0], 1.0 - 0.130 * c[..., 0], one], -1)
    u_m2 = -2.14 * s[..., 0]
    u_o1 = 10.80 * s[..., 0] - 1.34 * s[..., 1] + 0.19 * s[..., 2]
    u = np.stack([u_m2, zero, u_m2, -17.74 * s[..., 0] + 0.68 * s[..., 1] - 0.04 * s[..., 2],
                  -8.86 * s[..., 0] + 0.68 * s[..., 1] - 0.07 * s[..., 2], u_o1, zero, u_o1,
                  -23.74 * s[..., 0] + 2.68 * s[..., 1] - 0.38 * s[..., 2], zero, zero], -1)
    return f, u


def loading_up_west_south(site, epoch_utc) -> np.ndarray:
    """(…,3) m: up, west and south ocean-loading displacement of BLQ ``site`` at UTC epochs."""
    utc = as_utc_ns(epoch_utc)
    tt_cent = (utc + tai_minus_utc_ns(utc) + TT_MINUS_TAI_NS - J2000_NS) / NS_PER_DAY / DAYS_PER_JULIAN_CENTURY
    tau, shp = doodson_angles(tt_cent, np.mod(utc, NS_PER_DAY) / 3.6e12)
    beta = np.stack([tau, shp[..., 0], shp[..., 1], shp[..., 2]], -1)
    chi = beta @ _ARGUMENTS[:, :4].T + _ARGUMENTS[:, 4]                # (…,11) deg
    f, u = _nodal(-shp[..., 3])                                        # N = -N'
    arg = np.radians(chi + u)[..., None, :] - np.radians(site.phase_deg)
    return np.sum(f[..., None, :] * site.amplitude_m * np.cos(arg), axis=-1)


def ocean_loading_displacement(site, r_station_itrs, epoch_utc) -> np.ndarray:
    """ITRS displacement (…,3) m of the station at ``r_station_itrs`` (m) from BLQ ``site`` at UTC epochs."""
    from odpipe.environment.stations import enu_matrix, itrs_to_geodetic

    uws = loading_up_west_south(site, epoch_utc)
    enu = np.stack([-uws[..., 1], -uws[..., 2], uws[..., 0]], -1)
    lat, lon, _ = itrs_to_geodetic(np.asarray(r_station_itrs, float))
    return np.einsum("...ji,...j->...i", enu_matrix(lat, lon), enu)
