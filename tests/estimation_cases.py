"""Small self-contained problems for testing and benchmarking the estimation core.

These are NOT the product's dynamics or measurement models (see
``odpipe.dynamics`` / ``odpipe.measurements``); they satisfy the
:class:`~odpipe.estimation.fit.Problem` protocol with the fewest assumptions:

* :class:`LinearProblem` -- nilpotent linear dynamics ``dx/dt = A x`` with
  linear observations (exact linearization, for Monte Carlo statistics);
* :class:`TwoBodyProblem` -- one spacecraft in two-body motion with Gauss-Markov
  accelerations (inertial axes), impulsive maneuvers, ground-station range /
  range-rate with per-station range biases; fixed-step RK4 of state, STM and
  acceleration sensitivities (numba).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from odpipe.estimation.registry import ParameterRegistry

# ---------------------------------------------------------------- linear


class LinearProblem:
    """``dx/dt = A x`` (A nilpotent, A^4 = 0) in registry order; rows ``z_i = H_i x(t_i)``."""

    def __init__(self, registry: ParameterRegistry, A: np.ndarray, H_rows: np.ndarray,
                 times: np.ndarray):
        if np.any(np.linalg.matrix_power(A, 4)):
            raise ValueError("A must be nilpotent of order <= 4")
        self.registry, self.A, self.H_rows, self.times = registry, A, H_rows, times
        self._A2, self._A3 = A @ A, A @ A @ A

    def phi(self, dt):
        """Transition matrices for an array of dt: (len(dt), n, n)."""
        dt = np.asarray(dt, float)[..., None, None]
        n = self.A.shape[0]
        return np.eye(n) + self.A * dt + self._A2 * dt**2 / 2 + self._A3 * dt**3 / 6

    def transition(self, t0, t1, x0):
        Phi = self.phi(t1 - t0)
        return Phi @ x0, Phi

    def predict(self, t0, x0, rows):
        H = np.einsum("mj,mjk->mk", self.H_rows[rows], self.phi(self.times[rows] - t0))
        return H @ x0, H


# ---------------------------------------------------------------- integration


@njit(cache=True)
def _twobody_deriv(y, p, out):
    """y = [r, v, S(6 x k) row-major]; p = [mu, ax, ay, az]; S columns: x0 then acc. Writes dy/dt into ``out``
    without allocating (the kernel runs four times per RK4 step)."""
    mu = p[0]
    rn = np.sqrt(y[0] ** 2 + y[1] ** 2 + y[2] ** 2)
    rn3, rn5 = rn**3, rn**5
    for i in range(3):
        out[i] = y[3 + i]
        out[3 + i] = -mu * y[i] / rn3 + p[1 + i]
    k = (y.size - 6) // 6
    for c in range(k):          # d/dt S = [[0, I], [G, 0]] S + [0; I] on the acceleration columns (last three)
        for i in range(3):
            out[6 + i * k + c] = y[6 + (3 + i) * k + c]
            g = 0.0
            for j in range(3):
                G = 3 * mu * y[i] * y[j] / rn5 - (mu / rn3 if i == j else 0.0)
                g += G * y[6 + j * k + c]
            out[6 + (3 + i) * k + c] = g + (1.0 if c == k - 3 + i else 0.0)


@njit(cache=True)
def _rk4(y0, t0, times, h, p):
    """Fixed-step RK4 from t0 through sorted ``times`` (>= t0); returns states at times."""
    out = np.empty((times.size, y0.size))
    y = y0.copy()
    t = t0
    k = np.empty((5, y0.size))
    k1, k2, k3, k4, w = k[0], k[1], k[2], k[3], k[4]
    for i in range(times.size):
        while t < times[i]:
            dt = min(h, times[i] - t)
            _twobody_deriv(y, p, k1)
            for n in range(y.size):
                w[n] = y[n] + 0.5 * dt * k1[n]
            _twobody_deriv(w, p, k2)
            for n in range(y.size):
                w[n] = y[n] + 0.5 * dt * k2[n]
            _twobody_deriv(w, p, k3)
            for n in range(y.size):
                w[n] = y[n] + dt * k3[n]
            _twobody_deriv(w, p, k4)
            for n in range(y.size):
                y[n] = y[n] + dt / 6 * (k1[n] + 2 * k2[n] + 2 * k3[n] + k4[n])
            t += dt
        out[i] = y
    return out


def flow(x0, acc, t0, times, h):
    """Two-body states (m, 6) and sensitivities (m, 6, 9) to [x0, acc] at ``times``."""
    y0 = np.concatenate([x0, np.hstack([np.eye(6), np.zeros((6, 3))]).ravel()])
    Y = _rk4(y0, float(t0), np.asarray(times, float), h,
             np.concatenate([[MU_EARTH], acc]))
    return Y[:, :6], Y[:, 6:].reshape(-1, 6, 9)


# ---------------------------------------------------------------- two-body

MU_EARTH = 3.986004415e14   # m^3/s^2
OMEGA_EARTH = 7.292115e-5   # rad/s
R_EARTH = 6378137.0         # m


def station_states(lat_lon, t):
    """Inertial position/velocity (m, m/s) of stations on a uniformly rotating Earth."""
    lat, lon = np.radians(np.asarray(lat_lon, float)).T
    th = lon[:, None] + OMEGA_EARTH * np.asarray(t)[None, :]
    c = np.cos(lat)[:, None]
    r = R_EARTH * np.stack([c * np.cos(th), c * np.sin(th), np.sin(lat)[:, None] + 0 * th], -1)
    v = R_EARTH * OMEGA_EARTH * np.stack([-c * np.sin(th), c * np.cos(th), 0 * th], -1)
    return r, v


class TwoBodyProblem:
    """One spacecraft ``sc``: registry [state(6), acc(3) or none, maneuvers..., range biases...].

    rows: per observation the station index and kind (0 range m, 1 range-rate m/s).
    """

    def __init__(self, registry, times, station, kind, stations_lat_lon, h=10.0):
        self.registry, self.times = registry, np.asarray(times, float)
        self.station, self.kind = np.asarray(station), np.asarray(kind)
        self.stations = np.asarray(stations_lat_lon, float)
        self.h = h
        self.i_state = registry.slice("state", "sc")
        self.i_acc = registry.indices("stochastic", "sc")   # three or none
        self.maneuvers = {}        # epoch -> (dV indices, epoch-offset index or None)
        for p in registry.parameters:
            if p.kind == "maneuver":
                dt = registry.indices("maneuver_epoch", p.owner)
                self.maneuvers[p.epoch] = (registry.indices("maneuver", p.owner),
                                           int(dt[0]) if dt.size else None)
        self.i_bias = np.array([registry.index(f"bias.range.{s}") for s in range(len(self.stations))])

    def _start(self, t0, x0):
        """State right after t0 with a maneuver there applied; (state, d state / d params).

        A firing delayed by dt (epoch offset) shifts the state at t0 by -dt [dV; 0]
        to first order (f(x-) - f(x+) times dt, f = [v; a])."""
        s = x0[self.i_state].copy()
        J = {}
        if float(t0) in self.maneuvers:
            dv_idx, dt_idx = self.maneuvers[float(t0)]
            dv = x0[dv_idx]
            dt = x0[dt_idx] if dt_idx is not None else 0.0
            s[3:6] += dv
            s[0:3] -= dt * dv
            J[tuple(dv_idx)] = np.vstack([-dt * np.eye(3), np.eye(3)])
            if dt_idx is not None:
                J[(dt_idx,)] = np.concatenate([-dv, np.zeros(3)])[:, None]
        return s, J

    def _registry_sens(self, S, J, m):
        n = len(self.registry)
        D = np.zeros((m, 6, n))
        D[:, :, self.i_state] = S[:, :, :6]
        if self.i_acc.size:
            D[:, :, self.i_acc] = S[:, :, 6:]
        for idx, dsdp in J.items():
            D[:, :, list(idx)] = S[:, :, :6] @ dsdp
        return D

    def _acc(self, x0):
        return x0[self.i_acc] if self.i_acc.size else np.zeros(3)

    def transition(self, t0, t1, x0):
        s, dv_idx = self._start(t0, x0)
        X, S = flow(s, self._acc(x0), t0, [t1], self.h)
        Phi = np.eye(len(self.registry))
        Phi[self.i_state] = self._registry_sens(S, dv_idx, 1)[0]
        x1 = x0.copy()
        x1[self.i_state] = X[0]
        return x1, Phi

    def predict(self, t0, x0, rows):
        s, dv_idx = self._start(t0, x0)
        t = self.times[rows]
        X, S = flow(s, self._acc(x0), t0, t, self.h)
        D = self._registry_sens(S, dv_idx, rows.size)
        st = self.station[rows]
        rs, vs = station_states(self.stations, t)
        m = np.arange(rows.size)
        z, dz = range_and_rate(X, rs[st, m], vs[st, m], self.kind[rows])
        H = np.einsum("mj,mjk->mk", dz, D)
        isr = self.kind[rows] == 0
        z[isr] += x0[self.i_bias[st[isr]]]
        H[np.flatnonzero(isr), self.i_bias[st[isr]]] += 1.0
        return z, H


def range_and_rate(X, r_other, v_other, kind):
    """Range (kind 0) or range-rate (kind 1) from X (m, 6) to another body, with d/dX."""
    dr = X[:, :3] - r_other
    dv = X[:, 3:] - v_other
    rho = np.linalg.norm(dr, axis=1)
    u = dr / rho[:, None]
    rr = np.sum(u * dv, axis=1)
    dz = np.zeros((X.shape[0], 6))
    israte = kind == 1
    dz[~israte, :3] = u[~israte]
    du = (dv - rr[:, None] * u) / rho[:, None]
    dz[israte, :3] = du[israte]
    dz[israte, 3:] = u[israte]
    return np.where(israte, rr, rho), dz


# ---------------------------------------------------------------- scenario

DSN_LIKE = ((35.43, -116.89), (-35.40, 148.98), (40.43, -4.25))
# m/s^2: solar pressure on ~1.3 m^2 per tonne, away from the Sun of early April; the two-body fit
# has no SRP and must cover it with its stochastic accelerations
SRP_LIKE = -6e-9 * np.array([0.98, 0.17, 0.07]) / np.linalg.norm([0.98, 0.17, 0.07])


def visible_passes(times, stations_lat_lon, positions, min_el_deg=10.0):
    """(time index, station) pairs with elevation above ``min_el_deg`` (spherical Earth)."""
    rs, _ = station_states(stations_lat_lon, times)
    d = positions[None, :, :] - rs
    sin_el = np.sum(d * rs, -1) / (np.linalg.norm(d, axis=-1) * R_EARTH)
    st, it = np.nonzero(sin_el > np.sin(np.radians(min_el_deg)))
    order = np.lexsort((st, it))
    return it[order], st[order]


def simulate_twobody(x0, acc_batches, batch, maneuvers, times, rtol=1e-12):
    """Truth states (m, 6) at sorted ``times`` by scipy DOP853 (independent of the RK4).

    acc_batches: (nb, 3) acceleration per batch of ``batch`` s from t = 0;
    maneuvers: {epoch: dV(3)} applied impulsively.
    """
    from scipy.integrate import solve_ivp

    cuts = sorted(set(np.arange(0.0, times[-1], batch)) | set(maneuvers) | {times[-1]})
    out = np.empty((times.size, 6))
    x = np.array(x0, float)
    for a, b in zip(cuts[:-1], cuts[1:]):
        if a in maneuvers:
            x[3:] += maneuvers[a]
        acc = acc_batches[int(a // batch)]

        def rhs(_, y):
            r = y[:3]
            return np.concatenate([y[3:], -MU_EARTH * r / np.linalg.norm(r) ** 3 + acc])
        sel = (times >= a) & (times < b)
        te = np.append(times[sel], b)
        y = solve_ivp(rhs, (a, b), x, method="DOP853", rtol=rtol, atol=1e-9, t_eval=te).y
        out[sel] = y[:, :-1].T
        x = y[:, -1]
    out[times == cuts[-1]] = x
    return out


def twobody_case(rng, days=1.0, dt_obs=120.0, batch=8 * 3600.0, sig_acc=5e-9, tau=86400.0,
                 maneuvers=((10 * 3600.0, (3e-3, -2e-3, 5e-3)),), sig_range=2.0,
                 sig_rate=1e-4, dx0=(3e4, -2e4, 1e4, 0.3, -0.2, 0.1), stochastic=True,
                 designed=None, late=None, sigma_state=(1e5, 1.0), unmodelled=(0.0, 0.0, 0.0)):
    """Simulated two-body arc (orbit radius 20,000 km) tracked by three DSN-like stations.

    unmodelled: a constant inertial acceleration (m/s^2) the truth flies and the fit's model
    lacks (e.g. ``SRP_LIKE``); with stochastic accelerations their truth is the sum.

    maneuvers: (logged epoch, true dV); designed: a priori dV per maneuver (default 0);
    late: true firing delay (s) per maneuver, which also adds an epoch-offset
    parameter (sigma 10 s). Returns (problem, observations, truth) where truth holds
    the epoch vector in registry order and the per-batch accelerations. A priori as
    ARTEMIS Table 4.1: 100 km, 1 m/s, 5e-9 m/s^2 accelerations, 10 mm/s and 10 s
    maneuvers, 5 m range biases; ``sigma_state`` (m, m/s) replaces the state's.
    """
    from odpipe.estimation.fit import Observations

    r, inc = 2.0e7, np.radians(28.5)
    v = np.sqrt(MU_EARTH / r)
    x_nom = np.array([r, 0, 0, 0, v * np.cos(inc), v * np.sin(inc)])
    reg = ParameterRegistry()
    reg.add_state("sc", x_nom, *sigma_state)
    if stochastic:
        reg.add_stochastic_acceleration("sc", sig_acc, tau, batch, axes=("x", "y", "z"))
    designed = [(0.0, 0.0, 0.0)] * len(maneuvers) if designed is None else designed
    for j, (ep, _) in enumerate(maneuvers):
        reg.add_maneuver("sc", f"m{j}", ep, sigma_dv=0.01, designed=designed[j],
                         sigma_epoch=None if late is None else 10.0)
    for s in range(len(DSN_LIKE)):
        reg.add(f"bias.range.{s}", "bias", 0.0, 5.0, owner=f"dss{s}")
    arc = days * 86400.0
    nb = int(np.ceil(arc / batch)) + 1
    proc = reg.stochastic_groups()[0][1] if stochastic else None
    acc = np.zeros((nb, 3))
    if stochastic:
        m, q = proc.step()
        acc[0] = rng.normal(size=3) * sig_acc
        for j in range(1, nb):
            acc[j] = m * acc[j - 1] + rng.normal(size=3) * np.sqrt(q)
    acc = acc + np.asarray(unmodelled, float)
    x0 = x_nom + np.asarray(dx0)
    t_grid = np.arange(0.0, arc, dt_obs)
    fire = [ep + (0.0 if late is None else late[j]) for j, (ep, _) in enumerate(maneuvers)]
    X = simulate_twobody(x0, acc, batch, {f: np.asarray(dv) for f, (_, dv) in zip(fire, maneuvers)},
                         t_grid)
    it, st = visible_passes(t_grid, DSN_LIKE, X[:, :3])
    it, st = np.repeat(it, 2), np.repeat(st, 2)
    kind = np.tile([0, 1], it.size // 2)
    t = t_grid[it]
    rs, vs = station_states(DSN_LIKE, t)
    mrow = np.arange(t.size)
    z, _ = range_and_rate(X[it], rs[st, mrow], vs[st, mrow], kind)
    bias = rng.normal(size=len(DSN_LIKE)) * 5.0
    z[kind == 0] += bias[st[kind == 0]]
    sigma = np.where(kind == 0, sig_range, sig_rate)
    z += rng.normal(size=z.size) * sigma
    truth_vec = reg.apriori.copy()
    truth_vec[reg.slice("state", "sc")] = x0
    if stochastic:
        truth_vec[reg.slice("stochastic", "sc")] = acc[0]
    for j, (_, dv) in enumerate(maneuvers):
        truth_vec[reg.slice("maneuver", f"sc.m{j}")] = dv
        if late is not None:
            truth_vec[reg.index(f"sc.m{j}.dt")] = late[j]
    truth_vec[reg.slice("bias")] = bias
    problem = TwoBodyProblem(reg, t, st, kind, DSN_LIKE)
    obs = Observations(t, z, sigma, np.array([f"dss{s}.{'range' if k == 0 else 'rate'}"
                                              for s, k in zip(st, kind)]))
    return problem, obs, {"x0": truth_vec, "acc": acc, "states": X, "t_grid": t_grid}


def compile_kernels() -> None:
    """Compile this module's numba kernels into the checkout's cache (``make``'s install runs
    ``python -m tests.estimation_cases``), so that the tests load them instead of compiling."""
    flow(np.array([2.0e7, 0.0, 0.0, 0.0, 4.5e3, 0.0]), np.zeros(3), 0.0, np.array([60.0]), 30.0)


if __name__ == "__main__":
    compile_kernels()
