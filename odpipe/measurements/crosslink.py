"""Spacecraft-to-spacecraft (LiAISON) observables: two-way range and Doppler, dual one-way ranging.

* **Two-way** over the path ``[sc1, sc2, sc1]`` (Fujimoto et al., eqs. 1-4):
  round-trip light path length RTLPL = c (LT12 + LT21), solved exactly (not with
  the paper's linear extrapolation, eq. 2). Range = RTLPL/2 (m). Doppler = the
  change of RTLPL over the count interval, ``(RTLPL(t) - RTLPL(t - Tc)) / Tc``
  (m/s of round-trip path, about twice the range-rate; ``to_los`` = 1/2),
  positive when the spacecraft separate. The paper tags t at sc1's
  transmission (``anchor='transmit'``); ``anchor='receive'`` tags at sc1's reception.
* **Dual one-way ranging** (Li et al., eqs. 1-5, 9-10): each spacecraft
  receives the other's signal at the same epoch t; the pseudorange received
  by B from A is ``R_AB = c tau_AB + c (dtau_B(t) - dtau_A(t - tau_AB))`` with
  the clock polynomial ``dtau(t) = a0 + a1 (t - t_ref) + a2/2 (t - t_ref)^2`` (s).
  Combinations: sum ``(R_21 + R_12)/2`` keeps the geometry, difference
  ``(R_21 - R_12)/2`` (received by sc1 minus received by sc2) keeps the clocks:
  d diff/d(c a0 of sc1) = 1, d/d(c a1) = t - t_ref - tau_12/2,
  d/d(c a2) = ((t - t_ref)^2 + (t - tau_12 - t_ref)^2)/4, as the paper's eq. 10.
  Equipment delays enter as the 'bias' (m) of each combination.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from odpipe.constants import C_LIGHT

from .computed import Computed, EventPartial


@dataclass
class ClockModel:
    """Clock offset from TDB: a0 (s) + a1 (s/s) dt + a2/2 (1/s) dt^2, dt = t - t_ref (TDB s)."""

    a0: float = 0.0
    a1: float = 0.0
    a2: float = 0.0
    t_ref: float = 0.0

    def offset(self, t):
        dt = np.asarray(t, dtype=float) - self.t_ref
        return self.a0 + self.a1 * dt + 0.5 * self.a2 * dt**2

    def rate(self, t):
        return self.a1 + self.a2 * (np.asarray(t, dtype=float) - self.t_ref)

    def basis(self, t):
        """d (c * offset) / d (c a0, c a1, c a2): (N,3) in 1, s, s^2."""
        dt = np.asarray(t, dtype=float) - self.t_ref
        return np.stack([np.ones_like(dt), dt, 0.5 * dt**2], axis=1)


_CLOCK_KEYS = ("a0", "a1", "a2")


def _path_events(sol, roles, gain):
    return [EventPartial(r, sol.epochs[:, i], gain[:, None] * sol.dlt_dr[:, i]) for i, r in enumerate(roles)]


def two_way_range(sol) -> Computed:
    """Half the round-trip light path (m) of ``[sc1, sc2, sc1]`` solutions; parameter 'bias' (m)."""
    gain = np.full(sol.light_time.shape, C_LIGHT / 2)
    return Computed(gain * sol.light_time, "m", _path_events(sol, ("sc1", "sc2", "sc1"), gain),
                    {"bias": np.ones_like(gain)})


def two_way_doppler(sol_s, sol_e, count_time) -> Computed:
    """Change of the round-trip light path over the count time (m/s), solutions at the interval's start and end."""
    tc = np.asarray(count_time, dtype=float)
    dt = sol_e.light_time - sol_s.light_time
    gain = np.broadcast_to(C_LIGHT / tc, dt.shape)
    events = (_path_events(sol_e, ("sc1", "sc2", "sc1"), gain)
              + _path_events(sol_s, ("sc1", "sc2", "sc1"), -gain))
    return Computed(gain * dt, "m/s", events, {"bias": np.ones_like(dt)}, to_los=0.5)


def one_way_pseudorange(sol, clock_tx: ClockModel, clock_rx: ClockModel, roles=("sc2", "sc1")) -> Computed:
    """Pseudorange (m) of a receive-anchored ``[tx, rx]`` solution with both clocks; roles name tx, rx."""
    t_tx, t_rx = sol.epochs[:, 0] + sol.epoch_corr[:, 0], sol.epochs[:, 1] + sol.epoch_corr[:, 1]
    value = C_LIGHT * (sol.light_time + clock_rx.offset(t_rx) - clock_tx.offset(t_tx))
    gain = C_LIGHT * (1.0 + clock_tx.rate(t_tx))  # the transmit epoch moves with the light time
    params = {"bias": np.ones_like(value)}
    for k, col in zip(_CLOCK_KEYS, range(3)):
        params[f"clock_{roles[1]}_{k}"] = clock_rx.basis(t_rx)[:, col]
        params[f"clock_{roles[0]}_{k}"] = -clock_tx.basis(t_tx)[:, col]
    return Computed(value, "m", _path_events(sol, roles, gain), params)


def dual_one_way(sol_21, sol_12, clock1: ClockModel, clock2: ClockModel) -> tuple[Computed, Computed]:
    """(sum, difference) combinations of pseudoranges received at the same epoch.

    ``sol_21``: path [sc2, sc1] (received by sc1), ``sol_12``: path [sc1, sc2]
    (received by sc2), both anchored at the same reception epochs.
    """
    r21 = one_way_pseudorange(sol_21, clock2, clock1, ("sc2", "sc1"))
    r12 = one_way_pseudorange(sol_12, clock1, clock2, ("sc1", "sc2"))
    return _combine(r21, r12, 0.5, 0.5), _combine(r21, r12, 0.5, -0.5)


def _combine(a: Computed, b: Computed, wa: float, wb: float) -> Computed:
    events = [EventPartial(e.role, e.t, wa * e.d_pos) for e in a.events]
    events += [EventPartial(e.role, e.t, wb * e.d_pos) for e in b.events]
    keys = [k for k in a.params if k != "bias"]
    params = {k: wa * a.params[k] + wb * b.params[k] for k in keys}
    params["bias"] = np.ones_like(a.value)
    return Computed(wa * a.value + wb * b.value, "m", events, params)
