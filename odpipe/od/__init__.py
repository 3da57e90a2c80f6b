"""Orbit determination of a TrackingTable: the glue between dynamics, measurements and the SRIF.

* :mod:`.segment` - reference trajectory of one segment (STM, sensitivities, look-back).
* :mod:`.problem` - :class:`TrackingProblem`, the estimation ``Problem`` over table rows.
* :mod:`.arc` - :func:`fit_arc` with :class:`ArcSetup` -> :class:`ArcSolution`.
* :mod:`.simulate` - simulated DSN Doppler and range of a known trajectory.
"""

from .arc import ArcSetup, ArcSolution, ManeuverPlan, fit_arc
from .problem import TrackingProblem
from .simulate import TrackingPlan, simulate_tracking

__all__ = ["ArcSetup", "ArcSolution", "ManeuverPlan", "TrackingPlan", "TrackingProblem", "fit_arc",
           "simulate_tracking"]
