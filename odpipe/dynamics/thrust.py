"""Maneuvers: finite burns (a registered force with mass flow) and impulsive delta-v.

A :class:`FiniteBurn` thrusts with constant force (N) along a fixed ICRF or RTN
direction while the segment being integrated lies in [t_start, t_end); the mass
(kg) falls at ``mass_flow`` kg/s over it, which every mass-dependent force sees.
An :class:`ImpulsiveManeuver` is applied by the propagator between segments
(:mod:`odpipe.dynamics.propagator`); its parameters are 'dv[k].x|y|z' and 'dv[k].t'.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numba import njit

from odpipe.dynamics.force_registry import Force, kernel
from odpipe.dynamics.rtn import rtn_acceleration


@dataclass
class FiniteBurn:
    t_start: float
    t_end: float
    thrust: float  # N
    direction: Sequence[float]  # unit vector in ``frame``
    mass_flow: float = 0.0  # kg/s
    frame: str = "icrf"  # or 'rtn'


@dataclass
class ImpulsiveManeuver:
    epoch: float  # TDB s
    dv: Sequence[float]  # ICRF, m/s


# rows (n, 8): t_start, t_end (TDB s), thrust N, mass flow kg/s, direction (3), 1 if RTN else 0
BurnData = namedtuple("BurnData", ["rows"])


def burn_rows(components) -> np.ndarray:
    """(n, 8) rows of :data:`BurnData` (also the mass-flow schedule of :func:`spacecraft_mass`)."""
    return np.array([[b.t_start, b.t_end, b.thrust, b.mass_flow, *np.asarray(b.direction, float),
                      1.0 if b.frame == "rtn" else 0.0] for b in components], dtype=float).reshape(-1, 8)


@njit(cache=True)
def spacecraft_mass(t, mass0, burns):
    """Mass (kg) at t after the mass flow of the finite burns (rows of :func:`burn_rows`)."""
    m = mass0
    for k in range(burns.shape[0]):
        m -= burns[k, 3] * min(max(t - burns[k, 0], 0.0), burns[k, 1] - burns[k, 0])
    return m


@kernel(BurnData)
def _kernel(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    burns = data.rows
    for b in range(burns.shape[0]):
        if burns[b, 0] <= env.t_seg < burns[b, 1]:
            a_thrust = burns[b, 2] / env.mass * burns[b, 4:7]
            if burns[b, 7] > 0.0:
                rtn_acceleration(r, v, a_thrust, acc, grad_r, grad_v)
            else:
                acc += a_thrust


BURNS = Force("burns", (FiniteBurn,), lambda components, ctx: BurnData(burn_rows(components)),
              breakpoints=lambda components: [t for b in components for t in (b.t_start, b.t_end)])
