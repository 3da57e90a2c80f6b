"""The true trajectory of a simulated case: full force model, stochastic accelerations, executed maneuvers.

* stochastic accelerations: piecewise-constant RTN batches from a first-order
  Gauss-Markov sequence a[k+1] = m a[k] + sqrt(1 - m^2) sigma w[k],
  m = exp(-batch/tau) (white when tau = 0), seeded;
* initial state: the CRTBP Lyapunov state, z0 out of the plane in the DE421 geometry, its velocity corrected
  for a perpendicular x-z plane crossing (:mod:`odpipe.simulate.stationkeeping`);
* maneuvers: station-keeping delta-v designed in time order, with the filter's force model
  (the [spacecraft_model] cylinder), on the true state at the maneuver epoch plus a
  navigation error ~ N(0, nav_sigma) per axis (operations design from OD); attitude
  maneuvers as given; each executed as the designed ICRF delta-v scaled by (1 + e_mag)
  and turned by a pointing error (angle ~ N(0, sigma) about a random axis normal to it);
* force model: Earth centre, Moon and Sun point masses (DE421), SRP with Earth and Moon
  shadow on the real body ([truth_body]: a spin-averaged square bus, top and bottom
  plates, the spin axis tilted; without it the model's cylinder), the batches, the
  unmodelled accelerations ([unmodelled]: outgassing along the spin axis, piecewise linear
  per day; a plume acceleration after each burn), the maneuvers.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from odpipe.constants import SECONDS_PER_DAY
from odpipe.dynamics import (Cylinder, EmpiricalRTN, ForceModel, ImpulsiveManeuver, InertialPolynomialAcceleration,
                             Plate, PointMasses, SolarRadiationPressure, propagate)
from odpipe.dynamics.trajectory import Trajectory
from odpipe.simulate.libration import lyapunov_orbit, rotating_to_icrf
from odpipe.simulate.stationkeeping import design_dv
from odpipe.time import utc_to_tdb

MARGIN_S = 3600.0  # trajectory starts this long before the first sample (light time, uplink legs)


@dataclass
class Truth:
    trajectory: Trajectory
    force_model: ForceModel
    maneuvers: list          # dicts: name, epoch (UTC), kind, dv (designed, ICRF m/s)
    designed: np.ndarray     # (K,3) ICRF m/s
    executed: np.ndarray     # (K,3) ICRF m/s
    epochs: np.ndarray       # (K,) TDB s
    batches: np.ndarray      # (B,5) t_start, t_end, aR, aT, aN


def executed_dv(designed: np.ndarray, sigma_mag: float, sigma_point: float, rng) -> np.ndarray:
    """Executed delta-v (K,3): magnitude error (fraction) and pointing error (rad), both 1-sigma."""
    d = np.atleast_2d(designed)
    u = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)
    axis = np.cross(u, rng.standard_normal(d.shape))
    axis /= np.maximum(np.linalg.norm(axis, axis=1, keepdims=True), 1e-300)
    ang = sigma_point * rng.standard_normal(len(d))[:, None]
    turned = d * np.cos(ang) + np.cross(axis, d) * np.sin(ang)
    return turned * (1.0 + sigma_mag * rng.standard_normal(len(d)))[:, None]


def gauss_markov_batches(t0: float, t1: float, batch_s: float, sigma: float, tau: float, rng) -> np.ndarray:
    """(B,5) RTN batches [t_start, t_end, aR, aT, aN] over [t0, t1) (TDB s, m/s^2)."""
    edges = np.append(np.arange(t0, t1, batch_s), t1)
    n = edges.size - 1
    m = np.exp(-batch_s / tau) if tau > 0 else 0.0
    w = rng.standard_normal((n, 3)) * sigma
    a = np.empty((n, 3))
    a[0] = w[0]
    for k in range(1, n):
        a[k] = m * a[k - 1] + np.sqrt(1 - m * m) * w[k]
    return np.column_stack([edges[:-1], edges[1:], a])


def initial_state(case, ephemeris, t0: float) -> np.ndarray:
    """Geocentric ICRF state (m, m/s) at t0 from the case's CRTBP libration orbit."""
    mu = ephemeris.gm("moon") / (ephemeris.gm("moon") + ephemeris.gm("earth"))
    o = case.orbit
    s, _ = lyapunov_orbit(mu, o.point, o.amplitude)
    s[2] = o.z_amplitude    # out of the Earth-Moon plane: a Lissajous-like 3-D orbit
    return rotating_to_icrf(s, mu, ephemeris.state("moon", "earth", np.array([t0]))[0])


def tilted(axis: np.ndarray, degrees: float, w: np.ndarray) -> np.ndarray:
    """Unit ``axis`` turned by ``degrees`` about the direction normal to it nearest ``w`` (3,)."""
    u = axis / np.linalg.norm(axis)
    n = np.cross(u, w)
    n /= np.linalg.norm(n)
    a = np.radians(degrees)
    return u * np.cos(a) + np.cross(n, u) * np.sin(a)


def model_body(sc) -> list:
    """The filter's SRP surfaces: the [spacecraft_model] cylinder about the nominal spin axis."""
    axis = np.asarray(sc.spin_axis, float)
    return [Cylinder(axis / np.linalg.norm(axis), sc.radius_m, sc.length_m, sc.rho_s, sc.rho_d)]


def real_body(sc, tb, w: np.ndarray) -> tuple[list, np.ndarray]:
    """(SRP surfaces, spin axis) of the real body: the square bus spin-averaged as a cylinder of width
    4/pi its side, one-sided plates at both ends, the axis tilted by ``tb.axis_tilt_deg`` (direction from ``w``)."""
    axis = tilted(np.asarray(sc.spin_axis, float), tb.axis_tilt_deg, w)
    radius = 2.0 * tb.bus_side_m / np.pi
    surfaces = [Cylinder(axis, radius, sc.length_m, sc.rho_s, sc.rho_d)]
    if tb.plate_area_m2 > 0:
        surfaces += [Plate(s * axis, tb.plate_area_m2, sc.rho_s, sc.rho_d) for s in (1.0, -1.0)]
    return surfaces, axis


def outgassing(un, axis: np.ndarray, t0: float, t1: float) -> list:
    """Outgassing a0 exp(-(t - t0)/tau) along ``axis``, piecewise linear over days of [t0, t1] (TDB s)."""
    edges = np.append(np.arange(t0, t1, SECONDS_PER_DAY), t1)
    a = un.outgassing_m_s2 * np.exp(-(edges - t0) / (un.outgassing_tau_days * SECONDS_PER_DAY))
    return [InertialPolynomialAcceleration(ta, a[k] * axis, (a[k + 1] - a[k]) / (tb - ta) * axis, ta, tb)
            for k, (ta, tb) in enumerate(zip(edges[:-1], edges[1:])) if a[k] > 0]


def plume(un, t: float, dv: np.ndarray) -> list:
    """The plume acceleration after a burn at ``t`` (TDB s) of ``dv`` (m/s): plume_fraction dv over plume_hours."""
    if un is None or un.plume_fraction == 0:
        return []
    span = un.plume_hours * 3600.0
    return [InertialPolynomialAcceleration(t, un.plume_fraction * np.asarray(dv) / span, (0.0, 0.0, 0.0), t, t + span)]


def simulate_truth(case, ephemeris, rng) -> Truth:
    """Propagate the case's truth from MARGIN_S before its start to its end (+ margin)."""
    t0 = float(utc_to_tdb(case.start)) - MARGIN_S
    t1 = float(utc_to_tdb(case.end)) + MARGIN_S
    sc, st, ex, sk = case.body, case.stochastic, case.execution, case.station_keeping
    batches = gauss_markov_batches(t0, t1, st.batch_s, st.sigma, st.tau_s, rng)
    nominal = ForceModel("earth", [PointMasses(["moon", "sun"]), SolarRadiationPressure(surfaces=model_body(sc))],
                         mass=sc.mass_kg, ephemeris=ephemeris)
    surfaces, axis = model_body(sc), np.asarray(sc.spin_axis, float) / np.linalg.norm(sc.spin_axis)
    if case.truth_body is not None:
        surfaces, axis = real_body(sc, case.truth_body, rng.standard_normal(3))
    un = case.unmodelled
    extra = [] if un is None else outgassing(un, axis, t0, t1)
    gaps = tuple(np.asarray(sk.gap_days, float) * SECONDS_PER_DAY)
    horizon = sk.horizon_days * SECONDS_PER_DAY
    x0 = initial_state(case, ephemeris, t0)
    x0[3:] += design_dv(nominal, x0, t0, gaps, horizon, sk.max_dv_m_s)
    events = sorted([dict(m) for m in case.maneuvers]
                    + [{"name": f"SK-{k + 1}", "epoch": e, "kind": "station-keeping", "dv": None}
                       for k, e in enumerate(case.station_keeping_epochs())], key=lambda m: m["epoch"])
    components = [nominal.components[0], SolarRadiationPressure(surfaces=surfaces), EmpiricalRTN(batches)] + extra
    executed = []

    def flown():
        burns = [c for e, dv in executed for c in [ImpulsiveManeuver(e, dv)] + plume(un, e, dv)]
        return replace(nominal, components=components + burns)

    for m in events:
        t = float(utc_to_tdb(m["epoch"]))
        if m["dv"] is None:
            state = propagate(x0, t0, t, flown(), with_stm=False).state(t)[0]
            if sk.nav_sigma_m is not None or sk.nav_sigma_m_s is not None:
                state = state + np.concatenate([(sk.nav_sigma_m or 0.0) * rng.standard_normal(3),
                                                (sk.nav_sigma_m_s or 0.0) * rng.standard_normal(3)])
            m["dv"] = design_dv(nominal, state, t, gaps, horizon, sk.max_dv_m_s)
        executed.append((t, executed_dv(m["dv"], ex.sigma_magnitude, np.radians(ex.sigma_pointing_deg), rng)[0]))
    fm = flown()
    traj = propagate(x0, t0, t1, fm, with_stm=False)
    return Truth(traj, fm, events, np.array([m["dv"] for m in events]).reshape(-1, 3),
                 np.array([dv for _, dv in executed]).reshape(-1, 3), np.array([e for e, _ in executed]), batches)
