"""Local orbital frames (RTN/RIC) and the Earth–Moon rotating (synodic) frame.

All functions are vectorized over leading axes; positions in m, velocities in m/s.
"""

from __future__ import annotations

import numpy as np


def _unit(a: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    if np.any(n == 0):
        raise ValueError("degenerate frame: zero-length axis (r parallel to v, or r = 0)")
    return a / n


def rtn_matrix(r, v) -> np.ndarray:
    """Rotation inertial → RTN (…,3,3): rows R = r/|r|, N = r×v/|r×v|, T = N×R.

    RIC (radial, in-track, cross-track) is the same frame; see :func:`ric_matrix`.
    """
    r = np.asarray(r, float)
    v = np.asarray(v, float)
    rhat = _unit(r)
    nhat = _unit(np.cross(r, v))
    that = np.cross(nhat, rhat)
    return np.stack([rhat, that, nhat], axis=-2)


ric_matrix = rtn_matrix  # radial / in-track / cross-track ≡ radial / transverse / normal


def synodic_matrix(r_primary_to_secondary, v_primary_to_secondary) -> tuple[np.ndarray, np.ndarray]:
    """(Rotation inertial → rotating frame (…,3,3), angular velocity vector (…,3) rad/s in inertial axes).

    x from primary to secondary, z along their relative angular momentum.
    """
    r = np.asarray(r_primary_to_secondary, float)
    v = np.asarray(v_primary_to_secondary, float)
    m = rtn_matrix(r, v)
    omega = np.cross(r, v) / np.sum(r * r, axis=-1, keepdims=True)
    return m, omega


def earth_moon_rotating_state(r, v, r_moon, v_moon, mass_ratio: float | None = None,
                              normalize: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Position and velocity in the Earth–Moon rotating frame from geocentric inertial states.

    ``r, v``: object, ``r_moon, v_moon``: Moon, all geocentric inertial (m, m/s).
    Origin at the Earth, or at the barycentre when ``mass_ratio`` = m_moon/(m_earth+m_moon)
    is given (e.g. GM_moon/(GM_earth+GM_moon) from the ephemeris). With
    ``normalize`` positions are divided by the instantaneous Earth–Moon distance and
    velocities by distance × |ω| (the CR3BP units, pulsating for the real orbit).
    """
    m, omega = synodic_matrix(r_moon, v_moon)
    origin = 0.0 if mass_ratio is None else mass_ratio * np.asarray(r_moon, float)
    origin_v = 0.0 if mass_ratio is None else mass_ratio * np.asarray(v_moon, float)
    rel = np.asarray(r, float) - origin
    rel_v = np.asarray(v, float) - origin_v - np.cross(omega, rel)
    rr = np.einsum("...ij,...j->...i", m, rel)
    vv = np.einsum("...ij,...j->...i", m, rel_v)
    if normalize:
        d = np.linalg.norm(np.asarray(r_moon, float), axis=-1, keepdims=True)
        w = np.linalg.norm(omega, axis=-1, keepdims=True)
        return rr / d, vv / (d * w)
    return rr, vv
