"""Light-time solution along a path of nodes, with the Shapiro delay, and its partials.

A *path* is a list of nodes the signal visits in order, e.g.
``[station_tx, spacecraft, station_rx]`` for two- or three-way data,
``[spacecraft, station]`` for one-way, ``[sc1, sc2, sc1]`` for a crosslink
round trip. One epoch is known, the *anchor*: the reception at the last node
(``anchor='receive'``, the DSN convention: data are tagged at reception) or the
transmission at the first node (``anchor='transmit'``, as in the LiAISON paper's
eq. 1-3). Each leg is solved with Newton's method for

    c*tau = |r_R(t_R) - r_T(t_T)| + sum_B (1+gamma) GM_B/c^2 ln((r1+r2+r12+k)/(r1+r2-r12+k)),  k = (1+gamma) GM_B/c^2

with t_R - t_T = tau, gamma = 1, r1 and r2 the distances of transmitter and
receiver from body B (Moyer eq. 8-38). Body positions are taken at the leg's
known end and moved linearly over tau (error < 1 cm in r1, r2, below 1e-6 m of delay).

Frames: all node states must share one origin. ``'ssb'`` is the
relativistically correct solution (BCRS, TDB). A centre-relative origin
(e.g. ``'earth'`` for cislunar crosslinks) treats the centre as unaccelerated
over the light time and drops the difference between BCRS-difference and
local coordinates. For two-way data the first-order terms in the centre's
velocity V cancel; the second-order remainder 2L V^2/(2c^2)(1+cos^2 theta) is 4-8 m of
round-trip path at lunar distance for the Earth's 30 km/s (tested). Use it for Newtonian
crosslink studies like the LiAISON papers, not for fitting DSN data.

Epochs are TDB s past J2000 as float64 plus a small correction (s): each
evaluated epoch is ``fl(t)``; the rounding residual is carried in
``epoch_corr`` and the node's position moved by ``v*corr``, so light times keep
full precision though an epoch near 2025 has an ulp of 0.12 us.

Partials: ``dlt_dr[:, i, :]`` is d(total light time t_last - t_first)/d(position
of node i at its event), s/m, for a perturbation of that node's trajectory
through its event point (velocity partials at the events are zero; they enter
through the state transition matrix). Derivation per leg, with n the unit vector
transmitter->receiver and v_free the velocity of the end whose epoch floats:
``dtau = [n.(dr_R - dr_T) + n.(v_R - v_T) dt_known] / (c - n.v_free)``; the legs are
chained through their shared epochs. The Shapiro term's own derivative
(< 1e-8 of the geometric one) is left out.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Sequence

import numba
import numpy as np

from odpipe.constants import C_LIGHT

from .nodes import origin_state

_MAXITER = 12
_TOL = 1e-9  # s: a Newton step this small leaves an error below 1e-25 s (applied without re-evaluating)


def _leg_newton_step(r_rx, r_tx, v_free, tau, bpos, bvel, kb, direction):
    """:func:`_leg_newton_kernel` on C-contiguous copies where the inputs are column slices: one compiled
    signature, whether a slice of one row (C-contiguous to numpy) or of many (strided) is passed."""
    c = np.ascontiguousarray
    return _leg_newton_kernel(c(r_rx), c(r_tx), c(v_free), c(tau), c(bpos), c(bvel), c(kb), float(direction))


@numba.njit(cache=True)
def _leg_newton_kernel(r_rx, r_tx, v_free, tau, bpos, bvel, kb, direction):
    """One Newton step for every row of a leg.

    r_rx, r_tx: (N,3) receiver/transmitter positions at the current iterate;
    v_free: (N,3) velocity of the floating end; bpos, bvel: (B,N,3) bodies at the
    known end; kb: (B,) (1+gamma)GM/c^2 in m; direction: +1 when the free end is
    the receiver (anchor transmit), -1 when it is the transmitter.
    Returns (new tau, Shapiro delay in s).
    """
    n = r_rx.shape[0]
    nb = kb.shape[0]
    out = np.empty(n)
    shap = np.empty(n)
    for i in range(n):
        dx = r_rx[i, 0] - r_tx[i, 0]
        dy = r_rx[i, 1] - r_tx[i, 1]
        dz = r_rx[i, 2] - r_tx[i, 2]
        r12 = np.sqrt(dx * dx + dy * dy + dz * dz)
        s = 0.0
        for b in range(nb):
            # body at the known end, and moved over tau to the free end
            fx = bpos[b, i, 0] + direction * bvel[b, i, 0] * tau[i]
            fy = bpos[b, i, 1] + direction * bvel[b, i, 1] * tau[i]
            fz = bpos[b, i, 2] + direction * bvel[b, i, 2] * tau[i]
            if direction > 0:  # free end = receiver
                rxb = (r_rx[i, 0] - fx, r_rx[i, 1] - fy, r_rx[i, 2] - fz)
                txb = (r_tx[i, 0] - bpos[b, i, 0], r_tx[i, 1] - bpos[b, i, 1], r_tx[i, 2] - bpos[b, i, 2])
            else:
                rxb = (r_rx[i, 0] - bpos[b, i, 0], r_rx[i, 1] - bpos[b, i, 1], r_rx[i, 2] - bpos[b, i, 2])
                txb = (r_tx[i, 0] - fx, r_tx[i, 1] - fy, r_tx[i, 2] - fz)
            r2 = np.sqrt(rxb[0] ** 2 + rxb[1] ** 2 + rxb[2] ** 2)
            r1 = np.sqrt(txb[0] ** 2 + txb[1] ** 2 + txb[2] ** 2)
            s += kb[b] * np.log((r1 + r2 + r12 + kb[b]) / (max(r1 + r2 - r12, 0.0) + kb[b]))
        ndotv = (dx * v_free[i, 0] + dy * v_free[i, 1] + dz * v_free[i, 2]) / r12
        f = C_LIGHT * tau[i] - r12 - s
        out[i] = tau[i] - f / (C_LIGHT - ndotv)
        shap[i] = s / C_LIGHT
    return out, shap


@dataclass
class PathSolution:
    """Converged light-time solution of N paths of k+1 events.

    epochs (N,k+1) s TDB as evaluated, epoch_corr (N,k+1) s to add for the exact
    event epoch; states (N,k+1,6) at the exact events (solve frame);
    leg_time (N,k) s TDB including Shapiro; shapiro (N,k) s; clock (N,k+1) s:
    TDB minus each node's clock at its event; dlt_dr (N,k+1,3) s/m (see module doc);
    rate (N,): d(total light time)/d(anchor epoch), dimensionless (the limit of a
    count-averaged Doppler as the count time goes to 0, over c).
    """

    epochs: np.ndarray
    epoch_corr: np.ndarray
    states: np.ndarray
    leg_time: np.ndarray
    shapiro: np.ndarray
    clock: np.ndarray
    dlt_dr: np.ndarray
    rate: np.ndarray

    @property
    def light_time(self) -> np.ndarray:
        """Total light time t_last - t_first in TDB seconds, (N,)."""
        return self.leg_time.sum(axis=1)

    @property
    def clock_time(self) -> np.ndarray:
        """Total light time counted by the end nodes' clocks (s): TDB interval minus the clock terms."""
        return self.light_time - (self.clock[:, -1] - self.clock[:, 0])

    def take(self, idx) -> "PathSolution":
        """The solutions of paths ``idx`` (an index array)."""
        return PathSolution(*(getattr(self, f.name)[idx] for f in fields(self)))


def _shifted(t, corr, dt):
    """Evaluate-able epoch fl(t + dt) and the exact residual so that t + corr + dt = te + ce."""
    te = t + dt
    return te, ((t - te) + dt) + corr


def _state_at(node, te, ce):
    s = np.array(node.state(te), dtype=float)
    s[:, :3] += s[:, 3:] * ce[:, None]
    return s


def solve_path(nodes: Sequence, t_anchor, anchor: str = "receive", t_corr=None,
               shapiro_bodies: Sequence[str] = ("sun",), ephemeris=None, origin: str = "ssb",
               gm: dict | None = None) -> PathSolution:
    """Solve the light time along ``nodes`` from the anchor epoch ``t_anchor`` (TDB s, (N,)).

    ``shapiro_bodies`` names bodies whose Shapiro delay is included (their GM
    from ``gm`` or ``ephemeris.gm``; states from ``ephemeris`` relative to
    ``origin``). The Sun's delay is up to ~40 m near conjunction; the Earth's
    up to ~4 cm on an Earth-Moon leg; the Moon's below 1 mm except for grazing rays.
    """
    if anchor not in ("receive", "transmit"):
        raise ValueError(f"anchor must be 'receive' or 'transmit', not {anchor!r}")
    t_anchor = np.atleast_1d(np.asarray(t_anchor, dtype=float))
    n, k = t_anchor.size, len(nodes) - 1
    corr0 = np.zeros(n) if t_corr is None else np.broadcast_to(np.asarray(t_corr, dtype=float), (n,))
    kb = np.array([2.0 * (gm[b] if gm and b in gm else ephemeris.gm(b)) / C_LIGHT**2 for b in shapiro_bodies])

    order = range(k, -1, -1) if anchor == "receive" else range(k + 1)
    order = list(order)
    direction = -1.0 if anchor == "receive" else 1.0
    epochs = np.empty((n, k + 1))
    corr = np.empty((n, k + 1))
    states = np.empty((n, k + 1, 6))
    leg_time = np.empty((n, k))
    shapiro = np.empty((n, k))

    i0 = order[0]
    epochs[:, i0], corr[:, i0] = t_anchor, corr0
    states[:, i0] = _state_at(nodes[i0], t_anchor, corr0)
    for known, free in zip(order[:-1], order[1:]):
        leg = min(known, free)  # leg index: from node leg to node leg+1
        tk, ck, sk = epochs[:, known], corr[:, known], states[:, known]
        bodies = [origin_state(ephemeris, b, origin, tk) for b in shapiro_bodies]
        bpos = np.array([b[:, :3] for b in bodies]).reshape(len(bodies), n, 3)
        bvel = np.array([b[:, 3:] for b in bodies]).reshape(len(bodies), n, 3)
        if known == i0:  # first leg: from the free node's state at the anchor epoch, to second order
            tau = _first_guess(sk[:, :3], nodes[free].state(tk), bpos, bvel, kb, direction)
        else:  # later legs start from the previous leg's light time (off by ~ v tau / c, one Newton step)
            tau = tau.copy()
        for _ in range(_MAXITER):
            te, ce = _shifted(tk, ck, direction * tau)
            sf = _state_at(nodes[free], te, ce)
            r_rx, r_tx = (sk[:, :3], sf[:, :3]) if anchor == "receive" else (sf[:, :3], sk[:, :3])
            new, shap = _leg_newton_step(r_rx, r_tx, sf[:, 3:], tau, bpos, bvel, kb, direction)
            step = direction * (new - tau)
            tau = new
            if np.max(np.abs(step)) < _TOL:
                # the remaining Newton error is ~ (rho''/2c) step^2 < 1e-25 s: move the state, no new evaluation
                ce = ce + step
                sf[:, :3] += sf[:, 3:] * step[:, None]
                break
        else:
            raise RuntimeError(f"light time did not converge on leg {leg}: last step {np.max(np.abs(step)):.3e} s")
        epochs[:, free], corr[:, free] = te, ce
        states[:, free] = sf
        leg_time[:, leg] = tau
        shapiro[:, leg] = shap

    clock = np.stack([nodes[i].tdb_minus_clock(epochs[:, i], states[:, i]) for i in range(k + 1)], axis=1)
    return PathSolution(epochs, corr, states, leg_time, shapiro, clock, *_chain_partials(states, anchor))


def _first_guess(r_known, s_free, bpos, bvel, kb, direction) -> np.ndarray:
    """Light time (s) of a leg from the free node's state ``s_free`` at the known end's epoch: the Newton step
    from zero, then the path's curvature in it, tau = tau_1 (1 + q tau_1 / (c - n.v)) with q = |v_perp|^2 / (2 rho)
    (the free end moving at v over tau: rho(tau) = rho + n.v tau + q tau^2). Off by the free end's acceleration,
    a tau^2 / 2c (4e-11 s for a cislunar leg, below the Newton tolerance), where the distance alone was off by
    v tau / c (1.7e-5 s for a spacecraft at 30 km/s from the SSB) and took another
    evaluation of the free node."""
    r_rx, r_tx = (r_known, s_free[:, :3]) if direction < 0 else (s_free[:, :3], r_known)
    v = s_free[:, 3:]
    tau, _ = _leg_newton_step(r_rx, r_tx, v, np.zeros(len(v)), bpos, bvel, kb, direction)
    d = r_rx - r_tx
    rho = np.sqrt(np.einsum("ni,ni->n", d, d))
    nv = np.einsum("ni,ni->n", d, v) / rho
    q = 0.5 * (np.einsum("ni,ni->n", v, v) - nv * nv) / rho
    return tau * (1.0 + q * tau / (C_LIGHT - nv))


def _chain_partials(states: np.ndarray, anchor: str) -> tuple[np.ndarray, np.ndarray]:
    """d(t_last - t_first)/d(event positions) (N,k+1,3) s/m, and d(t_last - t_first)/d(anchor), by chaining legs."""
    return _chain_kernel(np.ascontiguousarray(states), anchor == "receive")


@numba.njit(cache=True)
def _chain_kernel(states, receive):
    """Per row: walk the legs away from the anchor, carrying the gradient of the floating epoch.

    Receive anchor: dt_{j-1} = (1-b) dt_j - a.dr_j + a.dr_{j-1}; transmit anchor:
    dt_j = (1+b) dt_{j-1} + a.dr_j - a.dr_{j-1}; a = n/(c - n.v_free), b = n.(v_R - v_T)/(c - n.v_free).
    """
    n, kp1, _ = states.shape
    out = np.zeros((n, kp1, 3))
    rate = np.empty(n)
    g = np.zeros((kp1, 3))
    for r in range(n):
        g[:, :] = 0.0
        dt = 1.0
        for step in range(1, kp1):
            j = kp1 - step if receive else step
            u = states[r, j, :3] - states[r, j - 1, :3]
            u = u / np.sqrt(u[0] ** 2 + u[1] ** 2 + u[2] ** 2)
            v_free = states[r, j - 1, 3:] if receive else states[r, j, 3:]
            den = C_LIGHT - (u[0] * v_free[0] + u[1] * v_free[1] + u[2] * v_free[2])
            dv = states[r, j, 3:] - states[r, j - 1, 3:]
            b = (u[0] * dv[0] + u[1] * dv[1] + u[2] * dv[2]) / den
            f = 1.0 - b if receive else 1.0 + b
            for m in range(kp1):
                for i in range(3):
                    g[m, i] *= f
            sign = -1.0 if receive else 1.0
            for i in range(3):
                g[j, i] += sign * u[i] / den
                g[j - 1, i] -= sign * u[i] / den
            dt *= f
        for m in range(kp1):
            for i in range(3):
                out[r, m, i] = -g[m, i] if receive else g[m, i]
        rate[r] = 1.0 - dt if receive else dt - 1.0
    return out, rate


def anchor_from_utc(epoch_utc, offset_s=0.0) -> tuple[np.ndarray, np.ndarray]:
    """UTC datetime64[ns] (+ offset s) to the (TDB s past J2000, correction s) pair :func:`solve_path` takes."""
    from odpipe.time import utc_to_tdb2

    whole, frac = utc_to_tdb2(np.atleast_1d(np.asarray(epoch_utc, dtype="datetime64[ns]")))
    frac = frac + offset_s
    t = whole + frac
    return t, (whole - t) + frac
