"""propagate(): state (+ STM + parameter sensitivities) through a force model.

Segments restart at maneuvers and at burn/empirical-batch boundaries. At an
impulsive maneuver (ICRF delta-v, state independent) the velocity jumps by
dv, the STM is continuous, the sensitivity to dv jumps by [0; I] and the
sensitivity to the maneuver epoch by f(x-) - f(x+) (f = [v; a], the state
derivative before and after the impulse). On backward arcs the impulse is
removed (x- = x+ - dv), the dv jump is -[0; I] and the epoch jump f(x+) - f(x-).
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

from odpipe.dynamics.dop853 import integrate
from odpipe.dynamics.rk4 import integrate_rk4
from odpipe.dynamics.forces import ForceModel, compile_model
from odpipe.dynamics.rhs import acceleration  # also registers the orbit right-hand side
from odpipe.dynamics.trajectory import Trajectory, TrajectorySet


class IntegrationError(RuntimeError):
    """The integrator gave up (typically a trajectory driven into the central body)."""


def _state_derivative(t, r, v, model):
    acc = np.zeros(3)
    acceleration(t, r, v, model, acc, np.zeros((3, 3)), np.zeros((3, 3)),
                 np.zeros((model.n_params, 3)))
    return np.concatenate([v, acc])


def propagate(state0, t0: float, t1: float, force_model: ForceModel, with_stm: bool = True,
              params: Sequence[str] | None = None, rtol: float = 1e-12, atol: float = 1e-9,
              max_step: float = np.inf, method: str = "dop853", first_step: float = 0.0) -> Trajectory:
    """Integrate ``state0`` (m, m/s, ICRF, relative to ``force_model.center``) from t0 to t1 (TDB s).

    ``params``: dynamic parameters to carry sensitivities for (default: all of the
    model's when ``with_stm``). ``rtol``/``atol`` (m and m/s) control the state error;
    ``rtol = inf`` integrates with fixed steps of ``max_step`` instead (8th order, no error control);
    ``method = 'rk4'``: classical Runge-Kutta with fixed steps of ``max_step``; ``first_step`` (s, > 0):
    DOP853's first step instead of its own starting estimate.
    """
    if method not in ("dop853", "rk4") or (method == "rk4" and not np.isfinite(max_step)):
        raise ValueError(f"method must be 'dop853' or 'rk4' (with a finite max_step), not {method!r}")
    params = list(force_model.parameter_names() if params is None and with_stm else (params or []))
    if params and not with_stm:
        raise ValueError("parameter sensitivities need with_stm=True")
    unknown = set(params) - set(force_model.parameter_names())
    if unknown:
        raise ValueError(f"parameters not in the force model: {sorted(unknown)}")
    model = compile_model(force_model, t0, t1, params, with_stm)
    npar = len(params)
    y = np.asarray(state0, dtype=float).ravel().copy()
    if with_stm:
        y = np.concatenate([y, np.eye(6).ravel(), np.zeros(6 * npar)])
    direction = 1.0 if t1 >= t0 else -1.0
    lo, hi = min(t0, t1), max(t0, t1)
    cuts = sorted(b for b in force_model.breakpoints() if lo < b < hi)
    if direction < 0:
        cuts = cuts[::-1]
    maneuvers = force_model.maneuvers()
    pieces = []
    n_eval = 0
    t_a = t0
    for t_b in cuts + [t1]:
        model.segment[0] = 0.5 * (t_a + t_b)
        try:
            ts, ys, Fs, ne = (integrate_rk4(model, float(t_a), y, float(t_b), float(max_step), 6)
                              if method == "rk4" else
                              integrate(model, float(t_a), y, float(t_b), rtol, atol, max_step, 6, first_step))
        except RuntimeError as err:
            raise IntegrationError(f"{err} between TDB {t_a:.3f} and {t_b:.3f} s, starting "
                                   f"{np.linalg.norm(y[:3]) / 1e3:.3f} km from {force_model.center}") from err
        pieces.append((ts, ys, Fs))
        n_eval += ne
        y = ys[-1].copy()
        for k, man in enumerate(maneuvers):
            if man.epoch == t_b and t_b != t1:
                y = _apply_maneuver(y, t_b, k, np.asarray(man.dv, float), direction, model, params)
        t_a = t_b
    return Trajectory(force_model.center, t0, t1, params, pieces, with_stm, n_eval)


def _apply_maneuver(y, t, k, dv, direction, model, params):
    r = y[0:3]
    before = _state_derivative(t, r, y[3:6], model)
    y[3:6] += direction * dv
    after = _state_derivative(t, r, y[3:6], model)
    if len(y) > 6:
        S = y[42:].reshape(6, len(params))
        for p, name in enumerate(params):
            if name.startswith(f"dv[{k}]."):
                axis = name[-1]
                if axis == "t":
                    S[:, p] += before - after  # f on the integration-incoming side minus outgoing side
                else:
                    S[3 + "xyz".index(axis), p] += direction
    return y


def propagate_many(states0: Mapping[str, np.ndarray], t0: float, t1: float,
                   force_models: ForceModel | Mapping[str, ForceModel], **kw) -> TrajectorySet:
    """Propagate several spacecraft independently (one force model or one per name)."""
    out = TrajectorySet()
    for name, s0 in states0.items():
        fm = force_models[name] if isinstance(force_models, Mapping) else force_models
        out[name] = propagate(s0, t0, t1, fm, **kw)
    return out
