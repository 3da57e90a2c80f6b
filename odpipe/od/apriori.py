"""A priori orbit of a low, near-circular orbiter from its own two-way Doppler.

For a spacecraft with no ephemeris (e.g. GRAIL-B in its 55-km lunar mapping orbit),
the epoch state is found in three steps, all in SI units (m, m/s, s; TDB s past J2000):

1. **Line of sight.** Blunders are edited (:func:`odpipe.preprocess.edit.edit`), the 1-s
   Doppler is compressed (:func:`odpipe.preprocess.compress.compress`, 60 s) and computed
   (:func:`odpipe.measurements.compute`) for a spacecraft sitting at the centre of the body.
   Observed minus that value, along the line of sight, is ``y`` (m/s): the spacecraft's
   range-rate relative to the centre's, modelled cheaply and to ~mm/s by the change over
   the count of ``|p + r| - |p|`` (``p`` station to centre, ``r`` centre to spacecraft;
   :class:`LineOfSight`).
2. **Grid search** over circular Kepler orbits: period, node (RAAN) and inclination in the
   body's PA frame frozen at the epoch. To first order ``y = v . u`` (``u`` towards the
   centre); for one (period, node, inclination) the model ``y = V [cos u0 A1(t) + sin u0 A2(t)]``
   is linear in (cos u0, sin u0), so the argument of latitude at epoch ``u0`` comes out of
   a 2x2 solve for every grid point (a compiled pass over the rows, no search over the phase).
   Candidates are scored by a trimmed RMS (the worst ``trim`` fraction left out), computed
   only where bounds from the untrimmed sum and the largest residual leave a grid point a
   chance among the best. Rows far off the best candidate are flagged BLUNDER.
3. **Refinement** of the best distinct candidates through the force model:
   ``scipy.optimize.least_squares`` (soft-L1 loss) on the six epoch-state components with
   the :class:`LineOfSight` model and the STM as Jacobian, the arc growing pass by pass;
   rows the fitted orbit misses by many robust sigmas are flagged RESIDUAL and the fit is
   repeated. The full measurement models then give the post-fit residuals; the lowest
   RMS wins. (:func:`odpipe.od.arc.fit_arc`, a filter-smoother with data reweighting,
   oscillated from a start some km and m/s off; it takes over from this a priori orbit.)

Doppler from Earth sees only the velocity along ``u``: rotating an orbit about ``u`` leaves
``y`` unchanged. With the inclination held near polar this leaves a two-fold ambiguity
(the orbit turned 180 deg about the Earth direction); only the dynamics (the body's
field, the slow turn of ``u``) separate the two, so both are refined and reported.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
from numba import njit
from scipy.optimize import least_squares

from odpipe.constants import C_LIGHT
from odpipe.dynamics.forces import ForceModel
from odpipe.dynamics.propagator import propagate
from odpipe.measurements import MeasurementSetup, compute, residuals
from odpipe.preprocess.compress import compress
from odpipe.preprocess.edit import EditConfig, edit
from odpipe.preprocess.flags import Flag, set_flag
from odpipe.tracking.ramp_segments import store
from odpipe.tracking.timetags import interval_bounds
from odpipe.time import utc_to_tdb


@dataclass
class AprioriResult:
    """Epoch state (ICRF about the force model's centre, m, m/s) at ``epoch`` (TDB s) with its fit.

    rms_los: post-fit RMS of the used 2-way Doppler (m/s); rms_hz: the same in Hz;
    elements: :func:`orbit_elements` of the state; candidates: the refined grid
    candidates (grid values, post-fit RMS); rows: the compressed Doppler with their flags and
    post-fit residuals ``postfit_los`` (m/s) and ``postfit_hz``.
    """

    epoch: float
    state: np.ndarray
    rms_los: float
    rms_hz: float
    elements: dict
    candidates: pd.DataFrame
    rows: pd.DataFrame


class _BodyCentre:
    """A 'trajectory' that stays at the centre of ``center`` (zero state)."""

    def __init__(self, center: str):
        self.center = center

    def state(self, t):
        return np.zeros((np.size(t), 6))


def doppler_rows(table: pd.DataFrame, ramps, spacecraft: str, count_time: float = 60.0,
                 min_count: float = 30.0) -> pd.DataFrame:
    """Unflagged 2-way Doppler of ``spacecraft``, blunder-edited and compressed to ``count_time`` (s); ``ramps``:
    a ramp table or :class:`parsers.ramps.RampStore`.

    Windows shorter than ``min_count`` s are left out: a ramp segment or pass start leaves
    one- or few-sample windows whose uplink is often not yet covered by the ramps.
    """
    sel = (table["observable"] == "doppler_2way").to_numpy() & (table["spacecraft"].astype(str) == spacecraft).to_numpy()
    ramps = store(ramps)  # checked once for the editors and the compression
    # no geometry yet (the orbit is what is sought): no elevation mask
    edited, _ = edit(table[sel].reset_index(drop=True), ramps, EditConfig(min_elevation=-np.inf))
    rows, _ = compress(edited, count_time, ramps=ramps)
    keep = (rows["flags"].to_numpy() == 0) & (rows["count_time"].to_numpy(float) >= min_count)
    return rows[keep].reset_index(drop=True)


@dataclass
class LineOfSight:
    """Doppler rows turned into spacecraft range-rate relative to the body's centre.

    t0, t1: spacecraft event times (TDB s) of each count interval's start and end (reception
    less the one-way light time to the centre); p0, p1: centre minus station position (N,3,
    ICRF m) at those times; y: observed minus the value computed for a spacecraft at the
    centre, along the line of sight (m/s; NaN where not computable). For a spacecraft at
    ``r`` (ICRF m, relative to the centre) the same quantity is
    ``(|p1 + r(t1)| - |p0 + r(t0)| - |p1| + |p0|) / (t1 - t0)`` (:meth:`model`).
    """

    t0: np.ndarray
    t1: np.ndarray
    p0: np.ndarray
    p1: np.ndarray
    y: np.ndarray

    @property
    def mid(self) -> np.ndarray:
        return 0.5 * (self.t0 + self.t1)

    @property
    def direction(self) -> np.ndarray:
        """Unit vectors (N,3) from the station to the centre at mid-interval."""
        d = self.p0 + self.p1
        return d / np.linalg.norm(d, axis=1)[:, None]

    def model(self, r0, r1, phi0, phi1):
        """Modelled y (N,) for positions r0, r1 (N,3) at t0, t1, and d y / d x0 (N,6) from the STMs (N,6,6)."""
        d0, d1 = self.p0 + r0, self.p1 + r1
        n0, n1 = np.linalg.norm(d0, axis=1), np.linalg.norm(d1, axis=1)
        dt = self.t1 - self.t0
        y = (n1 - n0 - np.linalg.norm(self.p1, axis=1) + np.linalg.norm(self.p0, axis=1)) / dt
        jac = (np.einsum("ni,nij->nj", d1 / n1[:, None], phi1[:, :3, :])
               - np.einsum("ni,nij->nj", d0 / n0[:, None], phi0[:, :3, :])) / dt[:, None]
        return y, jac


def line_of_sight(rows: pd.DataFrame, setup: MeasurementSetup, center: str) -> LineOfSight:
    """:class:`LineOfSight` of Doppler ``rows`` (see there)."""
    ev = compute(rows, {str(sc): _BodyCentre(center) for sc in rows["spacecraft"].unique()}, setup)
    _, y = residuals(rows, ev)
    start, end = interval_bounds(rows["epoch"].to_numpy("datetime64[ns]").astype(np.int64),
                                 rows["count_time"].to_numpy(float), rows["tag"].to_numpy(object))
    ends = []
    for ns in (start, end):
        t = np.asarray(utc_to_tdb(ns.astype("datetime64[ns]")), float)
        p = np.empty((len(rows), 3))
        for station, idx in rows.groupby("station_rx").indices.items():
            r_sta = setup.station(station).state(t[idx])[:, :3]
            lt = np.linalg.norm(setup.ephemeris.state(center, setup.origin, t[idx])[:, :3] - r_sta, axis=1) / C_LIGHT
            t[idx] -= lt
            p[idx] = setup.ephemeris.state(center, setup.origin, t[idx])[:, :3] - r_sta
        ends.append((t, p))
    (t0, p0), (t1, p1) = ends
    return LineOfSight(t0, t1, p0, p1, np.where(ev.status == "", y, np.nan))


def _plane_axes(raan, inc):
    """Node vector P and in-plane normal-to-node Q (K,3) in the body frame."""
    cO, sO, ci, si = np.cos(raan), np.sin(raan), np.cos(inc), np.sin(inc)
    return np.stack([cO, sO, 0 * cO], 1), np.stack([-ci * sO, ci * cO, si], 1)


def circular_search(tau, y, u_body, gm: float, periods, raans, inclinations, trim: float = 0.1,
                    keep: int = 200) -> pd.DataFrame:
    """Score circular orbits against line-of-sight velocities; the ``keep`` best, best first.

    tau: s past the epoch (N,); y: m/s (N,); u_body: unit vectors (N,3) in the frozen body
    frame; periods s, raans and inclinations rad (grids). Columns: period, raan, inc,
    arglat (rad, at the epoch), score (trimmed RMS, m/s).

    The trimmed mean square of an orbit lies between (sum - n_trimmed * largest) / n_use and the
    untrimmed mean square; only orbits whose lower bound is below the ``keep``-th smallest upper
    bound can be among the ``keep`` best, and only theirs is computed (the others' score is inf).
    """
    ok = np.isfinite(y)
    tau, y, u_body = tau[ok], y[ok], u_body[ok]
    n_use = max(1, int(round((1.0 - trim) * y.size)))
    O, I = (g.ravel() for g in np.meshgrid(raans, inclinations, indexing="ij"))
    P, Q = _plane_axes(O, I)
    periods = np.atleast_1d(np.asarray(periods, float))
    n = 2.0 * np.pi / periods
    Pu, Qu, speed = P @ u_body.T, Q @ u_body.T, (gm * n) ** (1.0 / 3.0)
    u0, total, largest, solved = _circular_fits(tau, y, Pu, Qu, speed, n)
    upper = np.where(solved, total / y.size, np.inf)
    lower = (total - (y.size - n_use) * largest) / n_use
    bound = np.partition(upper, keep - 1, axis=None)[keep - 1] if upper.size > keep else np.inf
    score = np.full(u0.shape, np.inf)
    which = np.flatnonzero(solved & (lower <= bound))
    score.flat[which] = _trimmed_rms(tau, y, Pu, Qu, speed, n, u0, which, n_use)
    out = []
    for j, period in enumerate(periods):
        best = np.argsort(score[j])[:keep]
        out.append(pd.DataFrame({"period": period, "raan": O[best], "inc": I[best],
                                 "arglat": np.mod(u0[j, best], 2 * np.pi), "score": score[j, best]}))
    return pd.concat(out, ignore_index=True).sort_values("score", kind="stable").head(keep).reset_index(drop=True)


@njit(cache=True)
def _circular_los(V, cn, sn, p, q):
    """The two terms (A1, A2) of y = cos(u0) A1 + sin(u0) A2, m/s, for circular speed V at mean anomaly
    n t (cos, sin) and the line of sight dotted with the node vector (p) and its in-plane normal (q)."""
    return V * (cn * q - sn * p), -V * (cn * p + sn * q)


@njit(cache=True)
def _circular_fits(tau, y, Pu, Qu, speed, n):
    """Best phase of circular orbits, M periods (``speed`` m/s, mean motion ``n`` rad/s) by K planes (``Pu``,
    ``Qu``: (K, N) node and normal-to-node vectors dotted with the N line-of-sight unit vectors): u0 (rad,
    at tau = 0) from the 2x2 normal equations in (cos u0, sin u0); the sum and the largest of the squared
    residuals (m2/s2); whether the phase is determined. Each (M, K)."""
    M, (K, N) = n.size, Pu.shape
    u0, total, largest = np.empty((M, K)), np.empty((M, K)), np.empty((M, K))
    solved = np.empty((M, K), np.bool_)
    cn, sn, A1, A2 = np.empty(N), np.empty(N), np.empty(N), np.empty(N)
    for m in range(M):
        for i in range(N):  # scalar loops: array expressions would triple the compile time
            cn[i], sn[i] = np.cos(n[m] * tau[i]), np.sin(n[m] * tau[i])
        for k in range(K):
            a11 = a12 = a22 = b1 = b2 = 0.0
            for i in range(N):
                A1[i], A2[i] = _circular_los(speed[m], cn[i], sn[i], Pu[k, i], Qu[k, i])
                a11 += A1[i] * A1[i]
                a12 += A1[i] * A2[i]
                a22 += A2[i] * A2[i]
                b1 += A1[i] * y[i]
                b2 += A2[i] * y[i]
            u = np.arctan2(a11 * b2 - a12 * b1, a22 * b1 - a12 * b2)
            c, s = np.cos(u), np.sin(u)
            sq, top = 0.0, 0.0
            for i in range(N):
                r2 = (y[i] - c * A1[i] - s * A2[i]) ** 2
                sq += r2
                top = max(top, r2)
            u0[m, k], total[m, k], largest[m, k], solved[m, k] = u, sq, top, a11 * a22 - a12 ** 2 > 0.0
    return u0, total, largest, solved


@njit(cache=True)
def _trimmed_rms(tau, y, Pu, Qu, speed, n, u0, which, n_use):
    """RMS (m/s) of the ``n_use`` smallest residuals of the circular orbits at flat indices ``which`` of
    :func:`_circular_fits`' (M, K) arrays."""
    K, N = Pu.shape
    cn, sn = np.empty((n.size, N)), np.empty((n.size, N))
    for m in range(n.size):
        for i in range(N):
            cn[m, i], sn[m, i] = np.cos(n[m] * tau[i]), np.sin(n[m] * tau[i])
    out, r2 = np.empty(which.size), np.empty(N)
    for j in range(which.size):
        m, k = which[j] // K, which[j] % K
        c, s = np.cos(u0[m, k]), np.sin(u0[m, k])
        for i in range(N):
            A1, A2 = _circular_los(speed[m], cn[m, i], sn[m, i], Pu[k, i], Qu[k, i])
            r2[i] = (y[i] - c * A1 - s * A2) ** 2
        out[j] = np.sqrt(_smallest_mean(r2, n_use))
    return out


@njit(cache=True)
def _smallest_mean(v, count: int) -> float:
    """Mean of the ``count`` smallest values of ``v`` (reordered in place: quickselect, median-of-three pivot;
    compiles in a fraction of the time of numba's ``np.partition``)."""
    lo, hi, kth = 0, v.size - 1, count - 1
    while lo < hi:
        a, b, c = v[lo], v[(lo + hi) // 2], v[hi]
        pivot = max(min(a, b), min(max(a, b), c))
        i, j = lo, hi
        while i <= j:
            while v[i] < pivot:
                i += 1
            while v[j] > pivot:
                j -= 1
            if i <= j:
                v[i], v[j] = v[j], v[i]
                i += 1
                j -= 1
        if kth <= j:
            hi = j
        elif kth >= i:
            lo = i
        else:
            break
    return v[:count].mean()


def circular_los(tau, u_body, gm: float, period: float, raan: float, inc: float, arglat: float) -> np.ndarray:
    """Line-of-sight velocity (m/s) of a circular orbit at ``tau`` s past the epoch (body-frame u)."""
    n = 2.0 * np.pi / period
    P, Q = (x[0] for x in _plane_axes(np.array([raan]), np.array([inc])))
    u = arglat + n * np.asarray(tau, float)
    return (gm * n) ** (1.0 / 3.0) * (np.cos(u) * (u_body @ Q) - np.sin(u) * (u_body @ P))


def circular_state(gm: float, period: float, raan: float, inc: float, arglat: float, body_to_icrf) -> np.ndarray:
    """ICRF state (6,) m, m/s of a circular orbit given in the body frame (rotation body->ICRF)."""
    n = 2.0 * np.pi / period
    a = (gm / n ** 2) ** (1.0 / 3.0)
    P, Q = (x[0] for x in _plane_axes(np.array([raan]), np.array([inc])))
    r = a * (np.cos(arglat) * P + np.sin(arglat) * Q)
    v = n * a * (-np.sin(arglat) * P + np.cos(arglat) * Q)
    return np.concatenate([body_to_icrf @ r, body_to_icrf @ v])


def orbit_elements(state, gm: float, icrf_to_body, mean_radius: float) -> dict:
    """Osculating elements in the body frame: a, altitude (a - mean_radius), period (s), e, inc,
    raan, arglat (rad), and the current radius (m)."""
    r, v = icrf_to_body @ np.asarray(state[:3], float), icrf_to_body @ np.asarray(state[3:], float)
    rn = np.linalg.norm(r)
    h = np.cross(r, v)
    a = 1.0 / (2.0 / rn - v @ v / gm)
    e_vec = np.cross(v, h) / gm - r / rn
    node = np.cross([0.0, 0.0, 1.0], h)
    inc = np.arccos(h[2] / np.linalg.norm(h))
    raan = np.mod(np.arctan2(node[1], node[0]), 2 * np.pi)
    arglat = np.mod(np.arctan2(r @ np.cross(h, node) / np.linalg.norm(h), r @ node), 2 * np.pi)
    return {"a": a, "altitude": a - mean_radius, "period": 2 * np.pi * np.sqrt(a ** 3 / gm),
            "e": float(np.linalg.norm(e_vec)), "inc": float(inc), "raan": float(raan), "arglat": float(arglat),
            "radius": float(rn)}


def distinct(candidates: pd.DataFrame, count: int, min_angle: float = np.radians(20.0)) -> pd.DataFrame:
    """The ``count`` best candidates whose orbit normals or phases differ by more than ``min_angle``."""
    chosen = []
    for row in candidates.itertuples():
        h = np.cross(*(x[0] for x in _plane_axes(np.array([row.raan]), np.array([row.inc]))))
        same = [c for c in chosen if np.arccos(np.clip(h @ c[1], -1, 1)) < min_angle
                and abs(np.angle(np.exp(1j * (row.arglat - c[0].arglat)))) < min_angle]
        if not same:
            chosen.append((row, h))
        if len(chosen) == count:
            break
    return candidates.loc[[c[0].Index for c in chosen]]


def flag_outliers(rows: pd.DataFrame, miss, k: float, reason: Flag) -> pd.DataFrame:
    """A copy of ``rows`` with ``reason`` set where ``|miss|`` exceeds k robust (1.4826 MAD) sigmas, or is NaN."""
    miss = np.asarray(miss, float)
    sigma = 1.4826 * np.nanmedian(np.abs(miss - np.nanmedian(miss)))
    out = rows.copy()
    out["flags"] = set_flag(out["flags"].to_numpy(np.int64), ~(np.abs(miss) <= k * sigma), reason)
    return out


def _solve(fun_jac, x0, loss_scale: float, max_nfev: int):
    """least_squares on a function returning (residuals, Jacobian), evaluated once per state."""
    cache = {}

    def cached(x):
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = fun_jac(x)
        return cache[key]

    return least_squares(lambda x: cached(x)[0], np.asarray(x0, float), jac=lambda x: cached(x)[1],
                         x_scale=np.array([1e3, 1e3, 1e3, 1.0, 1.0, 1.0]), loss="soft_l1", f_scale=loss_scale,
                         max_nfev=max_nfev).x


def refine_los(los: LineOfSight, force_model: ForceModel, state0, start: float, windows, loss_scale: float = 1.0,
               max_nfev: int = 20) -> np.ndarray:
    """Epoch state fitted to :class:`LineOfSight` data (m/s) with its range-difference model.

    The arc grows window by window (``windows``: end times, TDB s), each fit starting from the
    last, so the Doppler's strong nonlinearity in the orbital phase never meets a poor guess.
    """
    x = np.asarray(state0, float)
    for end in windows:
        sel = np.isfinite(los.y) & (los.t1 <= end)
        part = LineOfSight(los.t0[sel], los.t1[sel], los.p0[sel], los.p1[sel], los.y[sel])

        def fun_jac(x, part=part, end=end):
            traj = propagate(x, start, end, force_model, with_stm=True)
            y, jac = part.model(traj.state(part.t0)[:, :3], traj.state(part.t1)[:, :3],
                                traj.stm(part.t0), traj.stm(part.t1))
            return y - part.y, jac

        x = _solve(fun_jac, x, loss_scale, max_nfev)
    return x


def determine_orbit(rows: pd.DataFrame, setup: MeasurementSetup, force_model: ForceModel, spacecraft: str,
                    body_to_icrf, mean_radius: float, *, periods=None, raans=None, inclinations=None,
                    n_refine: int = 2, edit_k: float = 10.0) -> AprioriResult:
    """Epoch state at the start of ``rows`` (from :func:`doppler_rows`) by grid search and least squares.

    body_to_icrf(t) -> (3,3): the body frame (e.g. :func:`odpipe.frames.moon.moon_pa_to_icrf`);
    default grids: periods 105-120 min by 15 s, RAAN 0-360 deg by 2 deg, inclination 80-100 deg by 1 deg.
    Rows off the best circular orbit by more than ``edit_k`` robust sigmas are flagged BLUNDER
    before the fit; rows the fitted orbit misses by more than ``edit_k`` robust sigmas are
    flagged RESIDUAL and the fit repeated once.
    """
    periods = np.arange(105.0, 120.01, 0.25) * 60.0 if periods is None else periods
    raans = np.radians(np.arange(0.0, 360.0, 2.0)) if raans is None else raans
    inclinations = np.radians(np.arange(80.0, 100.01, 1.0)) if inclinations is None else inclinations
    gm = force_model.central_gm or force_model.ephemeris.gm(force_model.center)
    los = line_of_sight(rows, setup, force_model.center)
    start, end = float(np.floor(los.t0.min() - 10.0)), float(np.ceil(los.t1.max() + 10.0))
    rot = np.asarray(body_to_icrf(start), float)
    tau, u = los.mid - start, los.direction @ rot
    grid = circular_search(tau, los.y, u, gm, periods, raans, inclinations)
    best = grid.iloc[0]
    miss = los.y - circular_los(tau, u, gm, best.period, best.raan, best.inc, best.arglat)
    rows = flag_outliers(rows, miss, edit_k, Flag.BLUNDER)
    tried = []
    gaps = np.flatnonzero(np.diff(los.t1) > 600.0)
    windows = [float(los.t1[i]) + 1.0 for i in gaps] + [end]
    for cand in distinct(grid, n_refine).itertuples():
        x = circular_state(gm, cand.period, cand.raan, cand.inc, cand.arglat, rot)
        edited = rows
        try:
            for _ in range(2):  # fit, flag what the fitted orbit misses, fit again
                ok = edited["flags"].to_numpy() == 0
                x = refine_los(replace(los, y=np.where(ok, los.y, np.nan)), force_model, x, start, windows)
                post, post_hz = _postfit(edited, setup, force_model, spacecraft, x, start, end)
                edited = flag_outliers(edited, np.where(ok, post, 0.0), edit_k, Flag.RESIDUAL)
        except RuntimeError:  # the fit drove this candidate into the body: the integrator gives up
            continue
        tried.append((x, edited, post, post_hz, cand))
    if not tried:
        raise RuntimeError("no grid candidate could be refined into an orbit")
    tried.sort(key=lambda c: _rms(c[2], c[1]))
    state, used, post, post_hz, _ = tried[0]
    table = pd.DataFrame([{**c._asdict(), "postfit_rms": _rms(lo, r), "postfit_rms_hz": _rms(h, r)}
                          for _, r, lo, h, c in tried])
    return AprioriResult(start, state, _rms(post, used), _rms(post_hz, used), orbit_elements(state, gm, rot.T, mean_radius),
                         table, used.assign(postfit_los=post, postfit_hz=post_hz))


def _postfit(rows, setup, force_model, spacecraft, x, start, end):
    """Residuals of every row (m/s along the line of sight, and Hz) for epoch state x."""
    ev = compute(rows, {spacecraft: propagate(x, start, end, force_model, with_stm=False)}, setup)
    hz, los = residuals(rows, ev)
    return los, hz


def _rms(values, rows) -> float:
    ok = rows["flags"].to_numpy() == 0
    return float(np.sqrt(np.nanmean(np.asarray(values)[ok] ** 2)))
