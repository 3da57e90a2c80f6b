"""The true trajectory of a simulated case: full force model, stochastic accelerations, executed maneuvers.

* stochastic accelerations: piecewise-constant RTN batches from a first-order
  Gauss-Markov sequence a[k+1] = m a[k] + sqrt(1 - m^2) sigma w[k],
  m = exp(-batch/tau) (white when tau = 0), seeded;
* maneuvers: the designed ICRF delta-v scaled by (1 + e_mag) and turned by a
  pointing error (angle ~ N(0, sigma) about a random axis normal to it);
* force model: Earth centre, Moon and Sun point masses (DE421), SRP on a spinning
  cylinder (axis fixed in ICRF) with Earth and Moon shadow, the batches, the maneuvers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from odpipe.dynamics import (Cylinder, EmpiricalRTN, ForceModel, ImpulsiveManeuver, PointMasses,
                             SolarRadiationPressure, propagate)
from odpipe.dynamics.trajectory import Trajectory
from odpipe.simulate.libration import lyapunov_orbit, rotating_to_icrf
from odpipe.time import utc_to_tdb

MARGIN_S = 3600.0  # trajectory starts this long before the first sample (light time, uplink legs)


@dataclass
class Truth:
    trajectory: Trajectory
    force_model: ForceModel
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
    """Geocentric ICRF state (m, m/s) at t0 from the case's CRTBP Lyapunov orbit."""
    mu = ephemeris.gm("moon") / (ephemeris.gm("moon") + ephemeris.gm("earth"))
    s, _ = lyapunov_orbit(mu, int(case.orbit["point"]), float(case.orbit["amplitude"]))
    return rotating_to_icrf(s, mu, ephemeris.state("moon", "earth", np.array([t0]))[0])


def simulate_truth(case, ephemeris, rng) -> Truth:
    """Propagate the case's truth from MARGIN_S before its start to its end (+ margin)."""
    t0 = float(utc_to_tdb(case.start)) - MARGIN_S
    t1 = float(utc_to_tdb(case.end)) + MARGIN_S
    sc = case.body
    st = case.stochastic
    batches = gauss_markov_batches(t0, t1, float(st["batch_s"]), float(st["sigma"]), float(st["tau_s"]), rng)
    designed = np.array([m["dv"] for m in case.maneuvers]).reshape(-1, 3)
    epochs = np.array([float(utc_to_tdb(m["epoch"])) for m in case.maneuvers])
    ex = case.execution
    executed = executed_dv(designed, float(ex["sigma_magnitude"]), np.radians(float(ex["sigma_pointing_deg"])), rng) \
        if len(designed) else designed
    axis = np.asarray(sc["spin_axis"], float)
    fm = ForceModel("earth", [
        PointMasses(["moon", "sun"]),
        SolarRadiationPressure(surfaces=[Cylinder(axis / np.linalg.norm(axis), float(sc["radius_m"]),
                                                  float(sc["length_m"]), float(sc["rho_s"]), float(sc["rho_d"]))]),
        EmpiricalRTN(batches),
        *[ImpulsiveManeuver(t, dv) for t, dv in zip(epochs, executed)],
    ], mass=float(sc["mass_kg"]), ephemeris=ephemeris)
    traj = propagate(initial_state(case, ephemeris, t0), t0, t1, fm, with_stm=False)
    return Truth(traj, fm, designed, executed, epochs, batches)
