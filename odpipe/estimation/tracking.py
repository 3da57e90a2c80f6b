"""Adapter: the fit's :class:`~.fit.Problem` over the product's models, for one spacecraft.

Dynamics come from :func:`odpipe.dynamics.propagator.propagate`, observables and
partials from :func:`odpipe.measurements.compute` on TrackingTable rows. Each
grid interval ``[t0, t1)`` is propagated from the registry vector at ``t0``:
first backwards over ``margin`` seconds (so light time can reach before
``t0``), then forwards with STM and sensitivities; partials w.r.t. the vector at
``t0`` are the chain ``d x(t)/d x(ta) . d x(ta)/d x(t0)``. A maneuver exactly at
``t0`` lies outside the backward leg and inside the forward one, so it acts at
the start of the interval as the protocol requires.

Registry conventions: the state is ``<sc>.x .. <sc>.vz`` (m, m/s, ICRF about the
force model's centre); every force-model parameter ``p`` registered as
``<sc>.<p>`` (e.g. ``A.srp_scale``, ``A.dv[0].x``) is estimated. Stochastic
accelerations ``<sc>.acc_R|T|N`` (registry kind ``stochastic``) are added by the
adapter as one :class:`~odpipe.dynamics.forces.EmpiricalRTN` batch spanning the
interval with the registry's current values (the force model given must have
no EmpiricalRTN of its own).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np
import pandas as pd

from .fit import Observations
from .registry import ParameterRegistry

STATE_AXES = ("x", "y", "z", "vx", "vy", "vz")


def observations_from_rows(rows: pd.DataFrame, group_columns=("station_rx", "observable")) -> Observations:
    """Observations (TDB s, value, sigma, weighting group) of time-ordered TrackingTable rows."""
    from odpipe.time.scales import utc_to_tdb

    group = rows[list(group_columns)].astype(str).agg(".".join, axis=1).to_numpy()
    return Observations(utc_to_tdb(rows["epoch"].to_numpy()), rows["value"].to_numpy(float),
                        rows["sigma"].to_numpy(float), group)


class TrackingProblem:
    """Problem protocol for one spacecraft ``spacecraft`` tracked by ``rows``.

    force_model(x) -> ForceModel with the parameter values of registry vector ``x``;
    bias_index: per row, the registry index of its measurement bias or -1;
    margin: backward propagation (s) before each interval for light time.
    """

    def __init__(self, registry: ParameterRegistry, spacecraft: str, force_model: Callable,
                 rows: pd.DataFrame, setup, bias_index=None, margin: float = 60.0,
                 rtol: float = 1e-12):
        self.registry, self.sc, self.force_model = registry, spacecraft, force_model
        self.rows = rows.reset_index(drop=True)
        self.setup, self.margin, self.rtol = setup, margin, rtol
        self.times = observations_from_rows(self.rows).time
        self.i_state = np.array([registry.index(f"{spacecraft}.{a}") for a in STATE_AXES])
        self.bias_index = (np.full(len(rows), -1) if bias_index is None
                           else np.asarray(bias_index, int))
        self.i_acc = np.array([registry.index(f"{spacecraft}.acc_{a}") for a in "RTN"
                               if f"{spacecraft}.acc_{a}" in registry.names], int)
        if self.i_acc.size not in (0, 3):
            raise ValueError("stochastic accelerations need all of acc_R, acc_T, acc_N")

    def _flow(self, t0, x0, t_end):
        """Forward trajectory from ta = t0 - margin, d x(ta)/d x(t0), d x(ta)/d p, params."""
        from odpipe.dynamics.forces import EmpiricalRTN
        from odpipe.dynamics.propagator import propagate

        fm = self.force_model(x0)
        names = set(self.registry.names)
        params = [p for p in fm.parameter_names() if f"{self.sc}.{p}" in names]
        cols = [self.registry.index(f"{self.sc}.{p}") for p in params]
        if self.i_acc.size:
            if fm.of_type(EmpiricalRTN):
                raise ValueError("the force model must not carry its own EmpiricalRTN")
            lo, hi = min(t0 - self.margin, t0), max(t_end, t0) + 1.0
            fm = replace(fm, components=list(fm.components)
                         + [EmpiricalRTN(np.array([[lo, hi, *x0[self.i_acc]]]))])
            params += ["emp[0].R", "emp[0].T", "emp[0].N"]
            cols += list(self.i_acc)
        s0 = x0[self.i_state]
        if self.margin > 0:
            ta = t0 - self.margin
            back = propagate(s0, t0, ta, fm, params=params, rtol=self.rtol)
            sa, Phi_b = back.state(ta)[0], back.stm(ta)[0]
            S_b = back.sensitivity(ta)[0]
        else:
            ta, sa, Phi_b, S_b = t0, s0, np.eye(6), np.zeros((6, len(params)))
        fwd = propagate(sa, ta, t_end, fm, params=params, rtol=self.rtol)
        return fwd, Phi_b, S_b, np.array(cols, int), params

    def _to_registry(self, Phi_f, S_f, Phi_b, S_b, cols):
        """d x(t) / d (registry vector at t0), rows of the state: (m, 6, n)."""
        D = np.zeros((Phi_f.shape[0], 6, len(self.registry)))
        D[:, :, self.i_state] = Phi_f @ Phi_b
        if cols.size:
            D[:, :, cols] = Phi_f @ S_b + S_f
        return D

    def transition(self, t0, t1, x0):
        fwd, Phi_b, S_b, cols, _ = self._flow(t0, x0, t1)
        D = self._to_registry(fwd.stm(t1), fwd.sensitivity(t1), Phi_b, S_b, cols)
        Phi = np.eye(len(self.registry))
        Phi[self.i_state] = D[0]
        x1 = x0.copy()
        x1[self.i_state] = fwd.state(t1)[0]
        return x1, Phi

    def predict(self, t0, x0, rows):
        from odpipe.measurements import compute

        fwd, Phi_b, S_b, cols, params = self._flow(t0, x0, float(self.times[rows].max()) + 1.0)
        ev = compute(self.rows.iloc[rows], {self.sc: fwd}, self.setup)
        bad = ~np.isfinite(ev.value)
        if bad.any():
            raise ValueError(f"rows {rows[bad][:5]} not computable: {set(ev.status[bad])}")
        P_state = ev.partials[f"state:{self.sc}"]
        H = np.zeros((rows.size, len(self.registry)))
        H[:, self.i_state] = P_state @ Phi_b
        if cols.size:
            H[:, cols] = P_state @ S_b
            dyn = ev.partials.get(f"dynamic:{self.sc}")
            if dyn is not None:
                names = ev.names[f"dynamic:{self.sc}"]
                H[:, cols] += dyn[:, [names.index(p) for p in params]]
        z = ev.value.copy()
        b = self.bias_index[rows]
        has = b >= 0
        z[has] += x0[b[has]]
        H[np.flatnonzero(has), b[has]] += 1.0
        return z, H
