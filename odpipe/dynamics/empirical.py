"""Empirical accelerations: constant or piecewise-constant RTN components as a registered force.

Batch b adds aR R + aT T + aN N (m/s^2, :mod:`odpipe.dynamics.rtn`) while the
segment being integrated lies in [t_start, t_end); its estimable parameters are
'emp[b].R', 'emp[b].T', 'emp[b].N' (d a/d p = the R, T, N unit vectors), b
counting the batches of all EmpiricalRTN components in order.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from odpipe.dynamics.force_registry import Force, kernel
from odpipe.dynamics.rtn import add_rtn_axes, rtn_acceleration


@dataclass
class EmpiricalRTN:
    """Rows (t_start, t_end, aR, aT, aN): TDB s, m/s^2; active for t_start <= t < t_end."""

    batches: np.ndarray


# batches (n, 5) as above; rows (n, 3) d a/d p rows of emp[b].R|T|N (-1: not estimated)
EmpiricalData = namedtuple("EmpiricalData", ["batches", "rows"])


def _batches(components) -> np.ndarray:
    return np.concatenate([np.atleast_2d(np.asarray(e.batches, float)) for e in components]
                          or [np.zeros((0, 5))]).reshape(-1, 5)


def _parameters(components) -> list[str]:
    return [f"emp[{b}].{c}" for b in range(len(_batches(components))) for c in "RTN"]


def _compile(components, ctx) -> EmpiricalData:
    return EmpiricalData(_batches(components), ctx.rows(_parameters(components)).reshape(-1, 3))


@kernel(EmpiricalData)
def _kernel(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    for b in range(data.batches.shape[0]):
        if data.batches[b, 0] <= env.t_seg < data.batches[b, 1]:
            rtn_acceleration(r, v, data.batches[b, 2:5], acc, grad_r, grad_v)
            add_rtn_axes(r, v, data.rows[b], dadp)


EMPIRICAL = Force("empirical", (EmpiricalRTN,), _compile, parameters=_parameters,
                  breakpoints=lambda components: list(_batches(components)[:, :2].ravel()))
