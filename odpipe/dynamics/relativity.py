"""Post-Newtonian (Schwarzschild) correction of the central body, IERS 2010 eq. 10.12.

With beta = gamma = 1: a = GM/(c^2 r^3) [ (4 GM/r - v^2) r + 4 (r.v) v ] (m/s^2),
r, v relative to the central body. Lense-Thirring and de Sitter terms are
below 1e-10 m/s^2 for cislunar orbits and are not modelled.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass

import numpy as np
from numba import njit

from odpipe.constants import C_LIGHT
from odpipe.dynamics.pointmass import central_gm
from odpipe.dynamics.force_registry import Force, kernel


@dataclass
class Relativity:
    """The Schwarzschild term of the central body."""


RelativityData = namedtuple("RelativityData", ["on", "gm"])  # bool; central GM, m^3/s^2


@njit(cache=True)
def schwarzschild(r, v, gm, acc, grad_r, grad_v):
    """Add the correction to ``acc`` and its partials d a/d r, d a/d v."""
    rn2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
    rn = np.sqrt(rn2)
    v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    rv = r[0] * v[0] + r[1] * v[1] + r[2] * v[2]
    k = gm / (C_LIGHT * C_LIGHT * rn2 * rn)
    alpha = 4.0 * gm / rn - v2
    term = np.empty(3)
    for i in range(3):
        term[i] = alpha * r[i] + 4.0 * rv * v[i]
        acc[i] += k * term[i]
    for i in range(3):
        for j in range(3):
            eye = 1.0 if i == j else 0.0
            grad_r[i, j] += (-3.0 * k / rn2 * term[i] * r[j]
                             + k * (alpha * eye - 4.0 * gm / (rn2 * rn) * r[i] * r[j]
                                    + 4.0 * v[i] * v[j]))
            grad_v[i, j] += k * (-2.0 * r[i] * v[j] + 4.0 * v[i] * r[j] + 4.0 * rv * eye)


def _compile(components, ctx) -> RelativityData:
    return RelativityData(bool(components), central_gm(ctx))


@kernel(RelativityData)
def _kernel(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    if data.on:
        schwarzschild(r, v, data.gm, acc, grad_r, grad_v)


RELATIVITY = Force("relativity", (Relativity,), _compile)
