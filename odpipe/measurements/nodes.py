"""Participants of a radio link: where a station or a spacecraft is, in the frame the light time is solved in.

A *node* answers two questions at TDB epochs ``t`` (s past J2000, shape (N,)):

* ``state(t) -> (N, 6)``: position (m) and velocity (m/s), ICRF axes, relative to
  the solve origin (``'ssb'`` for the barycentric solution; a body such as
  ``'earth'`` for the faster centre-relative mode, see :mod:`.lighttime`);
* ``tdb_minus_clock(t, state) -> (N,)``: TDB minus the time scale the node counts
  in (s). For a ground station that is TT (station time is UTC, a constant offset
  from TT between leap seconds): TDB - TT = geocentric series (Fairhead & Bretagnon,
  through ERFA) + the topocentric term (v_earth . r_station)/c^2. The topocentric
  term is at most 2.1 us; its change over a lunar round trip is below 0.4 ns
  (12 cm of path) and it is kept because it costs one dot product. Spacecraft
  count in TDB here (0): their clocks are modelled by estimated clock parameters,
  and a spacecraft oscillator's proper-time rate by :func:`proper_rate_offset`.

Ephemeris objects follow ``odpipe.environment.ephemeris.Ephemeris``:
``state(target, center, t) -> (N, 6)`` in m, m/s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np

from odpipe.constants import C_LIGHT, ERA_RATE
from odpipe.time import tdb_minus_tt


class Node(Protocol):
    name: str

    def state(self, t: np.ndarray) -> np.ndarray: ...

    def tdb_minus_clock(self, t: np.ndarray, state: np.ndarray) -> np.ndarray: ...


def origin_state(ephemeris, body: str, origin: str, t: np.ndarray) -> np.ndarray:
    """State (N,6) of ``body`` relative to ``origin``; zeros when they coincide."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if body.lower() == origin.lower():
        return np.zeros((t.size, 6))
    if ephemeris is None:
        raise ValueError(f"an ephemeris is needed for the state of {body!r} relative to {origin!r}")
    return np.asarray(ephemeris.state(body, origin, t), dtype=float).reshape(t.size, 6)


PROPER_TIME_BODIES = ("sun", "earth", "moon", "jupiter")


def proper_rate_offset(ephemeris, origin: str, t: np.ndarray, state: np.ndarray,
                       bodies=PROPER_TIME_BODIES) -> np.ndarray:
    """1 - d(proper time)/d(TDB coordinate time) of a clock at ``state`` (N,6, relative to ``origin``) at
    TDB ``t``: (U + v^2/2)/c^2 with barycentric velocity v and the Newtonian potential U of ``bodies``
    (IERS 2010 eq. 10.6 to 1/c^2). About 1.5e-8 near the Earth-Moon system, its
    constant part being IERS L_C; about a lunar orbiter it varies by ~5e-10 with the orbit."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    bary = np.asarray(state, dtype=float) + origin_state(ephemeris, origin, "ssb", t)
    u = np.zeros(t.size)
    for body in bodies:
        u += ephemeris.gm(body) / np.linalg.norm(bary[:, :3] - ephemeris.position(body, "ssb", t), axis=1)
    return (u + 0.5 * np.einsum("ni,ni->n", bary[:, 3:], bary[:, 3:])) / C_LIGHT**2


@dataclass
class SpacecraftNode:
    """A spacecraft flying ``trajectory`` (``.state(t)``, ``.center``), seen from ``origin``."""

    trajectory: object
    ephemeris: object = None
    origin: str = "ssb"
    name: str = "spacecraft"

    def state(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        s = np.asarray(self.trajectory.state(t), dtype=float).reshape(t.size, 6)
        center = getattr(self.trajectory, "center", self.origin)
        return s + origin_state(self.ephemeris, center, self.origin, t)

    def tdb_minus_clock(self, t, state):
        return np.zeros(np.size(t))


@dataclass
class StationNode:
    """A ground antenna: ITRS position (m, fixed or a function of t with plate motion) turned to GCRS.

    ``gcrs_to_itrs(t) -> (N,3,3)`` is the full Earth-orientation matrix with EOP
    (``odpipe.frames.earth.gcrs_to_itrs``). The velocity is R^T (omega x r) with
    the nominal rotation rate; the neglected precession-nutation and polar-motion
    rates change it by < 1e-5 m/s.
    """

    position_itrs: np.ndarray | Callable
    gcrs_to_itrs: Callable
    ephemeris: object = None
    origin: str = "ssb"
    name: str = "station"

    def itrs(self, t):
        """ITRS position (N,3) in m."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        p = self.position_itrs(t) if callable(self.position_itrs) else self.position_itrs
        return np.broadcast_to(np.asarray(p, dtype=float), (t.size, 3))

    def itrs_to_frame(self, t):
        """Rotation (N,3,3) taking ITRS vectors to the solve frame's (ICRF) axes."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return np.swapaxes(np.asarray(self.gcrs_to_itrs(t), dtype=float).reshape(t.size, 3, 3), 1, 2)

    def geocentric_state(self, t):
        """GCRS state (N,6) of the antenna, m and m/s."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        r = self.itrs(t)
        rot = self.itrs_to_frame(t)
        w = np.zeros_like(r)       # (0, 0, omega) x r
        w[:, 0] = -ERA_RATE * r[:, 1]
        w[:, 1] = ERA_RATE * r[:, 0]
        return np.concatenate([np.einsum("nij,nj->ni", rot, r), np.einsum("nij,nj->ni", rot, w)], axis=1)

    def state(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return self.geocentric_state(t) + origin_state(self.ephemeris, "earth", self.origin, t)

    def tdb_minus_clock(self, t, state):
        """TDB - TT at the antenna (s): geocentric series plus (v_earth . r_station)/c^2."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = geocentric_tdb_minus_tt(t)
        if self.ephemeris is not None:
            earth = origin_state(self.ephemeris, "earth", self.origin, t)
            v_earth = earth[:, 3:] if self.origin.lower() == "ssb" else origin_state(self.ephemeris, "earth", "ssb", t)[:, 3:]
            r_geo = state[:, :3] - earth[:, :3]
            out = out + np.einsum("ni,ni->n", v_earth, r_geo) / C_LIGHT**2
        return out


def geocentric_tdb_minus_tt(t: np.ndarray) -> np.ndarray:
    """TDB - TT at the geocentre (s) for TDB seconds past J2000.

    :func:`odpipe.time.tdb_minus_tt` (ERFA's ``dtdb`` series) without station terms, which
    interpolates the series' values kept at whole hours (cubic; the series has no terms shorter
    than about a day at the geocentre: measured error 4e-16 s, rate error 2e-17 over 1-s differences).
    """
    return tdb_minus_tt(np.atleast_1d(np.asarray(t, dtype=float)))
