"""A single-pass extended Kalman filter over a fit :class:`~odpipe.estimation.fit.Problem`: the filter
of seed 000 (Fujimoto et al. sec. 3), to set beside odpipe's iterated filter-smoother.

Covariance form. At each grid epoch: the registry's stochastic steps (``p+ = m p + w``, ``w ~ N(0, q)``;
white RTN accelerations held over each batch are the paper's SNC, eqs. 10-11), then the rows of the
grid interval in one update with the Joseph form (eq. 9), then the reference is reset to the estimate
(the "extended" step) and propagated with its STM to the next epoch. No iteration, no smoother, no
innovation editing. Units: registry units (SI), times TDB s.

``gap_snc = (q, starts)`` replaces the registry's stochastic steps (its stochastic parameters are held
at zero, with no variance) by the paper's eqs. 10-11 taken literally: before each update,
``Gamma Q Gamma^T`` with ``Q = q I`` ((m/s^2)^2) and ``Gamma = dt [dt/2 I; I]`` over the time ``dt``
since the previous update, on the 6 state entries from each index in ``starts`` (a gap in the data
then gets ``dt^2`` of velocity variance, not ``dt`` times one interval's).

``dynamics``: a problem over the same registry and models without rows, asked for the transitions, for
grids whose every interval starts a new reference (spacing = the stochastic batch, as the Fujimoto
set-up): after an update the reference from the estimate is flown again to the next epoch only, and a
problem holding the rows (:class:`~odpipe.od.problem.TrackingProblem`) would evaluate them on it too,
never to be read (the next interval's rows are predicted on a reference from its own epoch). The
transitions are the same either way. With several grid intervals per batch leave it out: there the
problem's reference from a transition serves the next interval's rows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from odpipe.estimation.fit import Observations, build_grid


@dataclass(frozen=True)
class EKFResult:
    """Estimates on the grid (each after the rows before that epoch, as the fit's ``filtered_x``)
    and the post-fit residual of every row (observed - computed after its own update, row units)."""

    grid: np.ndarray        # (K,) TDB s
    x: np.ndarray           # (K, n)
    P: np.ndarray           # (K, n, n)
    postfit: np.ndarray     # (m,)


def gap_noise(q: float, dt: float) -> np.ndarray:
    """``Gamma Q Gamma^T`` (6 x 6, m and m/s) of white accelerations of variance ``q`` held over ``dt`` s (eq. 11)."""
    g = dt * np.vstack([0.5 * dt * np.eye(3), np.eye(3)])
    return q * g @ g.T


def ekf(problem, obs: Observations, t_start: float, t_end: float, block: float, gap_snc=None,
        dynamics=None) -> EKFResult:
    """One EKF pass from the registry's a priori over ``[t_start, t_end]`` with grid spacing ``block`` (s);
    transitions from ``dynamics`` when given (module doc), else from ``problem``."""
    reg = problem.registry
    if reg.n_estimated != len(reg):
        raise ValueError("ekf: consider parameters are not supported")
    grid, steps = build_grid(reg, t_start, t_end, block)
    bounds = np.searchsorted(obs.time, grid, side="left")
    bounds[-1] = np.searchsorted(obs.time, t_end, side="right")
    x, P = reg.apriori.copy(), np.diag(reg.sigma**2)
    if gap_snc is not None:
        held = reg.indices(kind="stochastic")
        x[held], P[held, held] = 0.0, 0.0
        steps = {}
    eye = np.eye(x.size)
    transition = (dynamics or problem).transition
    xs, Ps = [], []
    postfit = np.full(obs.time.size, np.nan)
    t_last = t_start
    for k in range(grid.size - 1):
        for idx, (m, q) in steps.get(k, ()):
            x[idx] *= m
            P[idx, :] *= m
            P[:, idx] *= m
            P[idx, idx] += q
        xs.append(x.copy())
        Ps.append(P.copy())
        rows = np.arange(bounds[k], bounds[k + 1])
        if rows.size:
            if gap_snc is not None:
                q, starts = gap_snc
                for i in starts:
                    P[i:i + 6, i:i + 6] += gap_noise(q, grid[k] - t_last)
                t_last = grid[k]
            computed, H = problem.predict(grid[k], x, rows)
            y = obs.value[rows] - computed
            R = np.diag(obs.sigma[rows] ** 2)
            PHt = P @ H.T
            K = np.linalg.solve(H @ PHt + R, PHt.T).T
            dx = K @ y
            A = eye - K @ H
            P = A @ P @ A.T + K @ R @ K.T
            x = x + dx
            postfit[rows] = y - H @ dx
        x, Phi = transition(grid[k], grid[k + 1], x)
        P = Phi @ P @ Phi.T
        P = 0.5 * (P + P.T)
    xs.append(x)
    Ps.append(P)
    return EKFResult(grid, np.array(xs), np.array(Ps), postfit)
