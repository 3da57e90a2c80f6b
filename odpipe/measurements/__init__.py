"""Measurement models: computed observables and their partials, vectorized over rows.

Entry point for estimation::

    from odpipe.measurements import MeasurementSetup, compute, residuals
    setup = MeasurementSetup.default(ramps=ramp_store)        # DE440, station catalog, Earth orientation
    ev = compute(rows, {"181": traj}, setup)                   # rows: a TrackingTable slice
    ev.value, ev.to_los, ev.status                             # (N,), row units; m or m/s per unit; why NaN
    ev.partials["state:181"]                                   # (N,6) d value / d epoch state (via traj.stm)
    ev.partials["dynamic:181"], ev.names["dynamic:181"]        # (N,p) via traj.sensitivity, traj.param_names
    ev.partials["station:DSS-14"], ev.partials["bias"], ...    # see odpipe.measurements.compute
    res, res_los = residuals(rows, ev)                         # observed - computed, and along the LOS

Layers (each a small module):

* :mod:`.bands` - c, turnaround ratios M2, range-unit factors F.
* :mod:`.nodes` - stations (ITRS -> GCRS with EOP, + Earth from the ephemeris) and spacecraft
  (trajectory + its centre) as states in the solve frame; station TDB - TT.
* :mod:`.lighttime` - Newton light-time solution along a path of nodes in the SSB frame
  (or centre-relative), Shapiro delay, partials of the total light time; numba kernel.
* :mod:`.dsn` - two/three-way range (RU, m, s), two/three-way and one-way Doppler (Moyer ch. 13;
  positive when receding; ramped via :class:`parsers.ramps.RampStore`).
* :mod:`.angles` - az/el and X/Y at reception.
* :mod:`.instantaneous` - geometric range and range-rate (Leonard thesis 3.11).
* :mod:`.crosslink` - LiAISON two-way range/Doppler and dual one-way ranging with clocks.
* :mod:`.partials` - event partials composed with STM/sensitivities and station rotations.
* :mod:`.compute`, :mod:`.residuals` - the table-level entry point and residuals.

Time: model epochs are TDB s past J2000 with a correction term carried through the light-time
solution; tags are reception times (UTC) unless a crosslink is anchored at transmission.
"""

from .compute import Evaluation, MeasurementSetup, compute
from .residuals import residuals

__all__ = ["Evaluation", "MeasurementSetup", "compute", "residuals"]
