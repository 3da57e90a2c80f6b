"""Force models, variational equations and numerical propagation (see DESIGN.md, Dynamics).

Public API: :func:`propagate`, :func:`propagate_many`, :class:`Trajectory`,
:class:`TrajectorySet`, :class:`ForceModel` and its components, and the CRTBP
(:func:`propagate_crtbp`, :func:`jacobi_constant`, :class:`EarthMoonUnits`).
"""

from odpipe.dynamics.crtbp import EarthMoonUnits, jacobi_constant, propagate_crtbp
from odpipe.dynamics.forces import (AtmosphericDrag, Cylinder, EmpiricalRTN, FiniteBurn, ForceModel,
                                    ImpulsiveManeuver, InertialPolynomialAcceleration, Plate, PointMasses,
                                    Relativity, SolarRadiationPressure, SphericalHarmonics)
from odpipe.dynamics.propagator import propagate, propagate_many
from odpipe.dynamics.trajectory import Trajectory, TrajectorySet

__all__ = [
    "AtmosphericDrag", "Cylinder", "EarthMoonUnits", "EmpiricalRTN", "FiniteBurn", "ForceModel", "ImpulsiveManeuver",
    "InertialPolynomialAcceleration", "Plate",
    "PointMasses", "Relativity", "SolarRadiationPressure", "SphericalHarmonics", "Trajectory",
    "TrajectorySet", "jacobi_constant", "propagate", "propagate_crtbp", "propagate_many",
]
