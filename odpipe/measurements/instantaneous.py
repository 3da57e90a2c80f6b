"""Instantaneous (geometric) range and range-rate between two participants, for studies.

Leonard's thesis, section 3.11 (eqs. 3.102-3.116), with both states at the
same epoch and centre (no light time): rho = |r2 - r1|,
rhodot = (v2 - v1) . u, u = (r2 - r1)/rho. Partials:
d rho/d r1 = -u, d rho/d r2 = u; d rhodot/d r1 = -(v2 - v1)^T (I - u u^T)/rho,
d rhodot/d v1 = -u, and the opposite signs for participant 2. This is the
limit of count-averaged Doppler as the count time goes to 0 only up to the
light-time terms (v/c); :attr:`.lighttime.PathSolution.rate` is that exact limit.
"""

from __future__ import annotations

import numpy as np

from .computed import Computed, EventPartial


def _geometry(s1, s2):
    d = s2[:, :3] - s1[:, :3]
    rho = np.linalg.norm(d, axis=1)
    return d / rho[:, None], rho, s2[:, 3:] - s1[:, 3:]


def instantaneous_range(s1: np.ndarray, s2: np.ndarray, t: np.ndarray, roles=("sc1", "sc2")) -> Computed:
    """Range (m) between states s1, s2 (N,6) at TDB epochs t; parameter 'bias' (m)."""
    u, rho, _ = _geometry(s1, s2)
    zero = np.zeros_like(u)
    events = [EventPartial(roles[0], t, -u, zero), EventPartial(roles[1], t, u, zero)]
    return Computed(rho, "m", events, {"bias": np.ones_like(rho)})


def instantaneous_range_rate(s1: np.ndarray, s2: np.ndarray, t: np.ndarray, roles=("sc1", "sc2")) -> Computed:
    """Range-rate (m/s), positive when the participants separate; parameter 'bias' (m/s)."""
    u, rho, dv = _geometry(s1, s2)
    rate = np.einsum("ni,ni->n", dv, u)
    d_r2 = (dv - rate[:, None] * u) / rho[:, None]  # (v2 - v1)^T (I - u u^T) / rho
    events = [EventPartial(roles[0], t, -d_r2, -u), EventPartial(roles[1], t, d_r2, u)]
    return Computed(rate, "m/s", events, {"bias": np.ones_like(rate)})
