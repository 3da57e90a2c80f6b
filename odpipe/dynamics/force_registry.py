"""How a force joins the model: a :class:`Force` record and the numba ``contribute`` generic.

A force lives in one module holding its component dataclass (what the user
writes in a :class:`~odpipe.dynamics.forces.ForceModel`), a namedtuple of the
arrays its kernel reads, a compile step (components -> that namedtuple), and an
``@overload(contribute)`` selected by the namedtuple's class that adds the
acceleration (m/s^2), d a/d r, d a/d v (1/s^2, 1/s) and d a/d p for its
estimable parameters. Listing the :class:`Force` in ``forces.FORCES`` registers it:
the right-hand side loops over every registered force's data with
``literal_unroll``, so it never names a force.

A force absent from a model still compiles to data of the same numba type
(empty arrays, ``on = False``), so every force model shares one compiled kernel.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
from numba.extending import overload

# Quantities every force may read, evaluated once per right-hand side call:
# pos (nbody, 3) m, body positions relative to the centre in CompileContext.slot order;
# mass kg (after the burns' mass flow); t_seg TDB s, the mid-epoch of the segment being
# integrated (piecewise-constant terms switch only between segments).
Environment = namedtuple("Environment", ["pos", "mass", "t_seg"])


def contribute(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    """Add one force's acceleration and partials; implemented per data class with :func:`kernel`."""
    raise NotImplementedError("contribute() is only callable from numba code")


def kernel(data_class):
    """Register ``impl(data, t, r, v, env, acc, grad_r, grad_v, dadp)`` as ``contribute`` for ``data_class``."""

    def register(impl):
        @overload(contribute, inline="always")
        def _select(data, t, r, v, env, acc, grad_r, grad_v, dadp):
            if getattr(data, "instance_class", None) is data_class:
                return impl
            return None

        return impl

    return register


@dataclass
class CompileContext:
    """What a compile step may use: the centre, the ephemeris, the span and the parameters.

    ``slot[body]`` is the row of ``env.pos`` holding that body; ``lo``/``hi`` the
    tabulation span (TDB s); ``params`` the estimated parameter names in the order of
    the rows of d a/d p; ``harmonic_bodies`` the bodies with a spherical-harmonic field
    (their point-mass terms change).
    """

    center: str
    ephemeris: object
    lo: float
    hi: float
    params: Sequence[str]
    with_stm: bool
    slot: dict
    central_gm: float | None
    harmonic_bodies: frozenset = frozenset()

    def gm(self, body: str) -> float:
        """GM (m^3/s^2) of ``body``; the model's ``central_gm`` for the centre when given."""
        if body == self.center and self.central_gm is not None:
            return float(self.central_gm)
        return float(self.ephemeris.gm(body))

    def rows(self, names: Sequence[str]) -> np.ndarray:
        """Row of each parameter name in d a/d p, -1 when it is not estimated (int64)."""
        index = {p: i for i, p in enumerate(self.params)}
        return np.array([index.get(n, -1) for n in names], dtype=np.int64)


def _nothing(components, *_):
    return []


@dataclass(frozen=True)
class Force:
    """One registered force.

    ``name``: field of the compiled model's ``forces``; ``components``: the dataclass(es)
    a ForceModel lists; ``compile(components, ctx) -> data`` (components may be empty);
    ``parameters(components) -> names`` of its estimable parameters, in canonical order;
    ``bodies(components, center) -> names`` whose positions the kernel needs;
    ``breakpoints(components) -> epochs`` where it switches on or off;
    ``substitute(components, values) -> components`` with estimated values (by parameter name) put in.
    """

    name: str
    components: tuple
    compile: Callable
    parameters: Callable = _nothing
    bodies: Callable = _nothing
    breakpoints: Callable = _nothing
    substitute: Callable = lambda components, values: list(components)
