"""Propagation benchmarks: wall time, steps and force evaluations per second.

(a) the peers' case (/work/shared/peers/bench/common.py): 14-day cislunar HEO from
    2003-06-01, Earth 8x8 (EGM96), Sun and Moon point masses, cannonball SRP with
    Earth+Moon shadow; max step 45 min and 1 d, with and without the 6x6 STM.
(b) 14-day Earth-Moon L2 libration orbit: Earth 16x16 (EGM96), Moon 16x16
    (LP165P), Sun, Venus, Mars, Jupiter, Saturn, SRP, STM.
(c) 1 day of a 55-km lunar orbit: Moon 200x200 (LP lpe200) with partials to degree
    50, and to 8 as the GRAIL nightly asks; Earth and Sun point masses, STM.
(d) the same day flown as a GRAIL-B fit flies it (runs/grail_b_2012_04_10.toml): 24 one-hour segments,
    each integrated afresh with the STM and the sensitivities to the SRP scale and its hour's RTN
    acceleration; Moon 150x150 with partials to 8, Earth and Sun, cannonball SRP with Earth and Moon
    shadows, the exact references' tolerances (rtol 1e-11, atol 1e-5).
(e) the field kernel alone (``sh_acceleration``, lpe200) at degrees 50-200, without and with the gradient
    to degree 8, at 1,000 points 55 km up: CPU-us per evaluation and the rate of a degree-n field's
    3n^2 multiply-adds, beside the rate a compiled dot product (the floating-point limit of one core
    reading vectors that stay in cache) reaches on the same machine.

Run: .venv/bin/python benchmarks/bench_dynamics.py  (compile time is reported apart).
Each case reports wall and CPU time (the CPU time is the steadier figure on a shared machine).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
from numba import njit

from odpipe.dynamics.crtbp import EarthMoonUnits, propagate_crtbp
from odpipe.dynamics.forces import (EmpiricalRTN, ForceModel, PointMasses, SolarRadiationPressure,
                                    SphericalHarmonics)
from odpipe.dynamics.harmonics import field_table, sh_acceleration, workspace
from odpipe.dynamics.propagator import propagate
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.gravity import read_gravity
from odpipe.time import utc_to_tdb

DATA = Path(os.environ.get("ODPIPE_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
PEER_FINAL_KM = {  # final positions printed by the peers' runs (bench/results/*.json)
    "nyx 2.6.0 RK89": np.array([-335876.45645546576, 25752.521929658575, -156235.41356561327]),
    "Orekit 13.1.9 DP853": np.array([-335876.3442637621, 25752.24517815597, -156235.37508346396]),
}


def timed(fn, repeat=3):
    """Best (wall s, CPU s) of ``repeat`` calls, and the last result."""
    best = None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        dt = (time.perf_counter() - t, time.process_time() - c)
        best = dt if best is None else (min(best[0], dt[0]), min(best[1], dt[1]))
    return best, out


def report(label, seconds, traj):
    wall, cpu = seconds
    print(f"{label:42s} {wall:8.3f} s (cpu {cpu:7.3f} s)  steps {traj.n_steps:6d}  evals {traj.n_eval:7d}  "
          f"{traj.n_eval / cpu:8.0f} evals/cpu-s")


def case_peers(eph):
    t0 = float(utc_to_tdb(np.datetime64("2003-06-01T00:00:00"))[()])
    t1 = t0 + 14 * 86400.0
    x0 = np.array([6252.878075666748, -360.9143112901398, 2842.206999982947,
                   -0.559937727219993, 10.347539903919273, 2.5458376452827824]) * 1e3
    egm = read_gravity(DATA / "gravity/gmat/EGM96.cof")
    fm = ForceModel("earth", [SphericalHarmonics("earth", egm, 8), PointMasses(["moon", "sun"]),
                              SolarRadiationPressure(cr_area=1.3 * 5.0)], mass=500.0, ephemeris=eph)
    print("(a) peers' case: 14-day HEO, Earth 8x8, Sun+Moon, cannonball SRP, rtol 1e-12")
    for max_step, tag in ((2700.0, "45min"), (86400.0, "1d")):
        for stm in (False, True):
            sec, traj = timed(lambda: propagate(x0, t0, t1, fm, with_stm=stm, params=[] if stm else None,
                                                rtol=1e-12, atol=1e-6, max_step=max_step))
            report(f"  max step {tag}, {'6x6 STM' if stm else 'state only'}", sec, traj)
        final = traj.state(t1)[0][:3] / 1e3
        for peer, ref in PEER_FINAL_KM.items():
            print(f"    final position vs {peer}: {np.linalg.norm(final - ref) * 1e3:8.1f} m")


def case_libration(eph):
    t0 = float(utc_to_tdb(np.datetime64("2012-04-01T00:00:00"))[()])
    units = EarthMoonUnits(gm1=eph.gm("earth"), gm2=eph.gm("moon"))
    # L2 halo-type orbit of period 3.4154 (14.8 d), differentially corrected in the CRTBP with its STM
    halo = np.array([1.1808881, 0.0, -0.00327775, 0.0, -0.15591859, 0.0])
    # CRTBP rotating state -> ICRF Earth-centred state with the instantaneous Earth-Moon frame
    moon = eph.state("moon", "earth", np.array([t0]))[0]
    r_m, v_m = moon[:3], moon[3:]
    x_hat = r_m / np.linalg.norm(r_m)
    z_hat = np.cross(r_m, v_m) / np.linalg.norm(np.cross(r_m, v_m))
    rot = np.column_stack([x_hat, np.cross(z_hat, x_hat), z_hat])
    dist = np.linalg.norm(r_m)
    omega = np.linalg.norm(np.cross(r_m, v_m)) / dist**2
    r_rel = (halo[:3] + [units.mu, 0, 0]) * dist
    r_in = rot @ r_rel
    dist_rate = r_m @ v_m / dist  # pulsating frame: lengths scale with the Earth-Moon distance
    v_in = rot @ (halo[3:] * dist * omega) + np.cross(omega * z_hat, r_in) + dist_rate / dist * r_in
    x0 = np.r_[r_in, v_in]
    egm = read_gravity(DATA / "gravity/gmat/EGM96.cof")
    lp = read_gravity(DATA / "gravity/gmat/LP165P.cof")
    fm = ForceModel("earth", [SphericalHarmonics("earth", egm, 16), SphericalHarmonics("moon", lp, 16),
                              PointMasses(["moon", "sun", "venus", "mars", "jupiter", "saturn"]),
                              SolarRadiationPressure(cr_area=1.3 * 5.0)], mass=500.0, ephemeris=eph)
    print("(b) 14-day Earth-Moon L2 libration orbit, Earth 16x16, Moon 16x16, Sun+planets, SRP")
    for stm in (False, True):
        sec, traj = timed(lambda: propagate(x0, t0, t0 + 14 * 86400.0, fm, with_stm=stm,
                                            rtol=1e-12, atol=1e-6, max_step=2700.0))
        report(f"  {'6x6 STM + SRP-scale sensitivity' if stm else 'state only'}", sec, traj)
    crtbp = propagate_crtbp(halo, 0.0, 14 * 86400.0 / units.time, units.mu, with_stm=False)
    days = np.arange(0, 15, 1.0)
    t = t0 + days * 86400.0
    d_moon = np.linalg.norm(traj.state(t)[:, :3] - eph.position("moon", "earth", t), axis=1) / 1e3
    print(f"    CRTBP model of the same orbit: {crtbp.n_steps} steps. The ephemeris-model arc (no "
          f"ephemeris correction of the CRTBP seed) stays in the L2 region:")
    print("    distance from the Moon [1000 km] on days 0..14: " + " ".join(f"{d / 1e3:.0f}" for d in d_moon))


def low_lunar_orbit(utc: str):
    """(TDB s, the lpe200 field, a circular 55-km orbit inclined 89 deg at that epoch: m, m/s)."""
    lpe = read_gravity(DATA / "gravity/tudat/lpe200.txt")
    r = lpe.radius + 55e3
    v = np.sqrt(lpe.gm / r)
    inc = np.radians(89.0)
    return float(utc_to_tdb(np.datetime64(utc))[()]), lpe, np.array([r, 0.0, 0.0, 0.0, v * np.cos(inc),
                                                                     v * np.sin(inc)])


def case_low_lunar(eph):
    t0, lpe, x0 = low_lunar_orbit("2012-04-08T00:00:00")
    print("(c) 1 day, 55-km polar lunar orbit, Moon 200x200, Earth+Sun, STM")
    for partial in (50, 8):   # 8: the GRAIL nightly's partial_degree
        fm = ForceModel("moon", [SphericalHarmonics("moon", lpe, 200, partial_degree=partial),
                                 PointMasses(["earth", "sun"])], mass=300.0, ephemeris=eph)
        sec, traj = timed(lambda: propagate(x0, t0, t0 + 86400.0, fm, with_stm=True, rtol=1e-11, atol=1e-6),
                          repeat=1)
        report(f"  6x6 STM, field partials {partial}x{partial}", sec, traj)


def case_grail_segments(eph):
    t0, lpe, x = low_lunar_orbit("2012-04-10T04:00:00")
    base = [SphericalHarmonics("moon", lpe, 150, partial_degree=8), PointMasses(["earth", "sun"]),
            SolarRadiationPressure(cr_area=5.0)]
    params = ["srp_scale", "emp[0].R", "emp[0].T", "emp[0].N"]
    print("(d) 1 day at 55 km as 24 one-hour fit segments: Moon 150x150 (partials 8), Earth+Sun, SRP, "
          "an RTN batch each, STM + 4 sensitivities")

    def day():
        y, trajs = x, []
        for h in range(24):
            a = t0 + 3600.0 * h
            fm = ForceModel("moon", base + [EmpiricalRTN(np.array([[a - 1.0, a + 3601.0, 1e-8, -2e-8, 1e-8]]))],
                            mass=220.0, ephemeris=eph)
            trajs.append(propagate(y, a, a + 3600.0, fm, with_stm=True, params=params, rtol=1e-11, atol=1e-5))
            y = trajs[-1].state(a + 3600.0)[0]
        return trajs

    sec, trajs = timed(day, repeat=2)
    wall, cpu = sec
    n_eval = sum(t.n_eval for t in trajs)
    print(f"  {'24 segments':40s} {wall:8.3f} s (cpu {cpu:7.3f} s)  steps {sum(t.n_steps for t in trajs):6d}  "
          f"evals {n_eval:7d}  {cpu / n_eval * 1e6:8.1f} cpu-us/eval")


@njit(cache=False)
def _field_sweep(points, gm, radius, T, nmax, ngrad, work, acc, grad):
    """sh_acceleration at every row of ``points`` (m); the x components summed (keeps the work)."""
    total = 0.0
    for k in range(points.shape[0]):
        sh_acceleration(points[k], gm, radius, T, nmax, ngrad, work, acc, grad)
        total += acc[0]
    return total


@njit(cache=False, fastmath={"reassoc", "contract"})
def _dot_sweep(a, b, repeat):
    """``repeat`` dot products of a and b (multiply-adds: repeat * len(a))."""
    total = 0.0
    for _ in range(repeat):
        s = 0.0
        for i in range(a.shape[0]):
            s += a[i] * b[i]
        total += s
    return total


def case_field_kernel():
    lpe = read_gravity(DATA / "gravity/tudat/lpe200.txt")
    rng = np.random.default_rng(1)
    u = rng.normal(size=(1000, 3))
    points = u / np.linalg.norm(u, axis=1)[:, None] * (lpe.radius + 55e3)
    a, b = rng.normal(size=4096), rng.normal(size=4096)
    _dot_sweep(a, b, 1)
    (_, cpu), _ = timed(lambda: _dot_sweep(a, b, 100_000))
    limit = 100_000 * a.size / cpu
    print(f"(e) field kernel alone, 1,000 points 55 km up; a compiled dot product reaches {limit / 1e9:.1f} G "
          "multiply-adds/cpu-s here")
    acc, grad = np.zeros(3), np.zeros((3, 3))
    for nmax in (50, 100, 150, 200):
        for ngrad in (-1, 8):
            T, work = field_table(lpe.C, lpe.S, nmax, ngrad), workspace(nmax, ngrad)
            _field_sweep(points[:1], lpe.gm, lpe.radius, T, nmax, ngrad, work, acc, grad)
            (_, cpu), _ = timed(lambda: _field_sweep(points, lpe.gm, lpe.radius, T, nmax, ngrad, work, acc, grad))
            per = cpu / len(points)
            gradient = "none" if ngrad < 0 else f"to {ngrad}"
            print(f"  degree {nmax:3d}, gradient {gradient:5s} {per * 1e6:7.1f} cpu-us/eval  "
                  f"3n^2/t {3 * nmax**2 / per / 1e9:5.2f} G/s  ({3 * nmax**2 / per / limit:4.0%} of the dot product)")


def main():
    eph = Ephemeris.open("de440")
    t, c = time.perf_counter(), time.process_time()
    import odpipe.dynamics.rhs  # noqa: F401  (numba cache load or compile)
    fm = ForceModel("earth", central_gm=3.986e14)
    propagate(np.array([7e6, 0, 0, 0, 7.5e3, 0]), 0.0, 60.0, fm)
    propagate(np.array([7e6, 0, 0, 0, 7.5e3, 0]), 0.0, 60.0, fm, with_stm=False)
    print(f"numba load/compile: {time.perf_counter() - t:.1f} s (cpu {time.process_time() - c:.1f} s)")
    case_peers(eph)
    case_libration(eph)
    case_low_lunar(eph)
    case_grail_segments(eph)
    case_field_kernel()


if __name__ == "__main__":
    main()
