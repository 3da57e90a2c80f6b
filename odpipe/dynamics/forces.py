"""A force model (a centre and its components) and its compilation for the numba kernel.

A :class:`ForceModel` is a centre (NAIF name: 'earth', 'moon', 'sun', 'emb',
'ssb', ...) and a list of components, each owned by the module of its force:

* :class:`PointMasses` - third bodies from the ephemeris, indirect terms included
  (:mod:`~odpipe.dynamics.pointmass`, which also holds the central body's term);
* :class:`SphericalHarmonics` - a body's field in its body-fixed frame
  (:mod:`~odpipe.dynamics.gravity_fields`); it replaces that body's point mass;
* :class:`Relativity` - Schwarzschild term of the central body (:mod:`~odpipe.dynamics.relativity`);
* :class:`SolarRadiationPressure` with :class:`Plate` and :class:`Cylinder` surfaces,
  conical shadows (:mod:`~odpipe.dynamics.srp`);
* :class:`AtmosphericDrag` - Harris-Priester or NRLMSISE-00, Earth-centred models only (:mod:`~odpipe.dynamics.drag`);
* :class:`EmpiricalRTN` - piecewise-constant RTN accelerations (:mod:`~odpipe.dynamics.empirical`);
* :class:`InertialPolynomialAcceleration` - constant plus linear ICRF acceleration
  (:mod:`~odpipe.dynamics.polynomial`);
* :class:`FiniteBurn` - thrust with mass flow, and :class:`ImpulsiveManeuver`, a delta-v
  applied by the propagator (:mod:`~odpipe.dynamics.thrust`).

:data:`FORCES` registers the forces: the compiled model holds one data namedtuple
per entry, in this order, which is also the order in which the kernel adds them.
To add a force: a module with its component, data, compile step and kernel
(see :mod:`odpipe.dynamics.force_registry`), and one entry here.

Estimable dynamic parameters (names used by ``Trajectory.param_names``), in canonical
order: ``srp_scale``, ``rho_s[k]``/``rho_d[k]`` (surface k), ``cd`` (drag),
``emp[b].R|T|N`` (batch b), ``poly[k].x0|y0|z0|x1|y1|z1`` (polynomial acceleration k),
``dv[k].x|y|z`` and ``dv[k].t`` (impulsive maneuver k).
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass, field, replace
from typing import Sequence

import numpy as np

from odpipe.dynamics.drag import DRAG, AtmosphericDrag
from odpipe.dynamics.empirical import EMPIRICAL, EmpiricalRTN
from odpipe.dynamics.gravity_fields import HARMONICS, ROTATION_GRID, SphericalHarmonics
from odpipe.dynamics.pointmass import CENTRAL, THIRD_BODIES, PointMasses
from odpipe.dynamics.polynomial import POLYNOMIAL, InertialPolynomialAcceleration
from odpipe.dynamics.force_registry import CompileContext
from odpipe.dynamics.relativity import RELATIVITY, Relativity
from odpipe.dynamics.srp import BODY_RADIUS, SRP, Cylinder, Plate, SolarRadiationPressure
from odpipe.dynamics.thrust import BURNS, FiniteBurn, ImpulsiveManeuver, burn_rows

__all__ = ["AtmosphericDrag", "BODY_RADIUS", "CompiledModel", "Cylinder", "EmpiricalRTN", "FORCES", "FiniteBurn",
           "ForceModel", "ImpulsiveManeuver", "InertialPolynomialAcceleration", "Plate", "PointMasses",
           "ROTATION_GRID", "Relativity", "SolarRadiationPressure", "SphericalHarmonics", "compile_model"]

SCRATCH_FIXED = 27   # the right-hand side's scratch: acceleration 3, d a/d r 9, d a/d v 9, an STM column 6; then d a/d p

FORCES = (CENTRAL, THIRD_BODIES, HARMONICS, RELATIVITY, SRP, DRAG, EMPIRICAL, POLYNOMIAL, BURNS)
Forces = namedtuple("Forces", [f.name for f in FORCES])

# The arrays the numba right-hand side reads (odpipe.dynamics.rhs):
# forces      Forces: one data namedtuple per registered force;
# eph_coeffs, eph_t_start, eph_t_step: Chebyshev positions of the bodies the forces need
#             (odpipe.environment.ephemeris.interp_positions), rows in CompileContext.slot order;
# mass        kg at the start; mass_flow: the finite burns' rows (odpipe.dynamics.thrust.burn_rows);
# segment     (1,) mid-epoch (TDB s) of the segment being integrated, set by the propagator
#             so that empirical batches and burns switch exactly at segment boundaries;
# with_stm    whether the state carries the STM and sensitivities; n_params: rows of d a/d p;
# pos         (nbody, 3) the bodies' positions of the current evaluation, written by the kernel;
# work        the right-hand side's scratch (odpipe.dynamics.rhs.scratch_size): no allocation per evaluation.
CompiledModel = namedtuple("CompiledModel", ["forces", "eph_coeffs", "eph_t_start", "eph_t_step", "mass",
                                             "mass_flow", "segment", "with_stm", "n_params", "pos", "work"])


@dataclass
class ForceModel:
    """Centre, components, spacecraft mass (kg), the ephemeris (``Ephemeris``) and
    optionally the centre's GM (m^3/s^2; default from the ephemeris)."""

    center: str
    components: list = field(default_factory=list)
    mass: float = 1000.0
    ephemeris: object = None
    central_gm: float | None = None

    def of_type(self, kind):
        return [c for c in self.components if isinstance(c, kind)]

    def maneuvers(self) -> list[ImpulsiveManeuver]:
        return sorted(self.of_type(ImpulsiveManeuver), key=lambda m: m.epoch)

    def parameter_names(self) -> list[str]:
        """All estimable dynamic parameters of this model, in canonical order."""
        names = [n for f in FORCES for n in f.parameters(self.of_type(f.components))]
        for k, _ in enumerate(self.maneuvers()):
            names += [f"dv[{k}].{c}" for c in "xyz"] + [f"dv[{k}].t"]
        return names

    def with_parameters(self, values: dict) -> "ForceModel":
        """The same model with estimated values (by the names of :meth:`parameter_names`) in its components."""
        comps = list(self.components)
        for f in FORCES:
            at = [i for i, c in enumerate(comps) if isinstance(c, f.components)]
            for i, c in zip(at, f.substitute([comps[i] for i in at], values)):
                comps[i] = c
        return replace(self, components=comps)

    def breakpoints(self) -> list[float]:
        """Epochs where the dynamics are discontinuous (segments restart there)."""
        pts = [m.epoch for m in self.maneuvers()]
        pts += [float(t) for f in FORCES for t in f.breakpoints(self.of_type(f.components))]
        return sorted(set(pts))


def compile_model(fm: ForceModel, t0: float, t1: float, params: Sequence[str], with_stm: bool) -> CompiledModel:
    """The :data:`CompiledModel` of ``fm`` over [t0, t1] (TDB s) for the parameters ``params``."""
    lo, hi = min(t0, t1) - 3600.0, max(t0, t1) + 3600.0
    center = fm.center.lower()
    parts = [(f, fm.of_type(f.components)) for f in FORCES]
    # every body whose position the kernel needs, relative to the centre
    needed = list(dict.fromkeys(b for f, comps in parts for b in f.bodies(comps, center)))
    if needed:
        interp = fm.ephemeris.interpolant(needed, center, lo, hi)
        coeffs, t_start, t_step = interp.coeffs, interp.t_start, interp.t_step
    else:
        coeffs, t_start, t_step = np.zeros((1, 1, 3, 1)), lo, hi - lo
    ctx = CompileContext(center, fm.ephemeris, lo, hi, list(params), with_stm,
                         {b: i for i, b in enumerate(needed)}, fm.central_gm,
                         frozenset(s.body.lower() for s in fm.of_type(SphericalHarmonics)))
    forces = Forces(*(f.compile(comps, ctx) for f, comps in parts))
    npar = len(params)
    return CompiledModel(forces, coeffs, float(t_start), float(t_step), float(fm.mass),
                         burn_rows(fm.of_type(FiniteBurn)), np.array([0.5 * (t0 + t1)]), bool(with_stm),
                         npar, np.zeros((coeffs.shape[0], 3)), np.zeros(SCRATCH_FIXED + 3 * npar))
