"""Orbit determination of a TrackingTable: the glue between dynamics, measurements and the SRIF.

* :mod:`.segment` - reference trajectory of one segment (STM, sensitivities, look-back).
* :mod:`.problem` - :class:`TrackingProblem`, the estimation ``Problem`` over table rows.
* :mod:`.arc` - :func:`fit_arc` with :class:`ArcSetup` -> :class:`ArcSolution`.

Simulated tracking of a known trajectory, to fit against the truth, is :mod:`odpipe.simulate`.
"""

from .arc import ArcSetup, ArcSolution, ManeuverPlan, fit_arc
from .problem import TrackingProblem

__all__ = ["ArcSetup", "ArcSolution", "ManeuverPlan", "TrackingProblem", "fit_arc"]
