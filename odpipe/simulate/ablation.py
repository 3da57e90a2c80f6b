"""The ARTEMIS twin's error sources, each switchable off: a loaded case without one of them.

Each entry of :data:`SOURCES` names an error source of the thesis' budget (seed 004 ch. 4) the
twin carries and turns it off in a :class:`~odpipe.simulate.case.Case` (``benchmarks/artemis_ablation.py``
refits the case once per entry and reports what each contributes). A source is set to zero, not removed,
so that the same random numbers are drawn: the variants differ by the source only, not by the noise.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np


def _unmodelled(case, **changes):
    return replace(case, unmodelled=None if case.unmodelled is None else replace(case.unmodelled, **changes))


SOURCES = {
    "real-body SRP (truth flies the filter's cylinder)": lambda c: replace(c, truth_body=replace(
        c.truth_body, bus_side_m=np.pi * c.body.radius_m / 2, plate_area_m2=0.0, axis_tilt_deg=0.0)),
    "outgassing": lambda c: _unmodelled(c, outgassing_m_s2=0.0),
    "thruster plume": lambda c: _unmodelled(c, plume_fraction=0.0),
    "attitude burns known only by time (plan carries their delta-v)":
        lambda c: replace(c, maneuvers=[dict(m, planned=True) for m in c.maneuvers]),
    "media calibration errors": lambda c: replace(c, media=replace(c.media, error_wet_m=0.0, error_dry_m=0.0,
                                                                   error_ion_m=0.0)),
    "burns designed on an OD state (on the truth)":
        lambda c: replace(c, station_keeping=replace(c.station_keeping, nav_sigma_m=0.0, nav_sigma_m_s=0.0)),
}


def without(case, source: str):
    """``case`` with the error source ``source`` (a key of :data:`SOURCES`) switched off."""
    return SOURCES[source](case)
