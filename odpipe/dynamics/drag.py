"""Atmospheric drag with the Harris-Priester (Montenbruck & Gill 2000, 3.5) or NRLMSISE-00 density.

Acceleration (m/s^2) of a spacecraft of mass m at r (Earth-centred ICRF, m),
velocity v, in an atmosphere co-rotating with the Earth (M&G eq. 3.97):
    a = -1/2 Cd (A/m) rho |v_r| v_r,    v_r = v - w x r,   w = (0, 0, OMEGA_EARTH)
(the rotation axis is taken as the ICRF z axis: 0.3 deg off the true pole in 2023).

Density (kg/m^3), Harris-Priester (M&G eqs. 3.100-3.104): between the tabulated
heights h_i <= h < h_i+1 the night-time minimum and day-time maximum decay
exponentially, rho_m(h) = rho_m(h_i) exp((h_i - h)/H_m) with
H_m = (h_i - h_i+1)/ln(rho_m(h_i+1)/rho_m(h_i)) (same for the maximum), and
    rho = rho_m + (rho_M - rho_m) cos^n(psi/2),   cos^n(psi/2) = (1/2 + r.e_b/(2|r|))^(n/2),
e_b the apex of the diurnal bulge: the Sun's declination and its right
ascension plus 30 deg; n = 2 for low inclinations, 6 for polar orbits.
Table: M&G Table 3.8 (mean solar activity), 100-1000 km; zero density above
1000 km (and below 100 km the 100-km value). The height is geodetic to first
order in the flattening, h = |r| - R_E (1 - f sin^2(phi)), phi the ICRF latitude
(tens of metres from the exact geodetic height at 500 km, an 0.3 % density change).

NRLMSISE-00 (:mod:`odpipe.environment.atmosphere.nrlmsise00`, total mass density with anomalous
oxygen), evaluated below 1500 km (zero above: under 1e-16 kg/m^3 there): the same height; geodetic
latitude phi_c + f sin(2 phi_c) from the ICRF latitude phi_c; longitude from the Earth rotation
angle at UT1 = UTC (precession-nutation ignored, 0.15 deg in 2010: the model's longitude terms are
smooth); UTC = TDB - (TT - UTC at the arc's start); local solar time UT + longitude/15 h. Solar and
geomagnetic activity from :mod:`~odpipe.environment.atmosphere.space_weather` (MSAFE or CSSI),
tabulated every 3 h over the arc at compile time and interpolated linearly. With ``ap_history`` the
model takes its Ap history (switch 9 = -1) instead of the daily Ap: tabulated once per UT 3-hour
interval (00, 03, ... 21 h UTC) and held over it, as the 3-hourly Ap it is made of.

Partials for the STM: d a/d v, d a/d r (through v_r, the height and, Harris-Priester, the bulge
angle; NRLMSISE-00: the height only, by a central difference of +-100 m) and d a/d Cd = a/Cd
(the estimable parameter 'cd').
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass, replace

import numpy as np
from numba import njit

from odpipe.constants import EARTH_ROTATION_RATE as OMEGA_EARTH, WGS84_A as R_EQUATOR, WGS84_F as FLATTENING
from odpipe.dynamics.force_registry import Force, kernel
from odpipe.environment.atmosphere.nrlmsise00 import mass_density
from odpipe.environment.atmosphere.space_weather import DailyRecords, MonthlyForecast
from odpipe.time.scales import tdb_to_utc, utc_to_tdb, utc_to_tt

BULGE_LAG = np.radians(30.0)
ATMOSPHERES = ("harris_priester", "nrlmsise00")
MSIS_TOP = 1500e3  # m, NRLMSISE-00 density taken as zero above
MSIS_DH = 100.0  # m, half-step of the height difference
SW_STEP = 10800.0  # s, space-weather tabulation step


@dataclass
class AtmosphericDrag:
    """Drag coefficient Cd (estimable parameter 'cd'), cross-section area (m^2);
    Harris-Priester bulge exponent n (2 low, 6 polar orbits); atmosphere 'harris_priester' or
    'nrlmsise00' (which needs space_weather; ap_history: NRLMSISE-00 fed the Ap history of the
    space weather instead of its daily Ap). Earth-centred models only."""

    cd: float
    area: float
    n_bulge: float = 6.0
    atmosphere: str = "harris_priester"
    space_weather: MonthlyForecast | DailyRecords | None = None
    ap_history: bool = False

    def __post_init__(self):
        if self.atmosphere not in ATMOSPHERES:
            raise ValueError(f"atmosphere must be one of {', '.join(ATMOSPHERES)}, not {self.atmosphere!r}")
        if self.atmosphere == "nrlmsise00" and self.space_weather is None:
            raise ValueError("the nrlmsise00 atmosphere needs a space_weather table")


# on; msis (NRLMSISE-00, else Harris-Priester); Cd; area m^2; bulge exponent; env.pos row of the Sun;
# d a/d p row of 'cd' (-1: not estimated); space weather: first epoch (TDB s), step (s), rows
# (previous day's F10.7, 81-day mean, Ap); TDB of the UTC year's start; TT - UTC (s); Ap history: TDB of
# the first UT 3-hour interval's start, one row (7,) per interval (NaN: the daily Ap instead)
DragData = namedtuple("DragData", ["on", "msis", "cd", "area", "n_bulge", "sun_slot", "cd_row", "sw_t0", "sw_step",
                                   "sw", "t_year", "tt_utc", "aph_t0", "aph"])
NO_HISTORY = np.full((1, 7), np.nan)

# height (km), minimum and maximum density (kg/m^3): M&G Table 3.8 (g/km^3 * 1e-12)
HP_TABLE = np.array([
    [100, 4.974e-07, 4.974e-07], [120, 2.490e-08, 2.490e-08], [130, 8.377e-09, 8.710e-09],
    [140, 3.899e-09, 4.059e-09], [150, 2.122e-09, 2.215e-09], [160, 1.263e-09, 1.344e-09],
    [170, 8.008e-10, 8.758e-10], [180, 5.283e-10, 6.010e-10], [190, 3.617e-10, 4.297e-10],
    [200, 2.557e-10, 3.162e-10], [210, 1.839e-10, 2.396e-10], [220, 1.341e-10, 1.853e-10],
    [230, 9.949e-11, 1.455e-10], [240, 7.488e-11, 1.157e-10], [250, 5.709e-11, 9.308e-11],
    [260, 4.403e-11, 7.555e-11], [270, 3.430e-11, 6.182e-11], [280, 2.697e-11, 5.095e-11],
    [290, 2.139e-11, 4.226e-11], [300, 1.708e-11, 3.526e-11], [320, 1.099e-11, 2.511e-11],
    [340, 7.214e-12, 1.819e-11], [360, 4.824e-12, 1.337e-11], [380, 3.274e-12, 9.955e-12],
    [400, 2.249e-12, 7.492e-12], [420, 1.558e-12, 5.684e-12], [440, 1.091e-12, 4.355e-12],
    [460, 7.701e-13, 3.362e-12], [480, 5.474e-13, 2.612e-12], [500, 3.916e-13, 2.042e-12],
    [520, 2.819e-13, 1.605e-12], [540, 2.042e-13, 1.267e-12], [560, 1.488e-13, 1.005e-12],
    [580, 1.092e-13, 7.997e-13], [600, 8.070e-14, 6.390e-13], [620, 6.012e-14, 5.123e-13],
    [640, 4.519e-14, 4.121e-13], [660, 3.430e-14, 3.325e-13], [680, 2.632e-14, 2.691e-13],
    [700, 2.043e-14, 2.185e-13], [720, 1.607e-14, 1.779e-13], [740, 1.281e-14, 1.452e-13],
    [760, 1.036e-14, 1.190e-13], [780, 8.496e-15, 9.776e-14], [800, 7.069e-15, 8.059e-14],
    [840, 4.680e-15, 5.741e-14], [880, 3.200e-15, 4.210e-14], [920, 2.210e-15, 3.130e-14],
    [960, 1.560e-15, 2.360e-14], [1000, 1.150e-15, 1.810e-14]])


@njit(cache=True)
def _layer(h_km):
    """Index i of the table layer h_i <= h < h_i+1 (clamped to the table)."""
    n = HP_TABLE.shape[0]
    i = 0
    while i < n - 2 and HP_TABLE[i + 1, 0] <= h_km:
        i += 1
    return i


@njit(cache=True)
def height(r):
    """Geodetic height (m) to first order in the flattening, and d h / d r (3,)."""
    rn = np.sqrt(np.sum(r * r))
    s = r[2] / rn
    h = rn - R_EQUATOR * (1.0 - FLATTENING * s * s)
    # d s/d r = (e_z - s r/|r|)/|r|
    dh = r / rn
    k = 2.0 * R_EQUATOR * FLATTENING * s / rn
    dh[0] -= k * s * r[0] / rn
    dh[1] -= k * s * r[1] / rn
    dh[2] += k * (1.0 - s * s)
    return h, dh


@njit(cache=True)
def harris_priester(r, r_sun, n_bulge):
    """Density (kg/m^3) at r (Earth-centred ICRF, m) with the Sun at r_sun; and d rho / d r (3,)."""
    h, dh = height(r)
    hk = h / 1000.0
    grad = np.zeros(3)
    if hk > HP_TABLE[-1, 0]:
        return 0.0, grad
    i = _layer(max(hk, HP_TABLE[0, 0]))
    h0, h1 = HP_TABLE[i, 0], HP_TABLE[i + 1, 0]
    sm = (h0 - h1) / np.log(HP_TABLE[i + 1, 1] / HP_TABLE[i, 1])  # scale heights, km
    sM = (h0 - h1) / np.log(HP_TABLE[i + 1, 2] / HP_TABLE[i, 2])
    rho_m = HP_TABLE[i, 1] * np.exp((h0 - hk) / sm)
    rho_M = HP_TABLE[i, 2] * np.exp((h0 - hk) / sM)
    # bulge apex: the Sun's declination, right ascension + lag
    ra = np.arctan2(r_sun[1], r_sun[0]) + BULGE_LAG
    dec = np.arctan2(r_sun[2], np.sqrt(r_sun[0] ** 2 + r_sun[1] ** 2))
    eb = np.array([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])
    rn = np.sqrt(np.sum(r * r))
    u = r / rn
    c = max(0.5 + 0.5 * np.sum(u * eb), 0.0)
    w = c ** (0.5 * n_bulge)
    rho = rho_m + (rho_M - rho_m) * w
    drho_dh = -(rho_m / sm + (rho_M / sM - rho_m / sm) * w) / 1000.0  # per m
    dw_dc = 0.5 * n_bulge * c ** (0.5 * n_bulge - 1.0) if c > 0.0 else 0.0
    proj = (eb - np.sum(u * eb) * u) / rn  # d (u.eb) / d r
    for k in range(3):
        grad[k] = drho_dh * dh[k] + (rho_M - rho_m) * dw_dc * 0.5 * proj[k]
    return rho, grad


@njit(cache=True)
def nrlmsise_density(t, r, sw_t0, sw_step, sw, t_year, tt_utc, aph_t0, aph):
    """NRLMSISE-00 density (kg/m^3) at r (Earth-centred ICRF, m) and TDB t; and d rho / d r (3,)."""
    h, dh = height(r)
    grad = np.zeros(3)
    if h > MSIS_TOP:
        return 0.0, grad
    k = min(max((t - sw_t0) / sw_step, 0.0), sw.shape[0] - 1.000001)
    i = int(k)
    w = k - i
    x = np.empty(8)
    s_year = t - t_year
    x[0] = np.floor(s_year / 86400.0) + 1.0
    x[1] = s_year - (x[0] - 1.0) * 86400.0
    rn = np.sqrt(np.sum(r * r))
    lat_c = np.arcsin(r[2] / rn)
    x[2] = np.degrees(lat_c + FLATTENING * np.sin(2.0 * lat_c))
    era = 2.0 * np.pi * (0.7790572732640 + 1.00273781191135448 * (t - tt_utc) / 86400.0)
    lon = np.degrees(np.arctan2(r[1], r[0]) - era) % 360.0
    x[3] = lon - 360.0 if lon > 180.0 else lon
    x[4] = x[1] / 3600.0 + x[3] / 15.0
    x[5] = (1.0 - w) * sw[i, 1] + w * sw[i + 1, 1]
    x[6] = (1.0 - w) * sw[i, 0] + w * sw[i + 1, 0]
    x[7] = (1.0 - w) * sw[i, 2] + w * sw[i + 1, 2]
    a = aph[min(max(int(np.floor((t - aph_t0) / SW_STEP)), 0), aph.shape[0] - 1)]
    rho = mass_density(x, h / 1000.0, a)
    up, down = mass_density(x, (h + MSIS_DH) / 1000.0, a), mass_density(x, (h - MSIS_DH) / 1000.0, a)
    drho_dh = (up - down) / (2.0 * MSIS_DH)
    for j in range(3):
        grad[j] = drho_dh * dh[j]
    return rho, grad


@njit(cache=True)
def drag_acceleration(rho, drho, r, v, cd, area, mass, acc, grad_r, grad_v, d_cd):
    """Add the drag acceleration (m/s^2) at density rho (kg/m^3, gradient drho) to acc, its partials
    to grad_r, grad_v (3x3), d a/d Cd to d_cd."""
    if rho == 0.0:
        return
    vr = np.array([v[0] + OMEGA_EARTH * r[1], v[1] - OMEGA_EARTH * r[0], v[2]])
    s = np.sqrt(np.sum(vr * vr))
    k = -0.5 * cd * area / mass
    # d a / d v_r = k rho (|v_r| I + v_r v_r^T / |v_r|);  d v_r / d r = -[w x] = [[0, W, 0], [-W, 0, 0], [0, 0, 0]]
    dav = np.empty((3, 3))
    for i in range(3):
        acc[i] += k * rho * s * vr[i]
        d_cd[i] += rho * s * vr[i] * (-0.5 * area / mass)
        for j in range(3):
            dav[i, j] = k * rho * (vr[i] * vr[j] / s + (s if i == j else 0.0))
    for i in range(3):
        for j in range(3):
            grad_v[i, j] += dav[i, j]
            grad_r[i, j] += k * s * vr[i] * drho[j]
        grad_r[i, 0] -= dav[i, 1] * OMEGA_EARTH
        grad_r[i, 1] += dav[i, 0] * OMEGA_EARTH


def _space_weather_rows(d: AtmosphericDrag, lo: float, hi: float):
    """First epoch, step and rows of the space weather every SW_STEP over [lo, hi]; the UTC year's start
    (TDB s) and TT - UTC (s) at lo."""
    if d.atmosphere != "nrlmsise00":
        return 0.0, 1.0, np.zeros((2, 3)), 0.0, 0.0
    n = int(np.ceil((hi - lo) / SW_STEP)) + 2
    t = lo + SW_STEP * np.arange(n)
    utc = tdb_to_utc(lo)
    year = np.datetime64(str(utc.astype("datetime64[Y]")) + "-01-01T00:00:00", "ns")
    tt_utc = float((utc_to_tt(utc) - utc) / np.timedelta64(1, "s"))
    return lo, SW_STEP, d.space_weather.nrlmsise_inputs(t), float(utc_to_tdb(year)), tt_utc


def _ap_history_rows(d: AtmosphericDrag, lo: float, hi: float):
    """TDB of the start of the UT 3-hour interval holding lo, and the Ap history of each interval to hi."""
    if d.atmosphere != "nrlmsise00" or not d.ap_history:
        return 0.0, NO_HISTORY
    hours = tdb_to_utc(lo).astype("datetime64[h]").astype(np.int64)
    t0 = float(utc_to_tdb(np.datetime64(int(hours - hours % 3), "h").astype("datetime64[ns]")))
    n = int(np.ceil((hi - t0) / SW_STEP)) + 1
    return t0, d.space_weather.ap_history(t0 + SW_STEP * (np.arange(n) + 0.5))


def _compile(components, ctx) -> DragData:
    if not components:
        return DragData(False, False, 0.0, 0.0, 0.0, -1, -1, 0.0, 1.0, np.zeros((2, 3)), 0.0, 0.0, 0.0, NO_HISTORY)
    if ctx.center != "earth":
        raise ValueError("atmospheric drag needs an Earth-centred force model")
    d = components[0]
    return DragData(True, d.atmosphere == "nrlmsise00", float(d.cd), float(d.area), float(d.n_bulge), ctx.slot["sun"],
                    int(ctx.rows(["cd"])[0]), *_space_weather_rows(d, ctx.lo, ctx.hi),
                    *_ap_history_rows(d, ctx.lo, ctx.hi))


@kernel(DragData)
def _kernel(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    if not data.on:
        return
    if data.msis:
        rho, drho = nrlmsise_density(t, r, data.sw_t0, data.sw_step, data.sw, data.t_year, data.tt_utc, data.aph_t0,
                                     data.aph)
    else:
        rho, drho = harris_priester(r, env.pos[data.sun_slot], data.n_bulge)
    d_cd = np.zeros(3)
    drag_acceleration(rho, drho, r, v, data.cd, data.area, env.mass, acc, grad_r, grad_v, d_cd)
    if data.cd_row >= 0:
        dadp[data.cd_row] += d_cd


DRAG = Force("drag", (AtmosphericDrag,), _compile, parameters=lambda components: ["cd"] if components else [],
             substitute=lambda components, values: [replace(c, cd=values.get("cd", c.cd)) for c in components],
             bodies=lambda components, center: ["sun"] if components and center != "sun" else [])
