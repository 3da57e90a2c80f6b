"""Point-mass gravity: central body and third bodies with the indirect term.

For a spacecraft at r relative to the centre and a body at s (both ICRF, m):
a = -GM r/|r|^3 (central) and a = GM [ (s - r)/|s - r|^3 - s/|s|^3 ] (third
body; the second term is the centre's acceleration towards the body, which is
what makes any centre - planet, Moon, Sun or a barycentre - correct). When the
centre is a barycentre, every massive body is a "third body" and the central
term is absent. Gradients d a / d r are returned for the STM.
"""

from __future__ import annotations

import numpy as np
from numba import njit


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
    d = s - r
    dn2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    dn = np.sqrt(dn2)
    sn = np.sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2])
    kd = gm / (dn2 * dn)
    ks = gm / (sn * sn * sn) if sn > 0.0 else 0.0
    for i in range(3):
        acc[i] += kd * d[i] - ks * s[i]
        for j in range(3):
            grad[i, j] += kd * (3.0 * d[i] * d[j] / dn2 - (1.0 if i == j else 0.0))
