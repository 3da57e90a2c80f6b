"""A reference trajectory over one segment of the arc, with a short look-back.

A segment starts at an epoch ``a`` where the reference may change (arc start,
stochastic-batch boundary, impulsive maneuver) and ends at the next such epoch
``b``. It is integrated once, forward from the state ``x(a-)`` (before a
maneuver at ``a``, whose dV is then added), and backward from ``x(a-)`` over a
look-back of ``lookback`` s so that the light-time and count-interval events of
the first rows (which precede their tags) are covered.

The look-back's first step is the forward flight's median step (DOP853's own start, a few
seconds in a low lunar orbit, would spend most of a 120-s look-back growing its steps).

It offers the :class:`~odpipe.dynamics.trajectory.Trajectory` interface that
the measurement models read, with

* ``stm(t) = d x(t) / d x(a-)`` (6x6), on both sides of ``a``;
* ``sensitivity(t) = d x(t) / d p`` for ``param_names`` = the force model's
  parameters, then ``dv.x|y|z`` of a maneuver at ``a`` (ICRF m/s), then ``dv.dt``,
  the offset (s) of its firing epoch when that is estimated; all zero before ``a``.

A burn logged at ``a`` that fires at ``a + dt`` is kept at the segment start: the
post-burn branch is flown back to ``a`` (pre-burn flight from ``a`` to ``a + dt``, dV added
there, post-burn flight back to ``a``), which is exact, and starts the forward
integration as ``x(a+)``. Its partials are first order in ``dt``: forces depend on
position only, so ``x(a+) = x(a-) + [-dV dt; dV]`` up to ``(d acc / d r) dV dt^2 / 2`` in
velocity (2e-8 m/s for 1 m/s and 10 s at 100,000 km from the Earth, 5e-4 m/s for
10 m/s in low Earth orbit), and after ``a`` the dV columns are ``stm(t) [-dt I; I]`` and
the epoch column ``-stm(t)[:, 0:3] dV``; ``stm`` is that of the post-burn branch from
``a`` (``d x(a+) / d x(a-)`` taken as the identity, relative error of order
``(d acc / d r) dt^2``). The epoch column is off by about the orbital rate times ``dt``
(1 % for 10 s in low orbit): that sets the convergence rate only, the converged
estimate rests on the exact reference. The reference state between ``a`` and ``a + dt`` is the
post-burn branch, and before ``a`` the pre-burn one: rows between the logged and the
actual firing see the wrong side of the burn (a velocity error of dV), so leave them
out, as is done around burns, or let the editing reject them.

The look-back flies the segment's own parameters: a stochastic acceleration of
the previous batch acts there as the current one (an error of order
``da * lookback**2 / 2``, micrometres for 1e-9 m/s^2 over 70 s), and a maneuver of the
previous segment less than ``lookback`` before ``a`` is not undone there (keep maneuvers and
batch boundaries further apart than the look-back); everything else is exact.
"""

from __future__ import annotations

import numpy as np

from odpipe.dynamics.propagator import propagate

DV_NAMES = ["dv.x", "dv.y", "dv.z"]
DT_NAME = "dv.dt"


class SegmentTrajectory:
    """Reference trajectory of one spacecraft over ``[a - lookback, b]`` (TDB s)."""

    def __init__(self, x_start, a, b, force_model, params, dv=None, lookback=120.0,
                 rtol=1e-12, atol=1e-6, dt=None, **integrator):
        """``dv``: ICRF dV (m/s) of a burn at ``a``; ``dt``: its estimated firing offset (s; None: not
        estimated, the burn is at ``a``); ``rtol``, ``atol`` and ``integrator`` (``max_step``,
        ``method``): as :func:`propagate`."""
        if dt is not None and dv is None:
            raise ValueError("an epoch offset needs the maneuver's dV")
        self.center = force_model.center
        self.t0, self.t1 = float(a), float(b)
        self.x_start = np.asarray(x_start, float).copy()      # x(a-), m and m/s
        self.n_dv = 0 if dv is None else 3
        self.param_names = (list(params) + (DV_NAMES if dv is not None else [])
                            + ([DT_NAME] if dt is not None else []))
        self._np = len(params)
        self._dv = None if dv is None else np.asarray(dv, float).copy()
        self._dt = None if dt is None else float(dt)
        x_plus = self.x_start.copy()
        tol = dict(rtol=rtol, atol=atol, **integrator)
        if self._dt:
            t_fire = a + self._dt
            x_fire = propagate(self.x_start, a, t_fire, force_model, with_stm=False, **tol).state(t_fire)[0]
            x_fire[3:6] += self._dv
            x_plus = propagate(x_fire, t_fire, a, force_model, with_stm=False, **tol).state(a)[0]
        elif dv is not None:
            x_plus[3:6] += self._dv
        self._fwd = propagate(x_plus, a, b, force_model, with_stm=True, params=list(params), **tol)
        self._back = propagate(self.x_start, a, a - lookback, force_model, with_stm=True,
                               params=list(params), first_step=self._fwd.median_step, **tol)
        self.n_eval = self._fwd.n_eval + self._back.n_eval
        self._memo: dict = {float(a): (self.x_start, np.eye(6), np.eye(6), np.zeros((6, len(self.param_names))))}
        self._last_full = (None, None)

    def _pieces(self, t):
        t = np.atleast_1d(np.asarray(t, float))
        before = t < self.t0
        return t, before

    def _full(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x (N, 6), Phi (N, 6, 6), S (N, 6, p)) at ``t``: one interpolation on each side of ``a``."""
        t, before = self._pieces(t)
        x = np.empty((t.size, 6))
        Phi = np.empty((t.size, 6, 6))
        S = np.zeros((t.size, 6, len(self.param_names)))
        for sel, traj in ((before, self._back), (~before, self._fwd)):
            if sel.any():
                x[sel], Phi[sel], S[sel, :, :self._np] = traj.variational(t[sel])
        after = ~before
        if self.n_dv and after.any():
            P = Phi[after]
            dv_cols = P[:, :, 3:6]
            if self._dt is not None:
                dv_cols = dv_cols - self._dt * P[:, :, 0:3]
                S[after, :, self._np + 3] = -P[:, :, 0:3] @ self._dv
            S[after, :, self._np:self._np + 3] = dv_cols
        return x, Phi, S

    def state(self, t) -> np.ndarray:
        """Position (m) and velocity (m/s), (N, 6); post-maneuver at ``a``. Interpolates the state alone
        (light-time solutions ask for states far more often than for partials)."""
        t, before = self._pieces(t)
        x = np.empty((t.size, 6))
        for sel, traj in ((before, self._back), (~before, self._fwd)):
            if sel.any():
                x[sel] = traj.state(t[sel])
        return x

    def stm(self, t) -> np.ndarray:
        """d x(t) / d x(a-), (N, 6, 6)."""
        return self._full_at(t)[1]

    def sensitivity(self, t) -> np.ndarray:
        """d x(t) / d params, (N, 6, p) in ``param_names`` order."""
        return self._full_at(t)[2]

    def _full_at(self, t):
        """:meth:`_full` at ``t``, remembered for the last epochs asked (a row group's partials ask for the STM
        and the sensitivities at the same epochs); its arrays are read-only."""
        t = np.atleast_1d(np.asarray(t, float))
        key = (t.shape, t.tobytes())
        if self._last_full[0] != key:
            got = self._full(t)
            for a in got:
                a.setflags(write=False)
            self._last_full = (key, got)
        return self._last_full[1]

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(x, Phi, Phi^-1, S) at one epoch, the state at ``a`` taken before its maneuver (Phi = I, S = 0).

        Served from :meth:`preload` or remembered: the filter asks for each grid epoch twice."""
        t = float(t)
        if t not in self._memo:
            self.preload([t])
        return self._memo[t]

    def at_many(self, epochs) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`at` of every epoch, stacked: x (N, 6), Phi (N, 6, 6), Phi^-1 (N, 6, 6), S (N, 6, p)."""
        self.preload(epochs)
        got = [self._memo[float(t)] for t in epochs]
        return tuple(np.array([g[i] for g in got]) for i in range(4))

    def preload(self, epochs) -> None:
        """Evaluate (x, Phi, Phi^-1, S) at ``epochs`` inside the segment in one vectorized pass."""
        ts = np.asarray([t for t in np.atleast_1d(epochs) if self.t0 < t <= self.t1 and t not in self._memo], float)
        if ts.size:
            x, Phi, S = self._full(ts)
            inv = np.linalg.inv(Phi)
            self._memo.update({float(t): (x[i], Phi[i], inv[i], S[i]) for i, t in enumerate(ts)})


class ShiftedSegmentTrajectory(SegmentTrajectory):
    """A segment flown from a start state and parameters near those of an integrated ``base``, to first
    order: ``x(t) = base.x(t) + stm(t) dx(a-) + sensitivity(t) dp``, with the base's STM and sensitivities.

    ``x_start``: the new x(a-) (m, m/s); ``params``: the new values of ``base.param_names`` less those of the
    base. The error is second order in the offset (for a position offset ``d`` at orbit radius ``r``
    about ``d**2 / r``: 2 cm for 180 m at the Moon's 1,800 km), plus a first-order part where the STM
    was integrated with a truncated gravity gradient (``partial_degree`` below the field's degree), so
    use it only where a reference need not be exact. No force evaluation."""

    def __init__(self, base: SegmentTrajectory, x_start, dp):
        base = getattr(base, "base", base)   # always shifted from an integrated segment
        self.base = base
        self.center, self.t0, self.t1 = base.center, base.t0, base.t1
        self.x_start = np.asarray(x_start, float).copy()
        self.param_names, self.n_dv, self._np = base.param_names, base.n_dv, base._np
        self._dx = self.x_start - base.x_start
        self._dp = np.asarray(dp, float).copy()
        self.n_eval = 0
        self._memo = {self.t0: (self.x_start, np.eye(6), np.eye(6), np.zeros((6, len(self.param_names))))}
        self._last_full = (None, None)

    def _full(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x, Phi, S = self.base._full(t)
        return x + Phi @ self._dx + S @ self._dp, Phi, S

    def state(self, t) -> np.ndarray:
        """Position (m) and velocity (m/s), (N, 6): the base's, shifted (needs its STM and sensitivities)."""
        return self._full(t)[0]
