"""The fitted trajectory as products: dense states, split at maneuvers, with covariances."""

from __future__ import annotations

import numpy as np

from odpipe.products.ephemeris import EphemerisSegment


def fitted_segments(arc, step: float = 60.0) -> list[EphemerisSegment]:
    """The smoothed trajectory every ``step`` s, one product segment per maneuver-free span.

    Inside each dynamics segment of the fit (cut at maneuvers and stochastic
    batches) the trajectory is the reference integrated from the smoothed
    state and parameters at its start: exactly what the fit linearized about.
    At a maneuver the next segment starts after the burn, so a span ending at
    a maneuver ends with the state before it. Covariances are the smoothed
    ones at the filter grid epochs of the span.
    """
    sol, sc, problem = arc.solution, arc.spacecraft, arc.problem
    grid, X = sol.grid, sol.smoothed_x
    _, _, P = sol.states(sc)
    center = problem.force_models[sc].center
    burns = sorted(float(e) for e in arc.maneuvers["epoch"]) if len(arc.maneuvers) else []
    cuts = [grid[0], *[e for e in burns if grid[0] < e < grid[-1]], grid[-1]]
    segments = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        t = np.append(np.arange(a, b, step), b)
        states = np.empty((t.size, 6))
        start = a
        while start < b:
            k = int(np.searchsorted(grid, start, "left"))  # dynamics segments start on grid epochs
            end, trajs, _ = problem.trajectories(grid[k], X[k])
            sel = (t >= start) & ((t < end) | (end >= b))
            states[sel] = trajs[sc].state(t[sel])
            start = end
        on = (grid >= a) & (grid <= b)
        segments.append(EphemerisSegment(t, states, center, P[on], grid[on]))
    return segments
