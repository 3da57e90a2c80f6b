"""Spherical-harmonic gravity of a body as a registered force.

The field acts in the body-fixed frame: the ICRF-to-body-fixed rotation is
tabulated once per arc (:mod:`odpipe.numerics.chebyshev`) and the kernel of
:mod:`odpipe.dynamics.harmonics` is evaluated at the rotated position relative to
the body. The field replaces the body's point mass (a third body keeps its
point-mass indirect term, :mod:`odpipe.dynamics.pointmass`).
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass
from typing import Callable

import numpy as np

from odpipe.dynamics.harmonics import ROWS, field_table, sh_acceleration, workspace
from odpipe.dynamics.force_registry import Force, kernel
from odpipe.environment.gravity import GravityField
from odpipe.numerics.chebyshev import evaluate, fit_channel, stack_channels

ROTATION_GRID = {"earth": (3600.0, 12), "moon": (86400.0, 12)}  # s per segment, degree


@dataclass
class SphericalHarmonics:
    """``rotation(t_tdb) -> (N,3,3)`` ICRF-to-body-fixed; default ITRS (Earth) / DE421 PA (Moon).

    ``partial_degree``: degree of the gradient for the STM (default ``degree``)."""

    body: str
    field: GravityField
    degree: int
    partial_degree: int | None = None
    rotation: Callable | None = None


# Per field k: its packed table T[k] (harmonics.field_table); gm (m^3/s^2), radius (m),
# degree, grad_degree (-1: no gradient), slot (env.pos row, -1: the centre); the rotation table (channel k);
# the kernel's scratch array (harmonics.workspace for the largest field, then 36 for the frame changes).
HarmonicsData = namedtuple("HarmonicsData", ["T", "gm", "radius", "degree", "grad_degree", "slot",
                                             "rot_coefs", "rot_meta", "work"])
FRAME_SCRATCH = 36


def default_rotation(body: str) -> Callable:
    """ICRF-to-body-fixed rotation ``(N,) TDB s -> (N, 3, 3)`` for the Earth and the Moon."""
    if body == "earth":
        from odpipe.frames.earth import gcrs_to_itrs

        return gcrs_to_itrs
    if body == "moon":
        from odpipe.frames.moon import moon_pa_to_icrf

        return lambda t: np.swapaxes(moon_pa_to_icrf(t), -1, -2)
    raise ValueError(f"no default body-fixed frame for {body!r}; give SphericalHarmonics.rotation")


_TABLES: dict = {}  # (id(field), degree, gradient degree) -> (field, table): a field's table once per arc
_TABLES_KEPT = 8


def _field_table(field: GravityField, degree: int, grad_degree: int):
    """:func:`field_table` of ``field`` to ``degree``, computed once and reused while the same field object
    is compiled again (every segment of every iteration of an arc; 63 ms at degree 150). ValueError
    when ``degree`` exceeds the field's."""
    key = (id(field), degree, grad_degree)
    hit = _TABLES.get(key)
    if hit is not None and hit[0] is field:
        return hit[1]
    truncated = field.truncated(degree)
    table = field_table(truncated.C, truncated.S, degree, grad_degree)
    while len(_TABLES) >= _TABLES_KEPT:
        _TABLES.pop(next(iter(_TABLES)))
    _TABLES[key] = (field, table)
    return table


_ROTATIONS: dict = {}  # (frame, first piece, last piece, segment, degree) -> fitted rotation channel: every
_ROTATIONS_KEPT = 512  # span inside the same whole pieces (each fit pass, each filter step) shares one fit


def _rotation_channel(s: SphericalHarmonics, lo: float, hi: float):
    """The Chebyshev table of ``s``'s ICRF-to-body-fixed rotation covering [lo, hi] (TDB s), in pieces on a
    fixed grid (whole multiples of the piece length from J2000), so a rotation does not depend on how a
    trajectory is cut into segments; fitted once per run of pieces and frame (a given ``rotation``
    function: by identity; else the body's default frame)."""
    body = s.body.lower()
    seg, deg = ROTATION_GRID.get(body, (3600.0, 12))
    first, last = int(np.floor(lo / seg)), int(np.ceil(hi / seg))
    key = (body if s.rotation is None else s.rotation, first, max(last, first + 1), seg, deg)
    hit = _ROTATIONS.get(key)
    if hit is None:
        rot = s.rotation or default_rotation(body)
        hit = fit_channel(lambda t: np.asarray(rot(t)).reshape(-1, 9), key[1] * seg, key[2] * seg, seg, deg)
        while len(_ROTATIONS) >= _ROTATIONS_KEPT:
            _ROTATIONS.pop(next(iter(_ROTATIONS)))
        _ROTATIONS[key] = hit
    return hit


def _compile(components, ctx) -> HarmonicsData:
    n = len(components)
    gm, radius = np.zeros(n), np.zeros(n)
    degree, grad_degree, slot = (np.zeros(n, dtype=np.int64) for _ in range(3))
    tables = []
    channels = []
    for k, s in enumerate(components):
        body = s.body.lower()
        channels.append(_rotation_channel(s, ctx.lo, ctx.hi))
        gm[k], radius[k], degree[k] = s.field.gm, s.field.radius, s.degree
        grad_degree[k] = (s.degree if s.partial_degree is None else s.partial_degree) if ctx.with_stm else -1
        slot[k] = ctx.slot.get(body, -1) if body != ctx.center else -1
        tables.append(_field_table(s.field, s.degree, int(grad_degree[k])))
    rot_coefs, rot_meta = stack_channels(channels)
    if n == 1:   # the one field's table as it is (1.8 MB at degree 150: no copy per segment)
        T = np.ascontiguousarray(tables[0])[np.newaxis]
    else:
        T = np.zeros((max(1, n), ROWS, max([t.shape[1] for t in tables] + [1])))
        for k, t in enumerate(tables):
            T[k, :, : t.shape[1]] = t
    work = np.concatenate([workspace(int(degree.max(initial=2)), int(grad_degree.max(initial=-1))),
                           np.zeros(FRAME_SCRATCH)])
    return HarmonicsData(T, gm, radius, degree, grad_degree, slot, rot_coefs, rot_meta, work)


@kernel(HarmonicsData)
def _kernel(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    sc = data.work[data.work.shape[0] - FRAME_SCRATCH:]  # no allocation per evaluation
    M = sc[0:9].reshape((3, 3))  # ICRF -> body-fixed
    rel = sc[9:12]
    r_bf = sc[12:15]
    a_bf = sc[15:18]
    g_bf = sc[18:27].reshape((3, 3))
    gM = sc[27:36].reshape((3, 3))
    for k in range(data.gm.shape[0]):
        slot = data.slot[k]
        for i in range(3):
            rel[i] = r[i] - env.pos[slot, i] if slot >= 0 else r[i]
        evaluate(data.rot_coefs, data.rot_meta, k, t, sc[0:9])
        for i in range(3):
            r_bf[i] = M[i, 0] * rel[0] + M[i, 1] * rel[1] + M[i, 2] * rel[2]
        ngrad = data.grad_degree[k]
        sh_acceleration(r_bf, data.gm[k], data.radius[k], data.T[k], data.degree[k], ngrad,
                        data.work, a_bf, g_bf)
        for i in range(3):
            acc[i] += M[0, i] * a_bf[0] + M[1, i] * a_bf[1] + M[2, i] * a_bf[2]
        if ngrad >= 0:  # M^T g M
            for i in range(3):
                for j in range(3):
                    gM[i, j] = g_bf[i, 0] * M[0, j] + g_bf[i, 1] * M[1, j] + g_bf[i, 2] * M[2, j]
            for i in range(3):
                for j in range(3):
                    grad_r[i, j] += M[0, i] * gM[0, j] + M[1, i] * gM[1, j] + M[2, i] * gM[2, j]


HARMONICS = Force("harmonics", (SphericalHarmonics,), _compile,
                  bodies=lambda components, center: [s.body.lower() for s in components
                                                     if s.body.lower() != center])
