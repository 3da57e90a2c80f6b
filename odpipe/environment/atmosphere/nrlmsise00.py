"""NRLMSISE-00 empirical model of the neutral atmosphere (Picone, Hedin & Drob 2002, JGR 107(A12) 1468).

The model's number densities (He, O, N2, O2, Ar, H, N, anomalous O) and temperatures, from the
ground to the exosphere, as functions of day of year, UT, geodetic altitude, latitude, longitude,
local solar time and solar/geomagnetic activity (F10.7 of the previous day, its 81-day centred
mean, daily Ap or the 7-element Ap history). Written here from the model's definition (the NRL
distribution's GTD7/GTS7/GLOBE7/GLOB7S/DENSU/DENSM structure), its coefficients read from
``nrlmsise00_coefficients.txt`` (numbers only; provenance in that file's header).

Structure:
* thermosphere (above 72.5 km): a Bates temperature profile T(z) = Tinf - (Tinf - Tlb) exp(-s zeta)
  above ~123 km, joined below to a cubic spline in 1/T; each species in diffusive equilibrium with
  its own Bates exponent, blended into the mixed (turbulent) profile below its turbopause, with
  chemistry/flux corrections; every boundary value modulated by the spherical-harmonic expansion G(L)
  (globe7: F10.7, annual/semiannual, diurnal/semi/terdiurnal, Ap, longitude and UT terms);
* mesosphere/stratosphere/troposphere (below 72.5 km): spline temperature profiles and hydrostatic
  N2 with the other species at fixed mixing ratios (globe7's truncated form glob7s).

Units inside are those of the model (cm^-3, g/cm^3, km, K); :func:`gtd7` returns SI
(m^-3, kg/m^3). ``switches`` are the model's 24 flags (1 on, 0 off; switches[9] = -1 selects
the Ap history instead of the daily Ap); index 0 (output units) is ignored.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numba import njit


def _read_coefficients(path: Path) -> dict:
    """Blocks 'name dim [dim]' followed by their values, row-major."""
    blocks, name, shape, values = {}, None, None, []
    for line in path.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        head = line.split()
        if head[0].isidentifier():
            if name is not None:
                blocks[name] = np.array(values, float).reshape(shape)
            name, shape, values = head[0], tuple(int(d) for d in head[1:]), []
        else:
            values.extend(float(v) for v in head)
    blocks[name] = np.array(values, float).reshape(shape)
    return blocks


_C = _read_coefficients(Path(__file__).with_name("nrlmsise00_coefficients.txt"))
PT, PD, PS, PDL, PTM, PDM, PTL, PMA, PAVGM = (_C[k] for k in ("pt", "pd", "ps", "pdl", "ptm", "pdm", "ptl", "pma",
                                                               "pavgm"))

DGTR = 1.74533e-2  # deg -> rad, as the model rounds it
DR = 1.72142e-2  # day -> rad of the year
HR = 0.2618  # hour -> rad of the day
SR = 7.2722e-5  # second -> rad of the day
RGAS = 831.4  # gas constant in the model's units
AMU = 1.66e-24  # g
ZN1 = np.array([PDL[1, 15], 110.0, 100.0, 90.0, 72.5])  # km, lower-thermosphere spline nodes (top: ~123.4 km)
ZN2 = np.array([72.5, 55.0, 45.0, 32.5])  # km, mesosphere/stratosphere nodes
ZN3 = np.array([32.5, 20.0, 15.0, 10.0, 0.0])  # km, stratosphere/troposphere nodes
ZMIX = 62.5  # km, bottom of the transition to full mixing
ALPHA = np.array([-0.38, 0.0, 0.0, 0.0, 0.17, 0.0, -0.38, 0.0, 0.0])  # thermal diffusion, by species slot
ALTL = np.array([200.0, 300.0, 160.0, 250.0, 240.0, 450.0, 320.0, 450.0])  # km, top of the mixing correction
SW_ON = np.ones(24)  # every switch on, daily Ap
SW_HISTORY = SW_ON.copy()
SW_HISTORY[9] = -1.0  # every switch on, the Ap history instead of the daily Ap


@njit(cache=True)
def _gravity(lat_deg):
    """Surface gravity (cm/s^2) and effective Earth radius (km) at a latitude (glatf)."""
    c2 = np.cos(2.0 * DGTR * lat_deg)
    g = 980.616 * (1.0 - 0.0026373 * c2)
    return g, 2.0 * g / (3.085462e-6 + 2.27e-9 * c2) * 1.0e-5


@njit(cache=True)
def _legendre(lat_deg):
    """Associated Legendre functions P_n^m(sin lat), (4, 9): m rows, n columns."""
    c = np.sin(lat_deg * DGTR)
    s = np.cos(lat_deg * DGTR)
    c2, s2 = c * c, s * s
    c4 = c2 * c2
    p = np.zeros((4, 9))
    p[0, 1] = c
    p[0, 2] = 0.5 * (3.0 * c2 - 1.0)
    p[0, 3] = 0.5 * (5.0 * c * c2 - 3.0 * c)
    p[0, 4] = (35.0 * c4 - 30.0 * c2 + 3.0) / 8.0
    p[0, 5] = (63.0 * c2 * c2 * c - 70.0 * c2 * c + 15.0 * c) / 8.0
    p[0, 6] = (11.0 * c * p[0, 5] - 5.0 * p[0, 4]) / 6.0
    p[1, 1] = s
    p[1, 2] = 3.0 * c * s
    p[1, 3] = 1.5 * (5.0 * c2 - 1.0) * s
    p[1, 4] = 2.5 * (7.0 * c2 * c - 3.0 * c) * s
    p[1, 5] = 1.875 * (21.0 * c4 - 14.0 * c2 + 1.0) * s
    p[1, 6] = (11.0 * c * p[1, 5] - 6.0 * p[1, 4]) / 5.0
    p[2, 2] = 3.0 * s2
    p[2, 3] = 15.0 * s2 * c
    p[2, 4] = 7.5 * (7.0 * c2 - 1.0) * s2
    p[2, 5] = 3.0 * c * p[2, 4] - 2.0 * p[2, 3]
    p[2, 6] = (11.0 * c * p[2, 5] - 7.0 * p[2, 4]) / 4.0
    p[2, 7] = (13.0 * c * p[2, 6] - 8.0 * p[2, 5]) / 5.0
    p[3, 3] = 15.0 * s2 * s
    p[3, 4] = 105.0 * s2 * s * c
    p[3, 5] = (9.0 * c * p[3, 4] - 7.0 * p[3, 3]) / 2.0
    p[3, 6] = (11.0 * c * p[3, 5] - 8.0 * p[3, 4]) / 3.0
    return p


@njit(cache=True)
def _g0(a, p):
    """Ap-history response function (its 3-hourly term)."""
    k = np.sqrt(p[24] * p[24])
    return a - 4.0 + (p[25] - 1.0) * (a - 4.0 + (np.exp(-k * (a - 4.0)) - 1.0) / k)


@njit(cache=True)
def _sg0(ex, p, ap):
    """Ap-history weighted mean of _g0 over the last 57 hours (ap: daily, 4 recent 3-hourly, two 8-h means)."""
    total = 1.0 + (1.0 - ex ** 19) / (1.0 - ex) * np.sqrt(ex)
    recent = _g0(ap[2], p) * ex + _g0(ap[3], p) * ex * ex + _g0(ap[4], p) * ex ** 3
    older = (_g0(ap[5], p) * ex ** 4 + _g0(ap[6], p) * ex ** 12) * (1.0 - ex ** 8) / (1.0 - ex)
    return (_g0(ap[1], p) + recent + older) / total


# the inputs vector x: day of year, UT s, latitude deg, longitude deg, local solar time h, F10.7 81-day mean,
# previous day's F10.7, daily Ap
_DOY, _SEC, _LAT, _LON, _LST, _F107A, _F107, _AP = range(8)


@njit(cache=True)
def _globe7(p, x, aph, plg, sw, swc, state):
    """Variation G(L) of the coefficient set p (globe7); state = [apdf, apt0] is updated for _glob7s."""
    t = np.zeros(15)
    doy, sec, lat, lon, tloc = x[_DOY], x[_SEC], x[_LAT], x[_LON], x[_LST]
    stloc, ctloc = np.sin(HR * tloc), np.cos(HR * tloc)
    s2tloc, c2tloc = np.sin(2.0 * HR * tloc), np.cos(2.0 * HR * tloc)
    s3tloc, c3tloc = np.sin(3.0 * HR * tloc), np.cos(3.0 * HR * tloc)
    cd32 = np.cos(DR * (doy - p[31]))
    cd18 = np.cos(2.0 * DR * (doy - p[17]))
    cd14 = np.cos(DR * (doy - p[13]))
    cd39 = np.cos(2.0 * DR * (doy - p[38]))
    df = x[_F107] - x[_F107A]
    dfa = x[_F107A] - 150.0
    t[0] = p[19] * df * (1.0 + p[59] * dfa) + p[20] * df * df + p[21] * dfa + p[29] * dfa * dfa
    f1 = 1.0 + (p[47] * dfa + p[19] * df + p[20] * df * df) * swc[1]
    f2 = 1.0 + (p[49] * dfa + p[19] * df + p[20] * df * df) * swc[1]
    t[1] = (p[1] * plg[0, 2] + p[2] * plg[0, 4] + p[22] * plg[0, 6]) + p[14] * plg[0, 2] * dfa * swc[1] \
        + p[26] * plg[0, 1]
    t[2] = p[18] * cd32
    t[3] = (p[15] + p[16] * plg[0, 2]) * cd18
    t[4] = f1 * (p[9] * plg[0, 1] + p[10] * plg[0, 3]) * cd14
    t[5] = p[37] * plg[0, 1] * cd39
    if sw[7] != 0.0:
        t71 = p[11] * plg[1, 2] * cd14 * swc[5]
        t72 = p[12] * plg[1, 2] * cd14 * swc[5]
        t[6] = f2 * ((p[3] * plg[1, 1] + p[4] * plg[1, 3] + p[27] * plg[1, 5] + t71) * ctloc
                     + (p[6] * plg[1, 1] + p[7] * plg[1, 3] + p[28] * plg[1, 5] + t72) * stloc)
    if sw[8] != 0.0:
        t81 = (p[23] * plg[2, 3] + p[35] * plg[2, 5]) * cd14 * swc[5]
        t82 = (p[33] * plg[2, 3] + p[36] * plg[2, 5]) * cd14 * swc[5]
        t[7] = f2 * ((p[5] * plg[2, 2] + p[41] * plg[2, 4] + t81) * c2tloc
                     + (p[8] * plg[2, 2] + p[42] * plg[2, 4] + t82) * s2tloc)
    if sw[14] != 0.0:
        t[13] = f2 * ((p[39] * plg[3, 3] + (p[93] * plg[3, 4] + p[46] * plg[3, 6]) * cd14 * swc[5]) * s3tloc
                      + (p[40] * plg[3, 3] + (p[94] * plg[3, 4] + p[48] * plg[3, 6]) * cd14 * swc[5]) * c3tloc)
    history = sw[9] < 0.0
    if history:
        if p[51] != 0.0:
            ex = np.exp(-10800.0 * np.sqrt(p[51] * p[51]) / (1.0 + p[138] * (45.0 - np.sqrt(lat * lat))))
            ex = min(ex, 0.99999)
            q = p.copy()
            q[24] = max(q[24], 1.0e-4)
            state[1] = _sg0(ex, q, aph)
            if sw[9] != 0.0:
                t[8] = state[1] * (p[50] + p[96] * plg[0, 2] + p[54] * plg[0, 4]
                                   + (p[125] * plg[0, 1] + p[126] * plg[0, 3] + p[127] * plg[0, 5]) * cd14 * swc[5]
                                   + (p[128] * plg[1, 1] + p[129] * plg[1, 3] + p[130] * plg[1, 5]) * swc[7]
                                   * np.cos(HR * (tloc - p[131])))
    else:
        apd = x[_AP] - 4.0
        p44 = p[43] if p[43] >= 0.0 else 1.0e-5
        state[0] = apd + (p[44] - 1.0) * (apd + (np.exp(-p44 * apd) - 1.0) / p44)
        if sw[9] != 0.0:
            t[8] = state[0] * (p[32] + p[45] * plg[0, 2] + p[34] * plg[0, 4]
                               + (p[100] * plg[0, 1] + p[101] * plg[0, 3] + p[102] * plg[0, 5]) * cd14 * swc[5]
                               + (p[121] * plg[1, 1] + p[122] * plg[1, 3] + p[123] * plg[1, 5]) * swc[7]
                               * np.cos(HR * (tloc - p[124])))
    if sw[10] != 0.0 and lon > -1000.0:
        cl, sl = np.cos(DGTR * lon), np.sin(DGTR * lon)
        if sw[11] != 0.0:
            t[10] = (1.0 + p[80] * dfa * swc[1]) * (
                (p[64] * plg[1, 2] + p[65] * plg[1, 4] + p[66] * plg[1, 6] + p[103] * plg[1, 1] + p[104] * plg[1, 3]
                 + p[105] * plg[1, 5] + swc[5] * (p[109] * plg[1, 1] + p[110] * plg[1, 3] + p[111] * plg[1, 5]) * cd14)
                * cl
                + (p[90] * plg[1, 2] + p[91] * plg[1, 4] + p[92] * plg[1, 6] + p[106] * plg[1, 1] + p[107] * plg[1, 3]
                   + p[108] * plg[1, 5] + swc[5] * (p[112] * plg[1, 1] + p[113] * plg[1, 3] + p[114] * plg[1, 5])
                   * cd14) * sl)
        if sw[12] != 0.0:
            t[11] = (1.0 + p[95] * plg[0, 1]) * (1.0 + p[81] * dfa * swc[1]) \
                * (1.0 + p[119] * plg[0, 1] * swc[5] * cd14) \
                * ((p[68] * plg[0, 1] + p[69] * plg[0, 3] + p[70] * plg[0, 5]) * np.cos(SR * (sec - p[71])))
            t[11] += swc[11] * (p[76] * plg[2, 3] + p[77] * plg[2, 5] + p[78] * plg[2, 7]) \
                * np.cos(SR * (sec - p[79]) + 2.0 * DGTR * lon) * (1.0 + p[137] * dfa * swc[1])
        if sw[13] != 0.0:
            if history:
                if p[51] != 0.0:
                    a = state[1]
                    t[12] = a * swc[11] * (1.0 + p[132] * plg[0, 1]) \
                        * ((p[52] * plg[1, 2] + p[98] * plg[1, 4] + p[67] * plg[1, 6]) * np.cos(DGTR * (lon - p[97]))) \
                        + a * swc[11] * swc[5] * (p[133] * plg[1, 1] + p[134] * plg[1, 3] + p[135] * plg[1, 5]) \
                        * cd14 * np.cos(DGTR * (lon - p[136])) \
                        + a * swc[12] * (p[55] * plg[0, 1] + p[56] * plg[0, 3] + p[57] * plg[0, 5]) \
                        * np.cos(SR * (sec - p[58]))
            else:
                a = state[0]
                t[12] = a * swc[11] * (1.0 + p[120] * plg[0, 1]) \
                    * ((p[60] * plg[1, 2] + p[61] * plg[1, 4] + p[62] * plg[1, 6]) * np.cos(DGTR * (lon - p[63]))) \
                    + a * swc[11] * swc[5] * (p[115] * plg[1, 1] + p[116] * plg[1, 3] + p[117] * plg[1, 5]) \
                    * cd14 * np.cos(DGTR * (lon - p[118])) \
                    + a * swc[12] * (p[83] * plg[0, 1] + p[84] * plg[0, 3] + p[85] * plg[0, 5]) \
                    * np.cos(SR * (sec - p[75]))
    g = p[30]
    for i in range(14):
        g += abs(sw[i + 1]) * t[i]
    return g


@njit(cache=True)
def _glob7s(p, x, plg, sw, swc, state):
    """Truncated expansion for the lower atmosphere (glob7s), with state's Ap terms from the last _globe7."""
    t = np.zeros(14)
    doy, lon, tloc = x[_DOY], x[_LON], x[_LST]
    cd32 = np.cos(DR * (doy - p[31]))
    cd18 = np.cos(2.0 * DR * (doy - p[17]))
    cd14 = np.cos(DR * (doy - p[13]))
    cd39 = np.cos(2.0 * DR * (doy - p[38]))
    dfa = x[_F107A] - 150.0
    t[0] = p[21] * dfa
    t[1] = p[1] * plg[0, 2] + p[2] * plg[0, 4] + p[22] * plg[0, 6] + p[26] * plg[0, 1] + p[14] * plg[0, 3] \
        + p[59] * plg[0, 5]
    t[2] = (p[18] + p[47] * plg[0, 2] + p[29] * plg[0, 4]) * cd32
    t[3] = (p[15] + p[16] * plg[0, 2] + p[30] * plg[0, 4]) * cd18
    t[4] = (p[9] * plg[0, 1] + p[10] * plg[0, 3] + p[20] * plg[0, 5]) * cd14
    t[5] = p[37] * plg[0, 1] * cd39
    if sw[7] != 0.0:
        t71 = p[11] * plg[1, 2] * cd14 * swc[5]
        t72 = p[12] * plg[1, 2] * cd14 * swc[5]
        t[6] = (p[3] * plg[1, 1] + p[4] * plg[1, 3] + t71) * np.cos(HR * tloc) \
            + (p[6] * plg[1, 1] + p[7] * plg[1, 3] + t72) * np.sin(HR * tloc)
    if sw[8] != 0.0:
        t81 = (p[23] * plg[2, 3] + p[35] * plg[2, 5]) * cd14 * swc[5]
        t82 = (p[33] * plg[2, 3] + p[36] * plg[2, 5]) * cd14 * swc[5]
        t[7] = (p[5] * plg[2, 2] + p[41] * plg[2, 4] + t81) * np.cos(2.0 * HR * tloc) \
            + (p[8] * plg[2, 2] + p[42] * plg[2, 4] + t82) * np.sin(2.0 * HR * tloc)
    if sw[14] != 0.0:
        t[13] = p[39] * plg[3, 3] * np.sin(3.0 * HR * tloc) + p[40] * plg[3, 3] * np.cos(3.0 * HR * tloc)
    if sw[9] == 1.0:
        t[8] = state[0] * (p[32] + p[45] * plg[0, 2] * swc[2])
    elif sw[9] == -1.0:
        t[8] = p[50] * state[1] + p[96] * plg[0, 2] * state[1] * swc[2]
    if not (sw[10] == 0.0 or sw[11] == 0.0 or lon <= -1000.0):
        t[10] = (1.0 + plg[0, 1] * (p[80] * swc[5] * np.cos(DR * (doy - p[81]))
                                    + p[85] * swc[6] * np.cos(2.0 * DR * (doy - p[86])))
                 + p[83] * swc[3] * np.cos(DR * (doy - p[84])) + p[87] * swc[4] * np.cos(2.0 * DR * (doy - p[88]))) \
            * ((p[64] * plg[1, 2] + p[65] * plg[1, 4] + p[66] * plg[1, 6] + p[74] * plg[1, 1] + p[75] * plg[1, 3]
                + p[76] * plg[1, 5]) * np.cos(DGTR * lon)
               + (p[90] * plg[1, 2] + p[91] * plg[1, 4] + p[92] * plg[1, 6] + p[77] * plg[1, 1] + p[78] * plg[1, 3]
                  + p[79] * plg[1, 5]) * np.sin(DGTR * lon))
    g = 0.0
    for i in range(14):
        g += abs(sw[i + 1]) * t[i]
    return g


@njit(cache=True)
def _spline(x, y, yp1, ypn):
    """Second derivatives of the cubic spline through (x, y) with end slopes yp1, ypn (>= 1e30: natural)."""
    n = x.shape[0]
    y2 = np.zeros(n)
    u = np.zeros(n)
    if yp1 <= 0.99e30:
        y2[0] = -0.5
        u[0] = 3.0 / (x[1] - x[0]) * ((y[1] - y[0]) / (x[1] - x[0]) - yp1)
    for i in range(1, n - 1):
        sig = (x[i] - x[i - 1]) / (x[i + 1] - x[i - 1])
        q = sig * y2[i - 1] + 2.0
        y2[i] = (sig - 1.0) / q
        u[i] = (6.0 * ((y[i + 1] - y[i]) / (x[i + 1] - x[i]) - (y[i] - y[i - 1]) / (x[i] - x[i - 1]))
                / (x[i + 1] - x[i - 1]) - sig * u[i - 1]) / q
    qn, un = 0.0, 0.0
    if ypn <= 0.99e30:
        qn = 0.5
        un = 3.0 / (x[n - 1] - x[n - 2]) * (ypn - (y[n - 1] - y[n - 2]) / (x[n - 1] - x[n - 2]))
    y2[n - 1] = (un - qn * u[n - 2]) / (qn * y2[n - 2] + 1.0)
    for k in range(n - 2, -1, -1):
        y2[k] = y2[k] * y2[k + 1] + u[k]
    return y2


@njit(cache=True)
def _splint(xa, ya, y2a, x):
    """Cubic-spline value at x."""
    lo, hi = 0, xa.shape[0] - 1
    while hi - lo > 1:
        k = (hi + lo) // 2
        if xa[k] > x:
            hi = k
        else:
            lo = k
    h = xa[hi] - xa[lo]
    a = (xa[hi] - x) / h
    b = (x - xa[lo]) / h
    return a * ya[lo] + b * ya[hi] + ((a ** 3 - a) * y2a[lo] + (b ** 3 - b) * y2a[hi]) * h * h / 6.0


@njit(cache=True)
def _splini(xa, ya, y2a, x):
    """Integral of the cubic spline from xa[0] to x."""
    n = xa.shape[0]
    total = 0.0
    lo = 0
    while lo < n - 1 and x > xa[lo]:
        hi = lo + 1
        xx = min(x, xa[hi]) if hi < n - 1 else x
        h = xa[hi] - xa[lo]
        a = (xa[hi] - xx) / h
        b = (xx - xa[lo]) / h
        a2, b2 = a * a, b * b
        curvature = (-(1.0 + a2 * a2) / 4.0 + a2 / 2.0) * y2a[lo] + (b2 * b2 / 4.0 - b2 / 2.0) * y2a[hi]
        total += ((1.0 - a2) * ya[lo] / 2.0 + b2 * ya[hi] / 2.0 + curvature * h * h / 6.0) * h
        lo += 1
    return total


@njit(cache=True)
def _zeta(z, zl, re):
    """Geopotential height difference (km) of z above zl."""
    return (z - zl) * (re + zl) / (re + z)


@njit(cache=True)
def _ccor(z, r, h1, zh):
    """Chemistry/dissociation correction factor exp(r / (1 + exp((z - zh)/h1)))."""
    e = (z - zh) / h1
    if e > 70.0:
        return 1.0
    if e < -70.0:
        return np.exp(r)
    return np.exp(r / (1.0 + np.exp(e)))


@njit(cache=True)
def _ccor2(z, r, h1, zh, h2):
    """Correction factor with two scale heights."""
    e1 = (z - zh) / h1
    e2 = (z - zh) / h2
    if e1 > 70.0 or e2 > 70.0:
        return 1.0
    if e1 < -70.0 and e2 < -70.0:
        return np.exp(r)
    return np.exp(r / (1.0 + 0.5 * (np.exp(e1) + np.exp(e2))))


@njit(cache=True)
def _dnet(dd, dm, zhm, xmm, xm):
    """Blend of the diffusive density dd and the mixed density dm (turbopause scale zhm)."""
    a = zhm / (xmm - xm)
    if not (dm > 0.0 and dd > 0.0):
        if dd == 0.0 and dm == 0.0:
            dd = 1.0
        if dm == 0.0:
            return dd
        if dd == 0.0:
            return dm
    ylog = a * np.log(dm / dd)
    if ylog < -10.0:
        return dd
    if ylog > 10.0:
        return dm
    return dd * (1.0 + np.exp(ylog)) ** (1.0 / a)


@njit(cache=True)
def _profile(z, zn, tn, tgn, grav):
    """Spline of 1/T over the nodes zn (temperatures tn, end gradients tgn): nodes, values, 2nd derivatives, x."""
    gsurf, re = grav
    n = zn.shape[0]
    z1, z2 = zn[0], zn[n - 1]
    zgdif = _zeta(z2, z1, re)
    xs = np.empty(n)
    ys = np.empty(n)
    for k in range(n):
        xs[k] = _zeta(zn[k], z1, re) / zgdif
        ys[k] = 1.0 / tn[k]
    yd1 = -tgn[0] / (tn[0] * tn[0]) * zgdif
    yd2 = -tgn[1] / (tn[n - 1] * tn[n - 1]) * zgdif * ((re + z2) / (re + z1)) ** 2
    y2 = _spline(xs, ys, yd1, yd2)
    return xs, ys, y2, _zeta(z, z1, re) / zgdif, zgdif


@njit(cache=True)
def _densu(alt, dlb, tinf, tlb, xm, alpha, zlb, s2, tn1, tgn1, grav):
    """Density (dlb at zlb) and temperature at alt for molecular mass xm (xm = 0: temperature only).

    Bates profile above ZN1[0]; below, the 1/T spline through tn1 (tn1[0], tgn1[0] set here from the
    Bates profile at ZN1[0])."""
    gsurf, re = grav
    za = ZN1[0]
    z = max(alt, za)
    zg2 = _zeta(z, zlb, re)
    tt = tinf - (tinf - tlb) * np.exp(-s2 * zg2)
    tz = tt
    if alt < za:
        tgn1[0] = (tinf - tt) * s2 * ((re + zlb) / (re + za)) ** 2
        tn1[0] = tt
        xs, ys, y2, x, zgdif = _profile(max(alt, ZN1[-1]), ZN1, tn1, tgn1, grav)
        tz = 1.0 / _splint(xs, ys, y2, x)
    if xm == 0.0:
        return tz, tz
    glb = gsurf / (1.0 + zlb / re) ** 2
    gamma = xm * glb / (s2 * RGAS * tinf)
    expl = np.exp(-s2 * gamma * zg2)
    if expl > 50.0 or tt <= 0.0:
        expl = 50.0
    dens = dlb * (tlb / tt) ** (1.0 + alpha + gamma) * expl
    if alt >= za:
        return dens, tz
    glb = gsurf / (1.0 + za / re) ** 2
    expl = xm * glb * zgdif / RGAS * _splini(xs, ys, y2, x)
    if expl > 50.0 or tz <= 0.0:
        expl = 50.0
    return dens * (tn1[0] / tz) ** (1.0 + alpha) * np.exp(-expl), tz


@njit(cache=True)
def _densm(alt, d0, xm, tn2, tgn2, tn3, tgn3, grav):
    """Density (d0 at ZN2[0]) and temperature at alt below ZN2[0] (xm = 0: temperature only)."""
    gsurf, re = grav
    dens = d0
    tz = 0.0
    for zn, tn, tgn, top in ((ZN2, tn2, tgn2, True), (ZN3, tn3, tgn3, False)):
        if not top and alt > ZN3[0]:
            break
        xs, ys, y2, x, zgdif = _profile(max(alt, zn[-1]), zn, tn, tgn, grav)
        tz = 1.0 / _splint(xs, ys, y2, x)
        if xm != 0.0:
            glb = gsurf / (1.0 + zn[0] / re) ** 2
            expl = min(xm * glb * zgdif / RGAS * _splini(xs, ys, y2, x), 50.0)
            dens = dens * (tn[0] / tz) * np.exp(-expl)
    return dens, tz


@njit(cache=True)
def _species(z, db, xm, alpha, alpha_mixed, zh, zhm, mixing, tinf, tlb, s, tn1, tgn1, grav):
    """Diffusive density at z from db at the lower boundary, blended with the mixed profile below the
    turbopause zh when ``mixing``; and the mixed density b at zh (the ground mixing-ratio reference)."""
    zlb = PTM[5]
    xmm = PDM[2, 4]
    d = _densu(z, db, tinf, tlb, xm, alpha, zlb, s, tn1, tgn1, grav)[0]
    b = 0.0
    if mixing:
        b = _densu(zh, db, tinf, tlb, xm - xmm, alpha - 1.0, zlb, s, tn1, tgn1, grav)[0]
        dm = _densu(z, b, tinf, tlb, xmm, alpha_mixed, zlb, s, tn1, tgn1, grav)[0]
        d = _dnet(d, dm, zhm, xmm, xm)
    return d, b


@njit(cache=True)
def _gts7(z, x, aph, plg, sw, swc, grav, state):
    """Thermosphere (z >= 72.5 km): densities (9, cm^-3 and g/cm^3 in slot 5, anomalous O excluded),
    Tinf, T(z), the lower-thermosphere spline temperatures tn1 and gradients tgn1, the mixed N2 density."""
    lat, doy, f107a = x[_LAT], x[_DOY], x[_F107A]
    tn1 = np.zeros(5)
    tgn1 = np.zeros(2)
    d = np.zeros(9)
    tinf = PTM[0] * PT[0]
    if z > ZN1[0]:
        tinf *= 1.0 + sw[16] * _globe7(PT, x, aph, plg, sw, swc, state)
    g0 = PTM[3] * PS[0]
    if z > ZN1[4]:
        g0 *= 1.0 + sw[19] * _globe7(PS, x, aph, plg, sw, swc, state)
    tlb = PTM[1] * (1.0 + sw[17] * _globe7(PD[3], x, aph, plg, sw, swc, state)) * PD[3, 0]
    s = g0 / (tinf - tlb)
    # lower-thermosphere temperature nodes (their variations matter below 300 km only)
    low = sw[18] if z < 300.0 else 0.0
    for k, m in ((1, 6), (2, 2), (3, 7)):
        tn1[k] = PTM[m] * PTL[k - 1, 0] / (1.0 - low * _glob7s(PTL[k - 1], x, plg, sw, swc, state))
    tn1[4] = PTM[4] * PTL[3, 0] / (1.0 - low * sw[20] * _glob7s(PTL[3], x, plg, sw, swc, state))
    tgn1[1] = PTM[8] * PMA[8, 0] * (1.0 + low * sw[20] * _glob7s(PMA[8], x, plg, sw, swc, state)) \
        * tn1[4] * tn1[4] / (PTM[4] * PTL[3, 0]) ** 2
    zhf = PDL[1, 24] * (1.0 + sw[5] * PDL[0, 24] * np.sin(DGTR * lat) * np.cos(DR * (doy - PT[13])))
    mix = sw[15] != 0.0
    zhm = PDM[2, 3] * PDL[1, 5]
    xmm = PDM[2, 4]
    # N2: its mixed profile keeps the thermal-diffusion exponent, and its turbopause moves
    db28 = PDM[2, 0] * np.exp(sw[21] * _globe7(PD[2], x, aph, plg, sw, swc, state)) * PD[2, 0]
    d[2] = _densu(z, db28, tinf, tlb, 28.0, ALPHA[2], PTM[5], s, tn1, tgn1, grav)[0]
    b28 = _densu(PDM[2, 2] * zhf, db28, tinf, tlb, 28.0 - xmm, ALPHA[2] - 1.0, PTM[5], s, tn1, tgn1, grav)[0]
    dm28 = 0.0
    if mix and z <= ALTL[2]:
        dm28 = _densu(z, b28, tinf, tlb, xmm, ALPHA[2], PTM[5], s, tn1, tgn1, grav)[0]
        d[2] = _dnet(d[2], dm28, zhm, xmm, 28.0)
    # He
    db04 = PDM[0, 0] * np.exp(sw[21] * _globe7(PD[0], x, aph, plg, sw, swc, state)) * PD[0, 0]
    m = mix and z < ALTL[0]
    d[0], b04 = _species(z, db04, 4.0, ALPHA[0], 0.0, PDM[0, 2], zhm, m, tinf, tlb, s, tn1, tgn1, grav)
    if m:
        d[0] *= _ccor(z, np.log(b28 * PDM[0, 1] / b04), PDM[0, 5] * PDL[1, 1], PDM[0, 4] * PDL[1, 0])
    # O
    db16 = PDM[1, 0] * np.exp(sw[21] * _globe7(PD[1], x, aph, plg, sw, swc, state)) * PD[1, 0]
    m = mix and z <= ALTL[1]
    d[1] = _species(z, db16, 16.0, ALPHA[1], 0.0, PDM[1, 2], zhm, m, tinf, tlb, s, tn1, tgn1, grav)[0]
    if m:
        rl = PDM[1, 1] * PDL[1, 16] * (1.0 + sw[1] * PDL[0, 23] * (f107a - 150.0))
        d[1] *= _ccor2(z, rl, PDM[1, 5] * PDL[1, 3], PDM[1, 4] * PDL[1, 2], PDM[1, 5] * PDL[1, 4])
        d[1] *= _ccor(z, PDM[1, 3] * PDL[1, 14], PDM[1, 7] * PDL[1, 13], PDM[1, 6] * PDL[1, 12])
    # O2
    db32 = PDM[3, 0] * np.exp(sw[21] * _globe7(PD[4], x, aph, plg, sw, swc, state)) * PD[4, 0]
    m = mix and z <= ALTL[3]
    d[3], b32 = _species(z, db32, 32.0, ALPHA[3], 0.0, PDM[3, 2], zhm, m, tinf, tlb, s, tn1, tgn1, grav)
    if m:
        d[3] *= _ccor(z, np.log(b28 * PDM[3, 1] / b32), PDM[3, 5] * PDL[1, 7], PDM[3, 4] * PDL[1, 6])
    if mix:
        rc32 = PDM[3, 3] * PDL[1, 23] * (1.0 + sw[1] * PDL[0, 23] * (f107a - 150.0))
        d[3] *= _ccor2(z, rc32, PDM[3, 7] * PDL[1, 22], PDM[3, 6] * PDL[1, 21], PDM[3, 7] * PDL[0, 22])
    # Ar
    db40 = PDM[4, 0] * np.exp(sw[21] * _globe7(PD[5], x, aph, plg, sw, swc, state)) * PD[5, 0]
    m = mix and z <= ALTL[4]
    d[4], b40 = _species(z, db40, 40.0, ALPHA[4], 0.0, PDM[4, 2], zhm, m, tinf, tlb, s, tn1, tgn1, grav)
    if m:
        d[4] *= _ccor(z, np.log(b28 * PDM[4, 1] / b40), PDM[4, 5] * PDL[1, 9], PDM[4, 4] * PDL[1, 8])
    # H
    db01 = PDM[5, 0] * np.exp(sw[21] * _globe7(PD[6], x, aph, plg, sw, swc, state)) * PD[6, 0]
    m = mix and z <= ALTL[6]
    d[6], b01 = _species(z, db01, 1.0, ALPHA[6], 0.0, PDM[5, 2], zhm, m, tinf, tlb, s, tn1, tgn1, grav)
    if m:
        rl = np.log(b28 * PDM[5, 1] * abs(PDL[1, 17]) / b01)
        d[6] *= _ccor(z, rl, PDM[5, 5] * PDL[1, 11], PDM[5, 4] * PDL[1, 10])
        d[6] *= _ccor(z, PDM[5, 3] * PDL[1, 20], PDM[5, 7] * PDL[1, 19], PDM[5, 6] * PDL[1, 18])
    # N
    db14 = PDM[6, 0] * np.exp(sw[21] * _globe7(PD[7], x, aph, plg, sw, swc, state)) * PD[7, 0]
    m = mix and z <= ALTL[7]
    d[7], b14 = _species(z, db14, 14.0, ALPHA[7], 0.0, PDM[6, 2], zhm, m, tinf, tlb, s, tn1, tgn1, grav)
    if m:
        rl = np.log(b28 * PDM[6, 1] * abs(PDL[0, 2]) / b14)
        d[7] *= _ccor(z, rl, PDM[6, 5] * PDL[0, 1], PDM[6, 4] * PDL[0, 0])
        d[7] *= _ccor(z, PDM[6, 3] * PDL[0, 5], PDM[6, 7] * PDL[0, 4], PDM[6, 6] * PDL[0, 3])
    # anomalous O: an isothermal profile at tho, decaying above zmho with the scale zsht
    db16h = PDM[7, 0] * np.exp(sw[21] * _globe7(PD[8], x, aph, plg, sw, swc, state)) * PD[8, 0]
    tho = PDM[7, 9] * PDL[0, 6]
    dd = _densu(z, db16h, tho, tho, 16.0, ALPHA[8], PTM[5], s, tn1, tgn1, grav)[0]
    zsht, zmho = PDM[7, 5], PDM[7, 4]
    gsurf, re = grav
    zsho = RGAS * tho / (gsurf / (1.0 + zmho / re) ** 2 * 16.0)
    d[8] = dd * np.exp(-zsht / zsho * (np.exp(-(z - zmho) / zsht) - 1.0))
    d[5] = AMU * (4.0 * d[0] + 16.0 * d[1] + 28.0 * d[2] + 32.0 * d[3] + 40.0 * d[4] + d[6] + 14.0 * d[7])
    tz = _densu(abs(z), 1.0, tinf, tlb, 0.0, 0.0, PTM[5], s, tn1, tgn1, grav)[1]
    return d, tinf, tz, tn1, tgn1, dm28


@njit(cache=True)
def _gtd7(x, alt, aph, sw, swc):
    """Densities (9, cgs; slot 5 the mass density without anomalous O), Tinf and T(alt) (K)."""
    grav = _gravity(x[_LAT] if sw[2] != 0.0 else 45.0)
    plg = _legendre(x[_LAT])
    state = np.zeros(2)
    d, tinf, tz, tn1, tgn1, dm28 = _gts7(max(alt, ZN2[0]), x, aph, plg, sw, swc, grav, state)
    if alt >= ZN2[0]:
        return d, tinf, tz
    # mesosphere and below: spline temperatures from glob7s, N2 hydrostatic, others at ground ratios
    tn2 = np.zeros(4)
    tgn2 = np.zeros(2)
    tn3 = np.zeros(5)
    tgn3 = np.zeros(2)
    tgn2[0] = tgn1[1]
    tn2[0] = tn1[4]
    tn2[1] = PMA[0, 0] * PAVGM[0] / (1.0 - sw[20] * _glob7s(PMA[0], x, plg, sw, swc, state))
    tn2[2] = PMA[1, 0] * PAVGM[1] / (1.0 - sw[20] * _glob7s(PMA[1], x, plg, sw, swc, state))
    tn2[3] = PMA[2, 0] * PAVGM[2] / (1.0 - sw[20] * sw[22] * _glob7s(PMA[2], x, plg, sw, swc, state))
    tgn2[1] = PAVGM[8] * PMA[9, 0] * (1.0 + sw[20] * sw[22] * _glob7s(PMA[9], x, plg, sw, swc, state)) \
        * tn2[3] * tn2[3] / (PMA[2, 0] * PAVGM[2]) ** 2
    tn3[0] = tn2[3]
    if alt < ZN3[0]:
        tgn3[0] = tgn2[1]
        for k in range(1, 5):
            tn3[k] = PMA[k + 2, 0] * PAVGM[k + 2] / (1.0 - sw[22] * _glob7s(PMA[k + 2], x, plg, sw, swc, state))
        tgn3[1] = PMA[7, 0] * PAVGM[7] * (1.0 + sw[22] * _glob7s(PMA[7], x, plg, sw, swc, state)) \
            * tn3[4] * tn3[4] / (PMA[6, 0] * PAVGM[6]) ** 2
    dmc = 1.0 - (ZN2[0] - alt) / (ZN2[0] - ZMIX) if alt > ZMIX else 0.0
    out = np.zeros(9)
    dz28 = d[2]
    n2, tz = _densm(alt, dm28, PDM[2, 4], tn2, tgn2, tn3, tgn3, grav)
    out[2] = n2 * (1.0 + (d[2] / dm28 - 1.0) * dmc)
    for slot, row in ((0, 0), (3, 3), (4, 4)):
        out[slot] = out[2] * PDM[row, 1] * (1.0 + (d[slot] / (dz28 * PDM[row, 1]) - 1.0) * dmc)
    out[5] = AMU * (4.0 * out[0] + 32.0 * out[3] + 28.0 * out[2] + 40.0 * out[4])
    return out, tinf, tz


def gtd7(doy, sec, alt_km, lat_deg, lon_deg, lst_h, f107a, f107, ap, ap_history=None, switches=None):
    """NRLMSISE-00 at one point: (densities, temperatures).

    densities (9,): He, O, N2, O2, Ar (m^-3), total mass (kg/m^3, anomalous O excluded as the
    model's GTD7), H, N, anomalous O (m^-3); temperatures (2,): exospheric and at alt_km (K).
    doy day of year, sec UT seconds of day, lst_h local solar time (h), f107 the previous day's
    F10.7, f107a its 81-day mean, ap the daily Ap; ap_history (7,) when switches[9] = -1."""
    sw_in = SW_ON if switches is None else np.asarray(switches, float)
    sw = np.where(sw_in == 1.0, 1.0, 0.0)
    swc = np.where(sw_in > 0.0, 1.0, 0.0)
    sw[9] = swc[9] = sw_in[9]
    x = np.array([doy, sec, lat_deg, lon_deg, lst_h, f107a, f107, ap], float)
    aph = np.zeros(7) if ap_history is None else np.asarray(ap_history, float)
    d, tinf, tz = _gtd7(x, float(alt_km), aph, sw, swc)
    si = d * 1.0e6
    si[5] = d[5] * 1.0e3
    return si, np.array([tinf, tz])


@njit(cache=True)
def mass_density(x, alt_km, aph):
    """Total mass density (kg/m^3) including anomalous oxygen (the model's GTD7D, the one for drag),
    all switches on; x = [doy, UT s, lat deg, lon deg, local solar time h, F10.7 81-day mean,
    previous day's F10.7, daily Ap]; with an Ap history aph (7,) (switch 9 = -1) unless aph[0] is NaN."""
    sw = SW_ON if np.isnan(aph[0]) else SW_HISTORY
    d = _gtd7(x, alt_km, aph, sw, sw)[0]
    return AMU * (4.0 * d[0] + 16.0 * (d[1] + d[8]) + 28.0 * d[2] + 32.0 * d[3] + 40.0 * d[4] + d[6]
                  + 14.0 * d[7]) * 1.0e3
