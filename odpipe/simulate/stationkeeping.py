"""Station-keeping of an Earth-Moon libration orbit: perpendicular x-z plane crossings.

A maneuver at t is the delta-v of least norm that makes the rotating-frame x
velocity vanish at the first crossing of the x-z plane (y = 0, pulsating
Earth-Moon frame) later than t + ``gap`` — the classic crossing control that
removes the unstable component. Gaps are tried in order of preference and the
first that converges is flown, unless its delta-v exceeds ``max_dv``: Newton may
converge on a far root (a 3.4 m/s design for a 7-day gap in the ARTEMIS twin
designed on its true state, where a 5-day gap takes 0.42 m/s), which an operations
team would not fly; the next gap is tried. A crossing soon after the burn gives little
leverage on the unstable mode: in the ARTEMIS-like case a 3-day gap needs up to
1.1 m/s a week, a 7-day gap 1-4 cm/s. Solved by Newton steps along the
finite-difference gradient (steps clipped to ``max_step`` m/s), with the
design force model (no stochastic accelerations, no execution errors).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.optimize import brentq

from odpipe.constants import SECONDS_PER_DAY
from odpipe.dynamics import propagate
from odpipe.simulate.libration import icrf_to_rotating

GRID_S = 1800.0


def crossing_vx(force_model, state, t: float, gap: float, horizon: float) -> float:
    """Rotating x velocity (nondimensional) at the first y = 0 crossing in [t + gap, t + horizon] (NaN if none)."""
    eph = force_model.ephemeris
    mu = eph.gm("moon") / (eph.gm("moon") + eph.gm("earth"))
    tr = propagate(state, t, t + horizon, force_model, with_stm=False)

    def rot(ts):
        return icrf_to_rotating(tr.state(ts), mu, eph.state("moon", "earth", ts))

    ts = t + np.arange(gap, horizon, GRID_S)
    y = rot(ts)[:, 1]
    if not np.isfinite(y).all():
        return np.nan
    k = np.flatnonzero(np.sign(y[1:]) != np.sign(y[:-1]))
    if not k.size:
        return np.nan
    tc = brentq(lambda q: rot(np.array([q]))[0, 1], ts[k[0]], ts[k[0] + 1], xtol=1e-3)
    return float(rot(np.array([tc]))[0, 3])


def design_dv(force_model, state, t: float, gaps=(7 * SECONDS_PER_DAY,), horizon: float = 8 * SECONDS_PER_DAY,
              max_dv: float | None = None) -> np.ndarray:
    """ICRF delta-v (3,) m/s at TDB ``t``: the crossing design of the first of ``gaps`` (s) that converges to at
    most ``max_dv`` (m/s; None: any)."""
    for gap in gaps:
        dv = _crossing_dv(force_model, state, t, gap, gap + horizon)
        if dv is not None and (max_dv is None or np.linalg.norm(dv) <= max_dv):
            return dv
    raise ValueError(f"no station-keeping solution at t={t:.0f} for gaps {gaps}"
                     + (f" within {max_dv} m/s" if max_dv is not None else ""))


def _crossing_dv(force_model, state, t, gap, horizon, max_step: float = 0.5, iterations: int = 12):
    """Delta-v for a perpendicular crossing after ``t + gap``, or None when Newton fails."""
    fm = replace(force_model, components=[c for c in force_model.components if not hasattr(c, "dv")])

    def f(dv):
        x = np.array(state, float)
        x[3:] += dv
        return crossing_vx(fm, x, t, gap, horizon)

    dv = np.zeros(3)
    for _ in range(iterations):
        r = f(dv)
        g = np.array([(f(dv + 1e-3 * e) - r) / 1e-3 for e in np.eye(3)])
        if not (np.isfinite(r) and np.isfinite(g).all()):
            return None
        step = -r * g / (g @ g)
        dv = dv + step * min(1.0, max_step / np.linalg.norm(step))
        if abs(r) < 1e-8:          # 1e-8 of ~1 km/s: 1e-5 m/s of crossing velocity
            return dv
    return None
