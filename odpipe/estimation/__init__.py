"""Estimation core: parameter registry, SRIF, SRIS smoother, batch least squares,
iterated filter-smoother fit, maneuver products.

    from odpipe.estimation import ParameterRegistry, fit, FitOptions, Observations
    reg = ParameterRegistry(); reg.add_state("sc", x0, 1e5, 1.0); ...
    sol = fit(problem, Observations(t, value, sigma, group), t0, t1, FitOptions())

``problem`` satisfies :class:`~odpipe.estimation.fit.Problem`: ``transition`` and
``predict`` in registry coordinates (see :mod:`.fit`); :class:`odpipe.od.TrackingProblem`
builds one from odpipe.dynamics and odpipe.measurements.
"""

from .least_squares import BatchSolution, batch_least_squares
from .fit import EDIT_INNOVATION, OUTSIDE_ARC, FitOptions, Observations, Problem, fit
from .maneuvers import ManeuverFinding, detect_maneuvers, maneuver_table
from .registry import GaussMarkov, Parameter, ParameterRegistry
from .smoother import smooth
from .solution import Solution
from .srif import SRIF, Gaussian

__all__ = ["BatchSolution", "batch_least_squares", "EDIT_INNOVATION", "OUTSIDE_ARC", "FitOptions",
           "Observations", "Problem", "fit", "ManeuverFinding", "detect_maneuvers",
           "maneuver_table", "GaussMarkov", "Parameter", "ParameterRegistry", "smooth",
           "Solution", "SRIF", "Gaussian"]
