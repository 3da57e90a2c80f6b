"""Two spacecraft in the Earth-Moon CRTBP tracked only by each other (LiAISON).

State vector (SI, rotating barycentric frame): ``[r1, v1, r2, v2]`` (m, m/s).
Rows are instantaneous crosslink range (kind 0) or range-rate (kind 1) from
:mod:`odpipe.measurements.instantaneous`; dynamics from :mod:`odpipe.dynamics.crtbp`
(integrated nondimensionally). :class:`CrosslinkProblem` is the
:class:`odpipe.estimation.fit.Problem` the fit needs.
"""

from __future__ import annotations

import numpy as np

from odpipe.dynamics.crtbp import EarthMoonUnits, propagate_crtbp
from odpipe.measurements.instantaneous import instantaneous_range, instantaneous_range_rate

RANGE, RANGE_RATE = 0, 1


def units_from_mu(length: float, gm_total: float, mu: float) -> EarthMoonUnits:
    """CRTBP units with a prescribed mass ratio: length (m), GM1 + GM2 (m^3/s^2)."""
    return EarthMoonUnits(length=length, gm1=(1 - mu) * gm_total, gm2=mu * gm_total)


def state_scale(units: EarthMoonUnits) -> np.ndarray:
    """D with x_SI = D x_nondim for one 6-vector."""
    return np.diag([units.length] * 3 + [units.length / units.time] * 3)


def flow(units: EarthMoonUnits, x0: np.ndarray, t0: float, times) -> tuple[np.ndarray, np.ndarray]:
    """SI states (N, 6) and STMs (N, 6, 6) at ``times`` (s) from x0 (SI) at t0 (s)."""
    times = np.atleast_1d(np.asarray(times, float))
    T = units.time
    t_end = max(float(times.max()), t0 + 1e-9 * T)
    tr = propagate_crtbp(units.from_si(x0), t0 / T, t_end / T, units.mu)
    D = state_scale(units)
    return units.to_si(tr.state(times / T)), D @ tr.stm(times / T) @ np.linalg.inv(D)


def crosslink_rows(X1: np.ndarray, X2: np.ndarray, t: np.ndarray, kind: np.ndarray):
    """Values (m or m/s) and partials w.r.t. [x1(t), x2(t)] (N, 12) of crosslink rows."""
    z = np.empty(t.size)
    H = np.zeros((t.size, 12))
    for k, model in ((RANGE, instantaneous_range), (RANGE_RATE, instantaneous_range_rate)):
        sel = kind == k
        if not sel.any():
            continue
        c = model(X1[sel], X2[sel], t[sel])
        z[sel] = c.value
        for e, cols in zip(c.events, (slice(0, 6), slice(6, 12))):
            H[sel, cols] = np.concatenate([e.d_pos, e.d_vel], axis=1)
    return z, H


class CrosslinkProblem:
    """fit() adapter: registry [sc1 (6), sc2 (6)] in SI; rows at ``times`` of ``kind``."""

    def __init__(self, registry, units: EarthMoonUnits, times: np.ndarray, kind: np.ndarray):
        self.registry, self.units, self.times, self.kind = registry, units, times, kind

    def transition(self, t0, t1, x0):
        x1, Phi = x0.copy(), np.eye(12)
        for s in (slice(0, 6), slice(6, 12)):
            X, P = flow(self.units, x0[s], t0, [t1])
            x1[s], Phi[s, s] = X[0], P[0]
        return x1, Phi

    def predict(self, t0, x0, rows):
        t = self.times[rows]
        X1, P1 = flow(self.units, x0[:6], t0, t)
        X2, P2 = flow(self.units, x0[6:], t0, t)
        z, H = crosslink_rows(X1, X2, t, self.kind[rows])
        return z, np.concatenate([np.einsum("mj,mjk->mk", H[:, :6], P1),
                                  np.einsum("mj,mjk->mk", H[:, 6:], P2)], axis=1)
