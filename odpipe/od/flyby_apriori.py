"""A priori orbit of a spacecraft approaching a planetary flyby, from its two-way Doppler and the flyby epoch.

For a cruise arc with no ephemeris (e.g. MESSENGER the 1.5 days before its second Venus flyby,
2007-06-05 23:08 UTC) the epoch state is found in three steps (SI units; times TDB s past J2000):

1. **Line of sight.** The arc's 2-way Doppler, computed for a spacecraft sitting at the planet's
   centre, gives ``y``: the spacecraft's range-rate relative to the planet (m/s,
   :class:`odpipe.od.apriori.LineOfSight`).
2. **Asymptote search.** Far from the planet the approach is close to the radial (rectilinear)
   hyperbola that reaches the centre at the flyby epoch ``t_p``: ``r(t) = s * rho(t_p - t)`` with
   ``rho = (mu/v∞²)(cosh F - 1)``, ``t_p - t = (mu/v∞³)(sinh F - F)``; ``s`` (unit vector, the
   side the spacecraft comes from) and ``v∞`` are searched on a grid, each scored by the trimmed
   RMS of its modelled ``y`` against the data (the diurnal parallax of the offset ``r`` orients
   ``s`` across the line of sight), then the best distinct candidates are polished by least squares
   over the side's two angles and ``v∞``. The flyby's miss distance (a planet radius) is neglected.
3. **Refinement** of the best distinct candidates through the full force model about the planet:
   rows off a running median of the candidate's residuals by more than ``jump`` m/s are flagged
   BLUNDER (segments hundreds of m/s off, uplink hand-overs), then soft-L1 least squares on the
   epoch state (:func:`refine`); rows the fitted orbit misses by many robust sigmas are flagged
   RESIDUAL and the fit repeated. The lowest post-fit RMS wins; its closest approach is compared
   with the published flyby. The arc fit (:func:`odpipe.od.arc.fit_arc`) takes over from there.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
from numba import njit
from scipy.optimize import least_squares

from odpipe.dynamics.forces import ForceModel
from odpipe.dynamics.propagator import propagate
from odpipe.measurements import MeasurementSetup
from odpipe.od.apriori import LineOfSight, flag_outliers, line_of_sight
from odpipe.preprocess.flags import Flag, set_flag


@dataclass
class FlybyApriori:
    """Epoch state (ICRF about the planet, m, m/s) at ``epoch`` (TDB s), its post-fit RMS of the
    used Doppler along the line of sight (m/s), the closest approach it predicts (``periapsis``
    m from the centre at ``periapsis_epoch`` TDB s), the searched ``candidates`` and the ``rows``
    with their flags and post-fit ``postfit_los`` (m/s)."""

    epoch: float
    state: np.ndarray
    rms_los: float
    periapsis: float
    periapsis_epoch: float
    candidates: pd.DataFrame
    rows: pd.DataFrame


def radial_distance(tau, mu: float, v_inf: float) -> np.ndarray:
    """Distance (m) on the radial hyperbola (speed ``v_inf`` m/s at infinity) ``tau`` s before it reaches the centre."""
    tau = np.asarray(tau, float)
    m = tau * v_inf ** 3 / mu  # = sinh F - F
    f = prev = np.arcsinh(m) + 1.0  # Newton from above the root (sinh F - F is convex for F > 0), 60 steps
    for k in range(60):
        step = f - (np.sinh(f) - f - m) / (np.cosh(f) - 1.0)
        if np.array_equal(step, prev, equal_nan=True):   # every value now repeats with period 1 or 2:
            f = step if (59 - k) % 2 == 0 else f                 # the 60th step's is the one of its parity
            break
        prev, f = f, step
    return mu / v_inf ** 2 * (np.cosh(f) - 1.0)


def sphere_grid(step_deg: float) -> np.ndarray:
    """Unit vectors (K,3) spaced about ``step_deg`` on the sphere."""
    out = []
    for lat in np.radians(np.arange(-90.0 + step_deg / 2, 90.0, step_deg)):
        n = max(1, int(round(360.0 * np.cos(lat) / step_deg)))
        lon = np.arange(n) * 2 * np.pi / n
        out.append(np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.full(n, np.sin(lat))], 1))
    return np.concatenate(out)


def radial_los(los: LineOfSight, t_p: float, mu: float, sides: np.ndarray, v_inf: float) -> np.ndarray:
    """Modelled y (K, N) m/s of the radial approaches from ``sides`` (K,3) at speed ``v_inf`` (m/s at infinity)
    reaching the centre at ``t_p``: ``|p + s rho|`` is ``sqrt(|p|² + 2 rho s.p + rho²)``."""
    sight = _Sight.of(los)
    return _sides_misfit(sight, _distances(sight, t_p, mu, v_inf), sides @ los.p0.T, sides @ los.p1.T,
                         np.zeros(los.y.size), False)


@dataclass
class _Sight:
    """What a :class:`LineOfSight` fixes for every approach tried on it: |p0|², |p1|² (m²), |p1| - |p0| (m),
    t1 - t0 (s), and its count bounds' distinct epochs ``tau_t`` (TDB s) with ``which`` (t0 then t1 rows into
    them: consecutive counts share a bound, so each distance is solved once)."""

    pp0: np.ndarray
    pp1: np.ndarray
    dn: np.ndarray
    dt: np.ndarray
    tau_t: np.ndarray
    which: np.ndarray

    @classmethod
    def of(cls, los: LineOfSight) -> "_Sight":
        t, which = np.unique(np.concatenate([los.t0, los.t1]), return_inverse=True)
        return cls(np.sum(los.p0 ** 2, 1), np.sum(los.p1 ** 2, 1),
                   np.linalg.norm(los.p1, axis=1) - np.linalg.norm(los.p0, axis=1), los.t1 - los.t0, t, which)


def _distances(sight: _Sight, t_p: float, mu: float, v_inf: float) -> tuple:
    """(rho0, rho1): the radial hyperbola's distances (m) at the count starts and ends of the rows of ``sight``
    (:func:`radial_distance` of each epoch does not depend on the others solved with it)."""
    rho = radial_distance(t_p - sight.tau_t, mu, v_inf)[sight.which]
    return rho[:sight.dt.size], rho[sight.dt.size:]


def _sides_misfit(sight: _Sight, rho, sp0: np.ndarray, sp1: np.ndarray, y: np.ndarray, square: bool) -> np.ndarray:
    """Modelled y of the sides minus ``y`` (K, N) m/s (squared when ``square``), from the distances ``rho`` =
    (rho0, rho1) (N,) and the products s.p0, s.p1 (K, N) of the sides with the station-to-centre vectors."""
    return _misfit_kernel(sp0, sp1, rho[0], rho[1], sight.pp0, sight.pp1, sight.dn, sight.dt, y, square)


@njit(cache=True, error_model="numpy")
def _misfit_kernel(sp0, sp1, rho0, rho1, pp0, pp1, dn, dt, y, square):
    """:func:`_sides_misfit` in one pass (each element's operations in the same order as the formula's)."""
    out = np.empty(sp0.shape)
    for k in range(sp0.shape[0]):
        for i in range(sp0.shape[1]):
            n0 = np.sqrt(sp0[k, i] * (2.0 * rho0[i]) + pp0[i] + rho0[i] * rho0[i])
            n1 = np.sqrt(sp1[k, i] * (2.0 * rho1[i]) + pp1[i] + rho1[i] * rho1[i])
            r = ((n1 - n0) - dn[i]) / dt[i] - y[i]
            out[k, i] = r * r if square else r
    return out


_SEARCH_CELLS = 1 << 16   # (side, row) cells per block of the asymptote search


def _usable(los: LineOfSight, t_p: float) -> LineOfSight:
    ok = np.isfinite(los.y) & (los.t1 < t_p)
    return LineOfSight(los.t0[ok], los.t1[ok], los.p0[ok], los.p1[ok], los.y[ok])


def asymptote_search(los: LineOfSight, t_p: float, mu: float, sides: np.ndarray, speeds, trim: float = 0.2,
                     keep: int = 50) -> pd.DataFrame:
    """Score radial approaches (side ``s`` from ``sides`` (K,3), speed at infinity from ``speeds`` m/s) reaching the
    centre at ``t_p``; the ``keep`` best, best first: columns sx, sy, sz, v_inf, score (trimmed RMS of y, m/s).
    The score changes by m/s within a degree: polish the best (:func:`polish_approach`)."""
    los = _usable(los, t_p)
    sight = _Sight.of(los)
    n_use = max(1, int(round((1.0 - trim) * los.y.size)))
    chunk = max(1, _SEARCH_CELLS // max(1, los.y.size))       # sides per block: its (K, N) arrays stay in cache
    blocks = [(sides[k:k + chunk] @ los.p0.T, sides[k:k + chunk] @ los.p1.T) for k in range(0, len(sides), chunk)]
    out = []
    for v in np.atleast_1d(speeds):
        rho = _distances(sight, t_p, mu, float(v))
        score = np.empty(len(sides))
        for k, (sp0, sp1) in zip(range(0, len(sides), chunk), blocks):
            r2 = _sides_misfit(sight, rho, sp0, sp1, los.y, True)
            score[k:k + chunk] = np.sqrt(np.partition(r2, n_use - 1, axis=1)[:, :n_use].mean(1))
        out.append(pd.DataFrame({"sx": sides[:, 0], "sy": sides[:, 1], "sz": sides[:, 2], "v_inf": float(v),
                                 "score": score}))
    return pd.concat(out, ignore_index=True).sort_values("score", kind="stable").head(keep).reset_index(drop=True)


def polish_approach(los: LineOfSight, t_p: float, mu: float, side, v_inf: float, loss_scale: float = 1.0):
    """(side (3,), v_inf m/s) of the radial approach fitted to ``los`` from a grid candidate (soft-L1 least
    squares over the side's two angles and the speed)."""
    los = _usable(los, t_p)
    sight = _Sight.of(los)
    s = np.asarray(side, float)

    def unit(a):
        return np.array([np.cos(a[1]) * np.cos(a[0]), np.cos(a[1]) * np.sin(a[0]), np.sin(a[1])])

    rho = {}   # speed -> (rho0, rho1): the Jacobian's steps in the two angles keep the speed

    def residual(a):
        v = a[2] * 1e3
        if v not in rho:
            rho[v] = _distances(sight, t_p, mu, v)
        side = unit(a)[None, :]
        return _sides_misfit(sight, rho[v], side @ los.p0.T, side @ los.p1.T, los.y, False)[0]

    a0 = np.array([np.arctan2(s[1], s[0]), np.arcsin(np.clip(s[2], -1, 1)), v_inf / 1e3])
    fit = least_squares(residual, a0, loss="soft_l1", f_scale=loss_scale, diff_step=1e-7)
    return unit(fit.x), float(fit.x[2] * 1e3)


def approach_state(side, v_inf: float, mu: float, tau: float) -> np.ndarray:
    """State (6,) m, m/s on the radial approach ``tau`` s before the centre, coming from ``side``."""
    rho = radial_distance(tau, mu, v_inf)
    s = np.asarray(side, float)
    return np.concatenate([s * rho, -s * np.sqrt(v_inf ** 2 + 2 * mu / rho)])


def distinct_sides(candidates: pd.DataFrame, count: int, min_angle: float = np.radians(10.0)) -> pd.DataFrame:
    """The ``count`` best candidates whose sides differ by more than ``min_angle``."""
    chosen = []
    for row in candidates.itertuples():
        s = np.array([row.sx, row.sy, row.sz])
        if all(np.arccos(np.clip(s @ c, -1, 1)) > min_angle for _, c in chosen):
            chosen.append((row.Index, s))
        if len(chosen) == count:
            break
    return candidates.loc[[i for i, _ in chosen]]


def closest_approach(state, start: float, t_p: float, force_model: ForceModel, window: float = 6 * 3600.0):
    """(distance m, epoch TDB s) of the closest approach to the centre within ``window`` s of ``t_p``."""
    traj = propagate(state, start, t_p + window, force_model, with_stm=False)
    t = np.linspace(max(start, t_p - window), t_p + window, 20001)
    d = np.linalg.norm(traj.state(t)[:, :3], axis=1)
    i = int(np.argmin(d))
    return float(d[i]), float(t[i])


def determine_flyby_orbit(rows: pd.DataFrame, setup: MeasurementSetup, force_model: ForceModel, t_p: float, *,
                          speeds=None, step_deg: float = 3.0, n_refine: int = 3, edit_k: float = 10.0,
                          jump: float = 5.0, loss_scale: float = 0.1) -> FlybyApriori:
    """Epoch state at the start of ``rows`` (compressed 2-way Doppler, :func:`odpipe.od.apriori.doppler_rows`)
    of a spacecraft that flies by ``force_model.center`` at ``t_p`` (TDB s).

    Default speed grid 3-20 km/s by 0.5 km/s; sides every ``step_deg`` deg. Rows the fitted orbit
    misses by more than ``edit_k`` robust sigmas are flagged RESIDUAL and the fit repeated.
    """
    speeds = np.arange(3e3, 20.01e3, 500.0) if speeds is None else speeds
    mu = force_model.central_gm or force_model.ephemeris.gm(force_model.center)
    los = line_of_sight(rows, setup, force_model.center)
    start, end = float(np.floor(los.t0.min() - 10.0)), float(np.ceil(los.t1.max() + 10.0))
    grid = asymptote_search(los, t_p, mu, sphere_grid(step_deg), speeds)
    tried = []
    for cand in distinct_sides(grid, n_refine).itertuples():
        side, v_inf = polish_approach(los, t_p, mu, [cand.sx, cand.sy, cand.sz], cand.v_inf)
        x = approach_state(side, v_inf, mu, t_p - start)
        try:
            miss = _postfit_los(los, force_model, x, start, end)
            smooth = pd.Series(miss).rolling(31, center=True, min_periods=5).median().to_numpy()
            edited = rows.assign(flags=set_flag(rows["flags"].to_numpy(np.int64), ~(np.abs(miss - smooth) <= jump),
                                                Flag.BLUNDER))
            for _ in range(2):  # fit, flag what the fitted orbit misses, fit again
                ok = edited["flags"].to_numpy() == 0
                x = refine(replace(los, y=np.where(ok, los.y, np.nan)), force_model, x, start, end, loss_scale)
                post = _postfit_los(los, force_model, x, start, end)
                edited = flag_outliers(edited, np.where(ok, post, 0.0), edit_k, Flag.RESIDUAL)
        except RuntimeError:  # the fit drove this candidate into the planet: the integrator gives up
            continue
        rms = float(np.sqrt(np.nanmean(post[edited["flags"].to_numpy() == 0] ** 2)))
        tried.append((rms, x, edited.assign(postfit_los=post), cand))
    if not tried:
        raise RuntimeError("no approach candidate could be refined into an orbit")
    tried.sort(key=lambda c: c[0])
    rms, state, used, _ = tried[0]
    r_p, t_min = closest_approach(state, start, t_p, force_model)
    table = pd.DataFrame([{**c._asdict(), "postfit_rms": r} for r, _, _, c in tried])
    return FlybyApriori(start, state, rms, r_p, t_min, table, used)


def _postfit_los(los: LineOfSight, force_model: ForceModel, x, start: float, end: float) -> np.ndarray:
    """Data minus the line-of-sight model (m/s) for epoch state ``x``."""
    traj = propagate(x, start, end, force_model, with_stm=True)
    y, _ = los.model(traj.state(los.t0)[:, :3], traj.state(los.t1)[:, :3], traj.stm(los.t0), traj.stm(los.t1))
    return los.y - y


def refine(los: LineOfSight, force_model: ForceModel, state0, start: float, end: float, loss_scale: float = 0.1,
           max_nfev: int = 200) -> np.ndarray:
    """Epoch state fitted to line-of-sight Doppler (m/s; NaN rows left out): soft-L1 least squares (scale
    ``loss_scale`` m/s) with the STM as Jacobian and the variables scaled by it (positions are ~1e3 times
    less determined than velocities at 0.7 AU, so unscaled steps stall)."""
    ok = np.isfinite(los.y)
    part = LineOfSight(los.t0[ok], los.t1[ok], los.p0[ok], los.p1[ok], los.y[ok])
    cache = {}

    def fun_jac(x):
        key = x.tobytes()
        if key not in cache:
            traj = propagate(x, start, end, force_model, with_stm=True)
            y, jac = part.model(traj.state(part.t0)[:, :3], traj.state(part.t1)[:, :3],
                                traj.stm(part.t0), traj.stm(part.t1))
            cache.clear()
            cache[key] = (y - part.y, jac)
        return cache[key]

    return least_squares(lambda x: fun_jac(x)[0], np.asarray(state0, float), jac=lambda x: fun_jac(x)[1],
                         x_scale="jac", loss="soft_l1", f_scale=loss_scale, max_nfev=max_nfev).x
