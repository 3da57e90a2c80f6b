"""Event partials composed into estimation partials: epoch state, dynamic parameters, station coordinates.

For a spacecraft flying a trajectory with ``stm(t) -> (N,6,6)`` (d x(t) / d x(t0))
and ``sensitivity(t) -> (N,6,p)`` (d x(t) / d p), the partial of an observable
with respect to the arc's epoch state is the sum over the spacecraft's events
of ``[d_pos, d_vel] @ stm(t_event)`` (likewise for p). For a station, the
partial with respect to its ITRS position is ``d_pos @ R_itrs_to_icrf(t_event)``,
plus ``d_vel @ R_itrs_to_icrf @ [omega x]`` where a velocity partial exists (the
antenna's velocity is the Earth's rotation of its position).
"""

from __future__ import annotations

import numpy as np

from odpipe.constants import ERA_RATE

from .computed import Computed

_OMEGA_CROSS = np.array([[0.0, -ERA_RATE, 0.0], [ERA_RATE, 0.0, 0.0], [0.0, 0.0, 0.0]])


def event_gradient(computed: Computed, role: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """[(t_event (N,), d value/d state (N,6))] for every event of ``role``."""
    out = []
    for ev in computed.events:
        if ev.role == role:
            dv = np.zeros_like(ev.d_pos) if ev.d_vel is None else ev.d_vel
            out.append((ev.t, np.concatenate([ev.d_pos, dv], axis=1)))
    return out


def _at_events(grads, fn) -> list[np.ndarray]:
    """``fn`` (a trajectory's ``stm`` or ``sensitivity``) at the epochs of each event of ``grads``, evaluated once
    per distinct epoch (a Doppler count's end is the next count's start)."""
    t = np.concatenate([t for t, _ in grads])
    epochs, which = np.unique(t, return_inverse=True)
    values = np.asarray(fn(epochs))[which.ravel()]
    return np.split(values, np.cumsum([t.size for t, _ in grads])[:-1])


def epoch_state_partials(computed: Computed, role: str, trajectory) -> np.ndarray:
    """d value / d (epoch state of ``trajectory``), (N,6), summing the events of ``role``."""
    total = np.zeros((computed.value.size, 6))
    grads = event_gradient(computed, role)
    if grads:
        for (_, g), stm in zip(grads, _at_events(grads, trajectory.stm)):
            total += np.einsum("ni,nij->nj", g, stm.reshape(-1, 6, 6))
    return total


def dynamic_partials(computed: Computed, role: str, trajectory) -> np.ndarray:
    """d value / d (dynamic parameters of ``trajectory``), (N,p), through ``trajectory.sensitivity``."""
    grads = event_gradient(computed, role)
    if not grads:
        return np.zeros((computed.value.size, 0))
    parts = [np.einsum("ni,nip->np", g, s) for (_, g), s in zip(grads, _at_events(grads, trajectory.sensitivity))]
    return sum(parts[1:], parts[0])


def station_partials(computed: Computed, role: str, station_node) -> np.ndarray:
    """d value / d (ITRS position of the station playing ``role``), (N,3)."""
    total = np.zeros((computed.value.size, 3))
    for ev in computed.events:
        if ev.role == role:
            rot = station_node.itrs_to_frame(ev.t)
            total += np.einsum("ni,nij->nj", ev.d_pos, rot)
            if ev.d_vel is not None:
                total += np.einsum("ni,nij,jk->nk", ev.d_vel, rot, _OMEGA_CROSS)
    return total
