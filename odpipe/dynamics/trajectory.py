"""Trajectory: dense-output ephemeris of one spacecraft over an arc, with STM and sensitivities.

Interface (what measurement models and estimators code against):

* ``traj.center`` - NAIF name of the origin ('earth', 'moon', ...); axes are ICRF.
* ``traj.t0``, ``traj.t1`` - arc epoch and end, TDB seconds past J2000 (t1 < t0 allowed).
* ``traj.state(t) -> (N, 6)`` - position m, velocity m/s at TDB epochs ``t`` (scalar or array).
* ``traj.stm(t) -> (N, 6, 6)`` - d state(t) / d state(t0), from the arc epoch t0 through
  any impulsive maneuvers (the impulse is state independent, so the STM is continuous).
* ``traj.sensitivity(t) -> (N, 6, p)`` - d state(t) / d params for ``traj.param_names``;
  ``traj.variational(t)`` gives the three from one interpolation.
* ``traj.param_names`` - dynamic parameters (see :mod:`odpipe.dynamics.forces`).
* ``traj.segments`` - (t_start, t_end) of the integration segments (restarts at maneuvers,
  burn and empirical-batch boundaries); at a maneuver epoch the post-maneuver state is returned.
* ``traj.n_steps``, ``traj.n_eval`` - accepted steps and force evaluations; ``traj.median_step`` -
  the accepted steps' median length (s).

Epochs outside the arc raise ``ValueError``. :class:`TrajectorySet` maps spacecraft
names to trajectories.
"""

from __future__ import annotations

import numpy as np

from odpipe.dynamics.dop853 import dense


class Trajectory:
    def __init__(self, center: str, t0: float, t1: float, param_names: list[str], pieces: list,
                 with_stm: bool, n_eval: int):
        self.center = center
        self.t0 = float(t0)
        self.t1 = float(t1)
        self.param_names = list(param_names)
        self._pieces = pieces  # list of (ts, ys, Fs)
        self.with_stm = with_stm
        self.n_eval = n_eval
        self.n_steps = sum(len(p[0]) - 1 for p in pieces)
        # segment lookup in ascending time; at a shared epoch the later-time piece (post-maneuver) wins
        starts = np.array([min(p[0][0], p[0][-1]) for p in pieces])
        self._order = np.argsort(starts)
        self._starts = starts[self._order]

    @property
    def median_step(self) -> float:
        """Median length (s) of the accepted steps; 0 without any."""
        steps = np.concatenate([np.abs(np.diff(p[0])) for p in self._pieces])
        return float(np.median(steps)) if steps.size else 0.0

    @property
    def segments(self) -> list[tuple[float, float]]:
        return [(float(p[0][0]), float(p[0][-1])) for p in self._pieces]

    def _values(self, t, n: int | None = None) -> np.ndarray:
        """The first ``n`` components (all by default) of the interpolated solution at ``t``, (N, n)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        lo, hi = min(self.t0, self.t1), max(self.t0, self.t1)
        if np.any((t < lo) | (t > hi)):
            raise ValueError(f"epoch outside the trajectory arc [{lo}, {hi}] TDB s")
        n = self._pieces[0][1].shape[1] if n is None else n
        if len(self._pieces) == 1:   # one integration segment (no restart inside the arc): no lookup
            ts, ys, Fs = self._pieces[0]
            return dense(ts, ys, Fs, np.require(t.ravel(), requirements="CW"), n) if len(ts) > 1 else \
                np.repeat(ys[:1, :n], t.size, axis=0)
        out = np.empty((t.size, n))
        idx = np.clip(np.searchsorted(self._starts, t, side="right") - 1, 0, len(self._pieces) - 1)
        for k in np.unique(idx):
            sel = idx == k
            ts, ys, Fs = self._pieces[self._order[k]]
            out[sel] = dense(ts, ys, Fs, t[sel], n) if len(ts) > 1 else ys[:1, :n]
        return out

    def state(self, t) -> np.ndarray:
        """Position (m) and velocity (m/s), (N, 6): the state's six components alone are interpolated."""
        return self._values(t, 6)

    def stm(self, t) -> np.ndarray:
        if not self.with_stm:
            raise ValueError("trajectory propagated without the STM")
        return self._values(t)[:, 6:42].reshape(-1, 6, 6)

    def sensitivity(self, t) -> np.ndarray:
        return self.variational(t)[2]

    def variational(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(state (N, 6), stm (N, 6, 6), sensitivity (N, 6, p)) from one interpolation."""
        if not self.with_stm:
            raise ValueError("trajectory propagated without the variational equations")
        v = self._values(t)
        return v[:, :6], v[:, 6:42].reshape(-1, 6, 6), v[:, 42:].reshape(len(v), 6, len(self.param_names))


class TrajectorySet(dict):
    """Trajectories of several spacecraft by name (``tset['grail-a'].state(t)``)."""

    def states(self, t) -> dict[str, np.ndarray]:
        return {name: traj.state(t) for name, traj in self.items()}
