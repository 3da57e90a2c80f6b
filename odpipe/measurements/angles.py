"""Antenna angles of a spacecraft seen from a station at reception: azimuth/elevation and X/Y.

The direction is the light-time-corrected one, d = r_sc(t2) - r_station(t3)
(path ``[spacecraft, station]``, receive-anchored), turned to the station's
east-north-up axes through ITRS at t3 (geodetic latitude/longitude, WGS84).
Azimuth from north through east in [0, 2 pi), elevation above the horizon;
X/Y are the CCSDS ``XEYN`` pair: X = atan2(east, up), Y = asin(north / |d|).
Aberration is not modelled; refraction of the elevation is :mod:`.refraction`,
applied by :func:`.compute.compute` when the setup asks for it. Partials include
the motion of the spacecraft over the change of light time: dd/dr_sc = I - v_sc g^T,
with g = d tau / d r_sc. Station partials also turn the local axes: d lat = d north/(M + h), d lon =
d east/((N + h) cos lat) on the WGS84 ellipsoid (M, N its radii of curvature).
"""

from __future__ import annotations

import numpy as np

from odpipe.constants import WGS84_A, WGS84_F
from odpipe.environment.stations import enu_matrix, itrs_to_geodetic

from .computed import Computed, EventPartial

KINDS = ("azimuth", "elevation", "x", "y")


def _axes_turn(lat, lon, h, d_itrs):
    """d(ENU components of the fixed ITRS vector d)/d(station ITRS position), (N,3,3)."""
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    z = np.zeros_like(sl)
    east = np.stack([-so, co, z], -1)
    north = np.stack([-sl * co, -sl * so, cl], -1)
    up = np.stack([cl * co, cl * so, sl], -1)
    e2 = WGS84_F * (2 - WGS84_F)
    w = np.sqrt(1 - e2 * sl**2)
    m_rad, n_rad = WGS84_A * (1 - e2) / w**3 + h, WGS84_A / w + h
    dot = lambda a: np.einsum("ni,ni->n", a, d_itrs)  # noqa: E731
    dw_dlat = np.stack([z, -dot(up), dot(north)], -1)
    dw_dlon = np.stack([dot(sl[:, None] * north - cl[:, None] * up), -sl * dot(east), cl * dot(east)], -1)
    return (np.einsum("ni,nj->nij", dw_dlat, north / m_rad[:, None])
            + np.einsum("ni,nj->nij", dw_dlon, east / (n_rad * cl)[:, None]))


def antenna_angle(sol, station_node, kind: str) -> Computed:
    """Angle ``kind`` (rad) of receive-anchored [spacecraft, station] solutions; parameter 'bias' (rad)."""
    if kind not in KINDS:
        raise ValueError(f"angle kind must be one of {KINDS}, not {kind!r}")
    t3 = sol.epochs[:, 1]
    rot = np.swapaxes(station_node.itrs_to_frame(t3), 1, 2)  # frame -> ITRS
    lat, lon, hgt = itrs_to_geodetic(station_node.itrs(t3))
    m = np.einsum("nij,njk->nik", enu_matrix(lat, lon), rot)  # frame -> ENU
    d = sol.states[:, 0, :3] - sol.states[:, 1, :3]
    w = np.einsum("nij,nj->ni", m, d)
    e, n, u = w[:, 0], w[:, 1], w[:, 2]
    rho = np.linalg.norm(w, axis=1)
    zero = np.zeros_like(e)
    if kind == "azimuth":
        value = np.mod(np.arctan2(e, n), 2 * np.pi)
        dw = np.stack([n, -e, zero], 1) / (e**2 + n**2)[:, None]
    elif kind == "x":
        value = np.arctan2(e, u)
        dw = np.stack([u, zero, -e], 1) / (e**2 + u**2)[:, None]
    else:
        axis = 2 if kind == "elevation" else 1
        value = np.arcsin(w[:, axis] / rho)
        unit = np.zeros_like(w)
        unit[:, axis] = 1.0
        dw = (unit / rho[:, None] - w[:, axis, None] * w / rho[:, None] ** 3) / np.cos(value)[:, None]
    dd = np.einsum("ni,nij->nj", dw, m)  # d angle / d d (frame)
    v_sc = sol.states[:, 0, 3:]
    g_sc, g_st = sol.dlt_dr[:, 0], sol.dlt_dr[:, 1]
    k = np.einsum("ni,ni->n", dd, v_sc)  # d angle / d t2
    # turning of the local axes, mapped back to the solve frame (station partials are taken in ITRS later)
    turn = np.einsum("ni,nij,njk->nk", dw, _axes_turn(lat, lon, hgt, np.einsum("nij,nj->ni", rot, d)), rot)
    events = [EventPartial("spacecraft", sol.epochs[:, 0], dd - k[:, None] * g_sc),
              EventPartial("station_rx", t3, -dd - k[:, None] * g_st + turn)]
    return Computed(value, "rad", events, {"bias": np.ones_like(value)}, to_los=rho)
