"""Point-mass gravity: central body and third bodies with the indirect term.

For a spacecraft at r relative to the centre and a body at s (both ICRF, m):
a = -GM r/|r|^3 (central) and a = GM [ (s - r)/|s - r|^3 - s/|s|^3 ] (third
body; the second term is the centre's acceleration towards the body, which is
what makes any centre - planet, Moon, Sun or a barycentre - correct). When the
centre is a barycentre, every massive body is a "third body" and the central
term is absent. Gradients d a / d r are returned for the STM.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numba import njit

from odpipe.dynamics.force_registry import Force, kernel

BARYCENTRES = ("ssb", "emb")


@dataclass
class PointMasses:
    """Third bodies (NAIF names) from the ephemeris, indirect terms included; a body that
    also has a :class:`~odpipe.dynamics.gravity_fields.SphericalHarmonics` field keeps only
    its indirect term here."""

    bodies: Sequence[str]


CentralData = namedtuple("CentralData", ["gm"])  # m^3/s^2; 0 for a barycentre or a centre with a field
ThirdBodyData = namedtuple("ThirdBodyData", ["gm", "slot", "direct"])  # (n,) m^3/s^2, env.pos row, bool


@njit(cache=True)
def central(r, gm, acc, grad):
    """Add -GM r/|r|^3 to ``acc`` and its gradient to ``grad`` (3x3)."""
    rn2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
    rn = np.sqrt(rn2)
    k = gm / (rn2 * rn)
    for i in range(3):
        acc[i] -= k * r[i]
        for j in range(3):
            grad[i, j] += k * (3.0 * r[i] * r[j] / rn2 - (1.0 if i == j else 0.0))


@njit(cache=True)
def third_body(r, s, gm, acc, grad):
    """Add the direct and indirect acceleration of a body at ``s`` (m) with GM."""
    d = (s[0] - r[0], s[1] - r[1], s[2] - r[2])
    dn2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    dn = np.sqrt(dn2)
    sn = np.sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2])
    kd = gm / (dn2 * dn)
    ks = gm / (sn * sn * sn) if sn > 0.0 else 0.0
    for i in range(3):
        acc[i] += kd * d[i] - ks * s[i]
        for j in range(3):
            grad[i, j] += kd * (3.0 * d[i] * d[j] / dn2 - (1.0 if i == j else 0.0))


def central_gm(ctx) -> float:
    """GM (m^3/s^2) of the central body; 0 for a barycentre."""
    return 0.0 if ctx.center in BARYCENTRES else ctx.gm(ctx.center)


def _compile_central(components, ctx) -> CentralData:
    return CentralData(0.0 if ctx.center in ctx.harmonic_bodies else central_gm(ctx))


def _third_bodies(components) -> list[str]:
    return [b.lower() for pm in components for b in pm.bodies]


def _compile_third(components, ctx) -> ThirdBodyData:
    bodies = _third_bodies(components)
    rows = ([b for b in bodies if b not in ctx.harmonic_bodies]
            + [b for b in bodies if b in ctx.harmonic_bodies])
    return ThirdBodyData(np.array([ctx.gm(b) for b in rows], dtype=float),
                         np.array([ctx.slot[b] for b in rows], dtype=np.int64),
                         np.array([b not in ctx.harmonic_bodies for b in rows], dtype=np.bool_))


@kernel(CentralData)
def _central_kernel(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    if data.gm > 0.0:
        central(r, data.gm, acc, grad_r)


@kernel(ThirdBodyData)
def _third_kernel(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    for k in range(data.gm.shape[0]):
        s = env.pos[data.slot[k]]
        if data.direct[k]:
            third_body(r, s, data.gm[k], acc, grad_r)
        else:  # body carries SH: indirect point-mass term only
            sn = np.sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2])
            for i in range(3):
                acc[i] -= data.gm[k] * s[i] / sn**3


CENTRAL = Force("central", (), _compile_central)
THIRD_BODIES = Force("third_bodies", (PointMasses,), _compile_third,
                     bodies=lambda components, center: _third_bodies(components))
