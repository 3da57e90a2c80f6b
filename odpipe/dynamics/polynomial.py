"""Inertial polynomial acceleration: a constant plus a linear drift in ICRF, as a registered force.

a(t) = c0 + c1 (t - t_ref) (m/s^2, m/s^3, TDB s), the same in every state, while
the segment being integrated lies in [t_start, t_end) - for example a propellant
leak or an unmodelled thrust of constant direction (in the spirit of Orekit's
PolynomialAccelerationModel, degree 1, per inertial axis). Component k of a model
has the estimable parameters 'poly[k].x0', 'poly[k].y0', 'poly[k].z0' (c0) and
'poly[k].x1', 'poly[k].y1', 'poly[k].z1' (c1): d a/d c0 = e_axis, d a/d c1 =
(t - t_ref) e_axis; the acceleration does not depend on r or v.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from odpipe.dynamics.force_registry import Force, kernel

PARAMETERS = ("x0", "y0", "z0", "x1", "y1", "z1")


@dataclass
class InertialPolynomialAcceleration:
    """c0 (3,) m/s^2 and c1 (3,) m/s^3 in ICRF about ``t_ref`` (TDB s), active for t_start <= t < t_end."""

    t_ref: float
    c0: Sequence[float] = (0.0, 0.0, 0.0)
    c1: Sequence[float] = (0.0, 0.0, 0.0)
    t_start: float = -np.inf
    t_end: float = np.inf


# rows (n, 9): t_start, t_end, t_ref, c0 (3), c1 (3); param_rows (n, 6): d a/d p rows in PARAMETERS order (-1: fixed)
PolynomialData = namedtuple("PolynomialData", ["rows", "param_rows"])


def _parameters(components) -> list[str]:
    return [f"poly[{k}].{c}" for k in range(len(components)) for c in PARAMETERS]


def _compile(components, ctx) -> PolynomialData:
    rows = np.array([[p.t_start, p.t_end, p.t_ref, *np.asarray(p.c0, float), *np.asarray(p.c1, float)]
                     for p in components], dtype=float).reshape(-1, 9)
    return PolynomialData(rows, ctx.rows(_parameters(components)).reshape(-1, 6))


@kernel(PolynomialData)
def _kernel(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    for k in range(data.rows.shape[0]):
        if data.rows[k, 0] <= env.t_seg < data.rows[k, 1]:
            dt = t - data.rows[k, 2]
            for i in range(3):
                acc[i] += data.rows[k, 3 + i] + data.rows[k, 6 + i] * dt
                if data.param_rows[k, i] >= 0:
                    dadp[data.param_rows[k, i], i] += 1.0
                if data.param_rows[k, 3 + i] >= 0:
                    dadp[data.param_rows[k, 3 + i], i] += dt


def _substitute(components, values) -> list:
    out = []
    for k, c in enumerate(components):
        p = [values.get(f"poly[{k}].{name}", v) for name, v in zip(PARAMETERS, (*c.c0, *c.c1))]
        out.append(replace(c, c0=tuple(p[:3]), c1=tuple(p[3:])))
    return out


POLYNOMIAL = Force("polynomial", (InertialPolynomialAcceleration,), _compile, parameters=_parameters,
                   substitute=_substitute,
                   breakpoints=lambda components: [t for p in components for t in (p.t_start, p.t_end)
                                                   if np.isfinite(t)])
