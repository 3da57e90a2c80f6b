"""GCRS ↔ ITRS: IAU 2006/2000A, CIO based (IERS Conventions 2010 ch. 5), via ERFA.

``GCRS→ITRS = W(xp, yp, s') · R3(ERA) · C(X+dX, Y+dY, s)``. X, Y, s come from
the full IAU 2006/2000A series (``erfa.xy06``, ``erfa.s06``); for many epochs
they are evaluated on a 1-hour grid and interpolated with cubic Lagrange
polynomials (error < 1e-13 rad, verified in tests/test_frames_earth.py).
EOP (UT1−UTC, xp, yp, dX, dY, LOD) default to :func:`odpipe.environment.eop.eop_at`.

Epochs ``t``: datetime64 UTC, or float TDB seconds past J2000. Matrices are
(N,3,3) for N epochs ((3,3) for a scalar epoch); vectors in m and m/s.
"""

from __future__ import annotations

from dataclasses import dataclass

import erfa
import numpy as np

from odpipe.environment.eop import EOPValues, eop_at
from odpipe.numerics.interpolation import on_uniform_grid
from odpipe.frames.epochs import utc_and_tt
from odpipe.frames.rotations import frame_rotation
from odpipe.constants import ERA_RATE, J2000_JD, J2000_NS, NS_PER_DAY, SECONDS_PER_DAY
from parsers.leap_seconds import tai_minus_utc_ns

CIP_GRID_STEP_DAYS = 1.0 / 24.0
_CIP_GRID_MIN_EPOCHS = 200


@dataclass(frozen=True)
class EarthRotation:
    """The three factors of GCRS→ITRS: ``rpom @ R3(era) @ rc2i``, Earth's rotation rate ``omega`` (rad/s)
    and, when asked for, the time derivatives (1/s) of ``rc2i`` and ``rpom`` (None when not known)."""

    rc2i: np.ndarray
    era: np.ndarray
    rpom: np.ndarray
    omega: np.ndarray
    rc2i_rate: np.ndarray | None = None
    rpom_rate: np.ndarray | None = None

    @property
    def gcrs_to_itrs(self) -> np.ndarray:
        return erfa.c2tcio(self.rc2i, self.era, self.rpom)


def _cip_xys_direct(tt_days: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x, y = erfa.xy06(J2000_JD, tt_days)
    return x, y, erfa.s06(J2000_JD, tt_days, x, y)


def cip_xys(tt_days) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """CIP X, Y and CIO locator s (rad) of IAU 2006/2000A at TT days past J2000 (no dX/dY)."""
    v = on_uniform_grid(lambda d: np.stack(_cip_xys_direct(d), axis=-1), tt_days, CIP_GRID_STEP_DAYS,
                        _CIP_GRID_MIN_EPOCHS)
    return v[..., 0], v[..., 1], v[..., 2]


def _rc2i(tt_days, dx, dy) -> np.ndarray:
    x, y, s = cip_xys(tt_days)
    x = x + dx
    y = y + dy
    s = erfa.s06(J2000_JD, tt_days, x, y) if np.size(tt_days) < _CIP_GRID_MIN_EPOCHS else s
    return erfa.c2ixys(x, y, s)


_RATE_STEP_DAYS = 1.0 / 24.0  # central difference over ±1 h: rate error < 1e-3 relative (shortest terms ~5 d)
_EOP_RATE_STEP_S = 600.0      # ±10 min for UT1 and pole rates (tidal terms ≥ 0.5 d period: 1e-3 relative)


def earth_rotation(t, eop: EOPValues | None = None, with_rate: bool = False) -> EarthRotation:
    """Factors of the GCRS→ITRS rotation at epochs ``t`` (EOP interpolated unless given).

    ``with_rate`` adds the precession-nutation rate of ``rc2i`` (≈5e-5 m/s at the
    Earth's surface, needed for station velocities at Doppler precision) and,
    with interpolated EOP, takes ω and the polar-motion rate from the EOP
    themselves (tidal UT1 and pole included). Given constant ``eop``, ω uses its LOD.
    """
    utc, tt_days = utc_and_tt(t)
    e = eop if eop is not None else eop_at(utc.astype("datetime64[ns]"))
    rc2i = _rc2i(tt_days, e.dx, e.dy)
    sp = erfa.sp00(J2000_JD, tt_days)
    rpom = erfa.pom00(e.xp, e.yp, sp)
    days, rem_ns = np.divmod(utc - J2000_NS, NS_PER_DAY)  # whole + fraction keeps ERA at 1e-16 rad
    era = erfa.era00(J2000_JD + days, rem_ns / NS_PER_DAY + e.ut1_utc / SECONDS_PER_DAY)
    omega = ERA_RATE * (1.0 - e.lod / SECONDS_PER_DAY)
    rc2i_rate = rpom_rate = None
    if with_rate:
        h = _RATE_STEP_DAYS
        rc2i_rate = (_rc2i(tt_days + h, e.dx, e.dy) - _rc2i(tt_days - h, e.dx, e.dy)) / (2 * h * SECONDS_PER_DAY)
        if eop is None:
            step = np.int64(_EOP_RATE_STEP_S * 1e9)
            ep = eop_at((utc + step).astype("datetime64[ns]"))
            em = eop_at((utc - step).astype("datetime64[ns]"))
            jump = (tai_minus_utc_ns(utc + step) - tai_minus_utc_ns(utc - step)) * 1e-9  # a leap second inside
            omega = ERA_RATE * (1.0 + (ep.ut1_utc - em.ut1_utc - jump) / (2 * _EOP_RATE_STEP_S))
            rpom_rate = (erfa.pom00(ep.xp, ep.yp, sp) - erfa.pom00(em.xp, em.yp, sp)) / (2 * _EOP_RATE_STEP_S)
    return EarthRotation(rc2i, era, rpom, omega, rc2i_rate, rpom_rate)


def gcrs_to_itrs(t, eop: EOPValues | None = None) -> np.ndarray:
    """GCRS→ITRS rotation matrices (N,3,3) at epochs ``t``."""
    return earth_rotation(t, eop).gcrs_to_itrs


def itrs_to_gcrs(t, eop: EOPValues | None = None) -> np.ndarray:
    """ITRS→GCRS rotation matrices (N,3,3) at epochs ``t``."""
    return np.swapaxes(gcrs_to_itrs(t, eop), -1, -2)


def _mv(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("...ij,...j->...i", m, v)


def _mtv(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("...ji,...j->...i", m, v)


def itrs_to_gcrs_state(t, r_itrs, v_itrs=None, eop: EOPValues | None = None):
    """GCRS position (m) and velocity (m/s) of ITRS positions/velocities at epochs ``t``.

    The velocity includes Earth rotation ω × r (ω from UT1's rate, tidal terms
    included) about the CIP, the precession-nutation rate and, with
    interpolated EOP, the polar-motion rate. ``v_itrs`` defaults to zero (a
    point fixed on the Earth).
    """
    rot = earth_rotation(t, eop, with_rate=True)
    r = np.asarray(r_itrs, dtype=float)
    r_tirs = _mtv(rot.rpom, r)
    v_tirs = np.zeros_like(r_tirs) if v_itrs is None else _mtv(rot.rpom, np.asarray(v_itrs, dtype=float))
    if rot.rpom_rate is not None:
        v_tirs = v_tirs + _mtv(rot.rpom_rate, r)
    w = np.asarray(rot.omega)[..., None]
    v_tirs = v_tirs + w * np.stack([-r_tirs[..., 1], r_tirs[..., 0], np.zeros_like(r_tirs[..., 0])], axis=-1)
    rz = frame_rotation(3, rot.era)
    r_cirs = _mtv(rz, r_tirs)
    return _mtv(rot.rc2i, r_cirs), _mtv(rot.rc2i, _mtv(rz, v_tirs)) + _mtv(rot.rc2i_rate, r_cirs)


def gcrs_to_itrs_state(t, r_gcrs, v_gcrs=None, eop: EOPValues | None = None):
    """ITRS position (m) and velocity (m/s) from GCRS position/velocity at epochs ``t`` (inverse of the above)."""
    rot = earth_rotation(t, eop, with_rate=True)
    rz = frame_rotation(3, rot.era)
    r = np.asarray(r_gcrs, dtype=float)
    v_cirs = _mv(rot.rc2i_rate, r) + (0.0 if v_gcrs is None else _mv(rot.rc2i, np.asarray(v_gcrs, dtype=float)))
    r_tirs = _mv(rz, _mv(rot.rc2i, r))
    w = np.asarray(rot.omega)[..., None]
    v_tirs = _mv(rz, v_cirs) - w * np.stack([-r_tirs[..., 1], r_tirs[..., 0], np.zeros_like(r_tirs[..., 0])], axis=-1)
    v_itrs = _mv(rot.rpom, v_tirs)
    if rot.rpom_rate is not None:
        v_itrs = v_itrs + _mv(rot.rpom_rate, r_tirs)
    return _mv(rot.rpom, r_tirs), v_itrs
