"""One LiAISON experiment: a spacecraft pair in the CRTBP, one crosslink data type.

:class:`CrosslinkPair` holds the set-up (truth initial states, arc, cadence,
noise, a priori); it simulates data, runs the fit (odpipe.estimation.fit) as a
Monte Carlo trial, and evaluates the Cramér-Rao bound and the observability
Gramian along the truth. Times are s from the arc epoch (t = 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from odpipe.analysis.crlb import crlb_history, snc_process_noise
from odpipe.analysis.observability import map_to_epoch
from odpipe.dynamics.crtbp import EarthMoonUnits
from odpipe.estimation.fit import FitOptions, Observations, fit
from odpipe.estimation.registry import ParameterRegistry

from .crtbp_problem import RANGE, CrosslinkProblem, crosslink_rows, flow, state_scale


@dataclass(frozen=True)
class CrosslinkPair:
    """units; x1, x2: truth at t = 0 (SI, rotating frame); arc, dt (s): data at dt, 2 dt, ..
    <= arc (``first`` = 0 puts a sample at t = 0 too); kinds: data types per epoch (0 range,
    1 range-rate); sigma: noise per type (m, m/s); apriori: (pos m, vel m/s) filter sigma;
    error: (pos m, vel m/s) sigma of the drawn a priori error per component; block (s):
    fit grid spacing; sigma_acc (m/s^2, per spacecraft): state-noise compensation in the
    CRLB only; deviation: fixed a priori error (12,) instead of drawing it."""

    units: EarthMoonUnits
    x1: np.ndarray
    x2: np.ndarray
    arc: float
    dt: float
    kinds: tuple = (RANGE,)
    sigma: tuple = (1.0, 3e-4)
    apriori: tuple = (1e3, 1e-2)
    error: tuple = (500.0, 1e-3)
    block: float = 3 * 3600.0
    first: int = 1
    max_iter: int = 6
    sigma_acc: tuple = (0.0, 0.0)
    deviation: np.ndarray | None = None

    @property
    def epochs(self) -> np.ndarray:
        return np.arange(self.first, int(np.floor(self.arc / self.dt + 1e-9)) + 1) * self.dt

    def rows(self) -> tuple[np.ndarray, np.ndarray]:
        """Row times (s) and kinds, every kind at each epoch."""
        t = self.epochs
        return np.repeat(t, len(self.kinds)), np.tile(np.asarray(self.kinds), t.size)

    def truth(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """States (N, 6) and STMs from t = 0 (N, 6, 6) of both spacecraft at t (s)."""
        X1, P1 = flow(self.units, self.x1, 0.0, t)
        X2, P2 = flow(self.units, self.x2, 0.0, t)
        return X1, X2, P1, P2

    def sigma_rows(self, kind) -> np.ndarray:
        return np.asarray(self.sigma, float)[kind]

    def epoch_partials(self):
        """Rows' times, kinds and partials w.r.t. the epoch state [x1(0), x2(0)]: (m, 12)."""
        t, kind = self.rows()
        X1, X2, P1, P2 = self.truth(t)
        _, H = crosslink_rows(X1, X2, t, kind)
        return t, kind, np.concatenate([map_to_epoch(H[:, :6], P1), map_to_epoch(H[:, 6:], P2)], 1)

    def nondimensional(self, H_epoch: np.ndarray, kind: np.ndarray) -> np.ndarray:
        """Epoch partials in CRTBP units (data in LU or LU/TU per LU, LU/TU)."""
        U = self.units
        scale = np.where(kind == RANGE, 1 / U.length, U.time / U.length)
        return scale[:, None] * H_epoch @ np.kron(np.eye(2), state_scale(U))

    def p0(self) -> np.ndarray:
        return np.diag(np.tile(np.repeat(np.asarray(self.apriori, float) ** 2, 3), 2))

    def crlb(self) -> tuple[np.ndarray, np.ndarray]:
        """(epochs, CRLB covariance (K, 12, 12) after each epoch's data), along the truth."""
        t_ep = self.epochs
        t, kind = self.rows()
        X1, X2, P1, P2 = self.truth(t_ep)
        n = len(self.kinds)
        S = np.zeros((t_ep.size, 12, 12))
        S[:, :6, :6], S[:, 6:, 6:] = P1, P2
        prev = np.concatenate([np.eye(12)[None], S[:-1]])
        Phis = S @ np.linalg.inv(prev)                     # Phi(t_k, t_k-1)
        _, H = crosslink_rows(np.repeat(X1, n, 0), np.repeat(X2, n, 0), t, kind)
        W = self.sigma_rows(kind) ** -2.0
        Hs = H.reshape(t_ep.size, n, 12)
        Ws = W.reshape(t_ep.size, n)
        steps = np.diff(np.concatenate([[0.0], t_ep]))
        Qs = None if not any(self.sigma_acc) else [snc_process_noise(h, self.sigma_acc) for h in steps]
        return t_ep, crlb_history(self.p0(), Phis, Hs, Ws, Qs)

    def __call__(self, rng: np.random.Generator, index: int = 0) -> dict:
        """One Monte Carlo run: draw a priori error and noise, fit; filtered and smoothed
        errors (K, 12) on the fit grid (s)."""
        t, kind = self.rows()
        X1, X2, _, _ = self.truth(t)
        z, _ = crosslink_rows(X1, X2, t, kind)
        sig = self.sigma_rows(kind)
        z = z + rng.normal(size=z.size) * sig
        x_true = np.concatenate([self.x1, self.x2])
        err0 = (rng.normal(size=12) * np.tile(np.repeat(np.asarray(self.error, float), 3), 2)
                if self.deviation is None else np.asarray(self.deviation, float))
        reg = ParameterRegistry()
        reg.add_state("sc1", x_true[:6] + err0[:6], *self.apriori)
        reg.add_state("sc2", x_true[6:] + err0[6:], *self.apriori)
        sol = fit(CrosslinkProblem(reg, self.units, t, kind), Observations(t, z, sig, kind),
                  0.0, float(t[-1]), FitOptions(block=self.block, max_iter=self.max_iter))
        G1, G2, _, _ = self.truth(sol.grid)
        truth = np.concatenate([G1, G2], axis=1)
        post = sol.residuals["postfit"].to_numpy()
        return {"grid": sol.grid, "filtered": sol.filtered_x - truth,
                "postfit_rms": [float(np.sqrt(np.nanmean(post[kind == k] ** 2))) for k in self.kinds],
                "smoothed": sol.smoothed_x - truth,
                "filtered_sigma": np.sqrt(np.diagonal(sol.filtered_P, axis1=1, axis2=2)),
                "converged": sol.converged, "iterations": len(sol.history)}
