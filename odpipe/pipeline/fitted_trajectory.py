"""The fitted trajectory as products: dense states, split at maneuvers, with covariances."""

from __future__ import annotations

import numpy as np

from odpipe.products.segments import EphemerisSegment


def product_epochs(a: float, b: float, step: float) -> np.ndarray:
    """Epochs (TDB s) every ``step`` s over [a, b] on whole microseconds, as the nearest doubles: the
    first is the first whole µs at or after ``a``, the last the last one at or before ``b``."""
    k0, k1 = np.ceil(a * 1e6), np.floor(b * 1e6)
    t0, t1 = (k0 + (k0 / 1e6 < a)) / 1e6, (k1 - (k1 / 1e6 > b)) / 1e6
    return np.unique(np.round(np.append(np.arange(t0, t1, step), t1) * 1e6) / 1e6)


def fitted_segments(arc, step: float = 60.0) -> list[EphemerisSegment]:
    """The smoothed trajectory every ``step`` s, one product segment per maneuver-free span.

    Inside each dynamics segment of the fit (cut at maneuvers and stochastic
    batches) the trajectory is the one through the smoothed state and
    parameters at its start: for a converged fit the fit's last reference
    corrected to first order (``problem.linearized``: no integration; the
    correction is below the convergence tolerance, its square negligible),
    otherwise integrated from them.
    At a maneuver the next segment starts after the burn, so a span ending at
    a maneuver ends with the state before it. Covariances are the smoothed
    ones at the filter grid epochs of the span.

    Product epochs lie on whole microseconds (the first rounded up, the last
    down, inside the span), the resolution of the OEM's time tags, so an OEM
    epoch read back (e.g. by SPICE's ``str2et``) is exactly an SPK epoch: the
    SPK covers every OEM epoch, its first and last included.
    """
    sol, sc, problem = arc.solution, arc.spacecraft, arc.problem
    grid, X = sol.grid, sol.smoothed_x
    _, _, P = sol.states(sc)
    center = problem.force_models[sc].center
    burns = sorted(float(e) for e in arc.maneuvers["epoch"]) if len(arc.maneuvers) else []
    cuts = [grid[0], *[e for e in burns if grid[0] < e < grid[-1]], grid[-1]]
    segments = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        t = product_epochs(a, b, step)
        states = np.empty((t.size, 6))
        start = a
        while start < b:
            k = int(np.searchsorted(grid, start, "left"))  # dynamics segments start on grid epochs
            near = problem.linearized(grid[k], X[k]) if arc.converged else None
            if near is None:
                end, trajs, _ = problem.trajectories(grid[k], X[k])
                near = end, {sc: trajs[sc].state}
            end, state = near[0], near[1][sc]
            sel = (t >= start) & ((t < end) | (end >= b))
            states[sel] = state(t[sel])
            start = end
        on = (grid >= a) & (grid <= b)
        segments.append(EphemerisSegment(t, states, center, P[on], grid[on]))
    return segments
