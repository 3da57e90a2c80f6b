"""DRO-LEO autonomous navigation by dual one-way ranging, DOWR (seed 003, Li et al. 2023, Table 13).

Truth (Table 4): Earth-centred ICRF, from 2023-01-01 for 40 days; the DRO state of Table 3 and
a circular sun-synchronous LEO (a = 6878.137 km, i = 97.4065 deg, RAAN = 10.3886 deg, u = 0);
Sun and Moon point masses (DE440; the paper: DE405), Earth field to degree 70 on the LEO
(GGM02C; the paper: GGM01C), lunar field to degree 20 on the DRO (LP165P; the paper: GL0120B),
cannonball SRP (Cr 1.3) on both, Harris-Priester drag (Cd 2.5) on the LEO, A/m = 0.002 m^2/kg.
Earth degrees on the DRO and the lunar field on the LEO are cut where they fall below 1e-15 m/s^2;
the variational equations take the field gradients to degree 8 (the filter's STM only).

Clocks (sec. 3.1): the DRO clock is the polynomial a0 + a1 dt + a2/2 dt^2 (Table 2 bounds:
a1 = 5e-9, a2 = 5e-12/day) plus white frequency noise sigma_y(1 s) = 3e-11 (a phase random
walk, which reproduces every Allan deviation of Table 2); the LEO's GNSS-disciplined time
error is a Gauss-Markov process of sigma 20 ns (the paper's 1 sigma) whose correlation time
the paper does not give. Each satellite's pseudorange (eq. 2) gets 0.5-m white thermal noise
and the equipment delay; the sum combination (eq. 3) keeps the geometry and the delay
D_com/2, the difference (eq. 5) the clock offset relative to the LEO (eq. 9, D_sub = 0 here).
Data: 1 h of pseudoranges every 12 h (DOWR or one-way ranging; Simu. 9: one-way every 12 h and DOWR
every 24 h, or 120 h as the paper says, in study_dro_leo_dowr_alternation.toml), one per ``sample_s``,
the link through the Earth removed (Fig. 2).

Filter: odpipe's iterated filter-smoother (:func:`odpipe.estimation.fit.fit`) over
:class:`DowrProblem`; estimated: both states, the DRO clock (c a0 as a random walk with the
truth's white-FM level, c a1, c a2), Cd of the LEO and the DRO's SRP scale (Cr/1.3) for the
reduced models, the delay D_com/2, and white RTN accelerations per ``batch_s`` whose variance
rate equals the paper's process noise per 60-s step (Tables 9, 11, 12). Accuracy = filtered -
truth, 3-D RMS over the last 8 days (Table 13); convergence = the time after which all three
position components stay below 100 m.
"""

from __future__ import annotations

import json
from dataclasses import replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.signal import lfilter

from odpipe.constants import SECONDS_PER_DAY
from odpipe.analysis.montecarlo import parallel_map
from odpipe.dynamics.forces import (AtmosphericDrag, ForceModel, PointMasses, SolarRadiationPressure,
                                    SphericalHarmonics)
from odpipe.dynamics.propagator import propagate
from odpipe.environment.gravity import read_gravity
from odpipe.estimation.fit import FitOptions, Observations, build_grid, fit
from odpipe.estimation.registry import GaussMarkov, ParameterRegistry
from odpipe.measurements import MeasurementSetup, compute
from odpipe.constants import C_LIGHT
from odpipe.measurements.crosslink import ClockModel
from odpipe.od.problem import TrackingProblem
from odpipe.time import utc_to_tdb
from parsers.table import build

from .halo_geo_doppler import link_clear
from .study_report import plot_convergence, spread, write_markdown, write_table

DAY = SECONDS_PER_DAY
NAMES = ("DRO", "LEO")
ONE_WAY = "sst_1way"     # pseudorange received by spacecraft_2 (LEO) from spacecraft (DRO)
# each row observable as a combination of compute()'s: R_LEO = (sum) - (difference)
TERMS = {"dowr_sum": (("dowr_sum", 1.0),), "dowr_diff": (("dowr_diff", 1.0),),
         ONE_WAY: (("dowr_sum", 1.0), ("dowr_diff", -1.0))}
CLOCK_KEYS = ("a0", "a1", "a2")
DIFFERENCES = """\
- Integrator: the truth integrates with adaptive DOP853 (rtol 1e-12). The filter does too, except in
  the integrator studies: RK4 with 60-s steps (Simu. 1) and fixed DOP853 steps of 30 s, 5 min and
  10 min (8th order without error control) for the paper's fixed-step RKF78 (Simu. 3-5). The other
  60-s RKF78 runs (Simu. 2, 6-9) integrate adaptively. Over one day of the LEO (Earth 50x50), against
  a tighter integration: adaptive 4 cm, 60-s fixed steps 1 mm, 5 min 77 m, 10 min 5.6 km, RK4 at 60 s
  2.0 km (benchmarks/bench_integrators.py).
- Filter: an iterated square-root information filter-smoother relinearized about the smoothed
  solution on growing arcs (``stage_days``), not one EKF pass. The filtered accuracy once converged is
  comparable; the early transients of an EKF started 1 km off (the paper's divergence to 3 km and 30 km
  in Simu. 8, Fig. 19) are absent, so convergence times where observability is poor come out shorter.
- Process noise: the paper's sigma per integration step (60 s, or the study's step) becomes white RTN
  accelerations held over ``batch_s`` with the same velocity-variance rate, so Simu. 4's 1e-8 m/s^2
  per 5-min step gives the DRO 22x Simu. 2's; the DRO clock offset gets a random walk of the truth's
  level (the paper holds its clock parameters constant in the time update).
- Simu. 9: the paper gives one-way ranging 1 h every 12 h and DOWR 1 h every 120 h (sec. 2.2 (3)), not where
  the DOWR pass falls in the 120-h cycle nor whether it takes a one-way pass's place. study_dro_leo_dowr.toml
  has DOWR on every other 12-h pass (24 h, 5x the paper's DOWR rate); study_dro_leo_dowr_alternation.toml
  runs 120 h at six phases (``first_h``) and reports the spread (``variant_of``).
- Models: DE440 (paper DE405), GGM02C (GGM01C) and LP165P (GL0120B); what matters is the truth-minus-
  filter truncation (70 -> 50 and 20 -> 15 in Model-B), which is kept.
- Not given in the paper, chosen here: the LEO time error's correlation time, the clock a0, the delay,
  the sample interval, the mass (only A/m matters) and the initial errors (drawn from the a priori
  sigmas with ``seed``, the same draws for every simulation); the Earth's shadowing of the link is
  removed, the Moon's is not modelled.
- Clock accuracy is the RMS of the filtered DRO clock offset minus the truth (polynomial + random walk)
  over the whole last 8 days, gaps included.
"""


def circular_state(gm: float, a: float, inc: float, raan: float, u: float) -> np.ndarray:
    """ICRF state (m, m/s) of a circular orbit: radius a (m), inclination, RAAN, argument of latitude (rad)."""
    p = np.array([np.cos(raan) * np.cos(u) - np.sin(raan) * np.sin(u) * np.cos(inc),
                  np.sin(raan) * np.cos(u) + np.cos(raan) * np.sin(u) * np.cos(inc), np.sin(u) * np.sin(inc)])
    q = np.array([-np.cos(raan) * np.sin(u) - np.sin(raan) * np.cos(u) * np.cos(inc),
                  -np.sin(raan) * np.sin(u) + np.cos(raan) * np.cos(u) * np.cos(inc), np.cos(u) * np.sin(inc)])
    return np.concatenate([a * p, np.sqrt(gm / a) * q])


def force_models(cfg, eph, model: dict, scale: dict | None = None) -> dict:
    """Force models by spacecraft (Earth-centred) for a [model.X] table; ``scale``: Cd and SRP scale of the run."""
    sc_cfg, scale = cfg["spacecraft"], scale or {}
    earth, moon = read_gravity(Path(cfg["earth_gravity"])), read_gravity(Path(cfg["moon_gravity"]))
    out = {}
    for sc in NAMES:
        comps = [PointMasses(["sun"] + ([] if model["moon_degree"].get(sc, 0) else ["moon"]))]
        for body, field, deg in (("earth", earth, model["earth_degree"][sc]),
                                 ("moon", moon, model["moon_degree"].get(sc, 0))):
            if deg:
                comps.append(SphericalHarmonics(body, field.truncated(deg), deg, partial_degree=min(deg, 8)))
        comps.append(SolarRadiationPressure(cr_area=sc_cfg["cr"] * sc_cfg["area_m2"],
                                            scale=scale.get(f"{sc}.srp_scale", 1.0)))
        if sc == "LEO":
            comps.append(AtmosphericDrag(scale.get("LEO.cd", sc_cfg["cd"]), sc_cfg["area_m2"], sc_cfg["n_bulge"]))
        out[sc] = ForceModel("earth", comps, mass=sc_cfg["mass_kg"], ephemeris=eph)
    return out


class DowrProblem(TrackingProblem):
    """:class:`TrackingProblem` with what DOWR needs and it lacks: rows 'dowr_sum', 'dowr_diff' and
    ONE_WAY (evaluated as combinations of compute()'s rows, :data:`TERMS`); the clock polynomial of
    ``clock_sc`` as registry kind 'clock' (owner '<sc>.clock', info clock='a0'|'a1'|'a2', values
    c*a in m, m/s, m/s^2, epoch ``clock_ref``); the LEO drag coefficient 'cd' as a reference
    parameter; biases (m) on the rows whose observable is in ``info['observables']``."""

    def __init__(self, *args, clock_sc: str, clock_ref: float, **kw):
        self.clock_sc, self.clock_ref = clock_sc, clock_ref
        super().__init__(*args, **kw)
        params = self.registry.parameters
        self._clock = {p.info["clock"]: i for i, p in enumerate(params) if p.kind == "clock"}

    def _segment_model(self, sc, x0, a, b):
        fm, names, idx = super()._segment_model(sc, x0, a, b)
        cd = [i for i, name in self._sc[sc]["dynamic"] if name == "cd"]
        if cd:
            fm = replace(fm, components=[replace(c, cd=x0[cd[0]]) if isinstance(c, AtmosphericDrag) else c
                                         for c in fm.components])
        return fm, names, idx

    def _measurement_setup(self, x0):
        setup = super()._measurement_setup(x0)
        a = [x0[self._clock[k]] / C_LIGHT if k in self._clock else 0.0 for k in CLOCK_KEYS]
        return replace(setup, clocks={**setup.clocks, self.clock_sc: ClockModel(*a, t_ref=self.clock_ref)})

    def _evaluate(self, lo, hi, trajs, x0):
        n, m = len(self.registry), hi - lo
        rows = self.rows.iloc[lo:hi]
        if m == 0:
            return super()._evaluate(lo, hi, trajs, x0)
        terms = [(k, obs, w) for k, o in enumerate(rows["observable"]) for obs, w in TERMS[o]]
        k_idx, obs, w = (list(v) for v in zip(*terms))
        expanded = rows.iloc[k_idx].reset_index(drop=True)
        expanded["observable"] = obs
        ev = compute(expanded, trajs, self._measurement_setup(x0))
        W = np.zeros((m, len(terms)))
        W[k_idx, np.arange(len(terms))] = w
        status = np.full(m, "", object)
        for j, s in zip(k_idx, ev.status):
            status[j] = status[j] or s
        G_x = {sc: W @ ev.partials.get(f"state:{sc}", np.zeros((len(terms), 6))) for sc in trajs}
        G_p = {sc: W @ ev.partials.get(f"dynamic:{sc}", np.zeros((len(terms), len(trajs[sc].param_names))))
               for sc in trajs}
        H_lin = np.zeros((m, n))
        clock = W @ ev.partials.get(f"clock:{self.clock_sc}", np.zeros((len(terms), 3)))
        for i, p in enumerate(self.registry.parameters):
            if p.kind == "bias":
                H_lin[rows["observable"].isin(p.info["observables"]).to_numpy(), i] = 1.0
            elif p.kind == "clock":
                H_lin[:, i] = clock[:, CLOCK_KEYS.index(p.info["clock"])]
        return W @ ev.value, np.ones(m), status, G_x, G_p, H_lin


# -- simulation ---------------------------------------------------------------------------------
def pass_epochs(cfg, every_h: float, first_h: float = 0.0) -> np.ndarray:
    """UTC reception epochs: ``pass_s`` of samples every ``sample_s`` at the start of every ``every_h`` hours
    from ``first_h`` past the epoch."""
    start = np.datetime64(cfg["epoch_utc"], "ns")
    sample = np.arange(cfg["sample_s"], cfg["pass_s"] + 1e-9, cfg["sample_s"])
    starts = np.arange(first_h * 3600.0, cfg["arc_days"] * DAY - cfg["pass_s"], every_h * 3600.0)
    sec = (starts[:, None] + sample[None, :]).ravel()
    return start + (sec * 1e9).astype("timedelta64[ns]")


def _rows(epochs, observables) -> pd.DataFrame:
    n = len(epochs)
    return build(n, epoch=epochs, observable=np.asarray(observables, object), unit="m", station_tx="",
                 station_rx="", spacecraft="DRO", spacecraft_2=np.array(["LEO"] * n, dtype=object),
                 tag="receive", count_time=0.0, band_up="", band_down="", uplink_hz=np.nan, ramped=False,
                 transponder_ratio=np.nan, value=0.0, sigma=np.nan, pass_id=0, flags=0, source="simulated",
                 record=np.arange(n))


class ClockTruth:
    """Truth clocks on a lattice (TDB s): DRO polynomial + phase random walk, LEO Gauss-Markov error (s)."""

    def __init__(self, c: dict, t0: float, t1: float, rng):
        self.poly = ClockModel(c["a0_s"], c["a1"], c["a2_per_day"] / DAY, t0)
        self.t = np.arange(t0 - 60.0, t1 + 60.0, c["lattice_s"])
        dt = c["lattice_s"]
        self.walk = np.cumsum(rng.normal(size=self.t.size)) * c["sigma_y_1s"] * np.sqrt(dt)
        phi = np.exp(-dt / c["leo_tau_s"])
        w = rng.normal(size=self.t.size) * c["leo_sigma_s"] * np.sqrt(1 - phi**2)
        w[0] = rng.normal() * c["leo_sigma_s"]
        self.leo = lfilter([1.0], [1.0, -phi], w)

    def dro_walk(self, t):
        """Stochastic part (s) of the DRO clock offset at TDB t."""
        return np.interp(t, self.t, self.walk)

    def dro(self, t):
        """DRO clock offset (s) at TDB t."""
        return self.poly.offset(t) + self.dro_walk(t)

    def leo_error(self, t):
        return np.interp(t, self.t, self.leo)


def simulate(cfg, meas, truth, clocks: ClockTruth, plan: list[dict], rng) -> tuple[pd.DataFrame, np.ndarray]:
    """Observed rows (value, sigma) in time order and their TDB times for a measurement plan."""
    c = cfg["clock"]
    by_epoch: dict = {}
    for item in plan:                       # DOWR passes replace one-way passes at the same epochs
        for e in pass_epochs(cfg, item["every_h"], item.get("first_h", 0.0)):
            if by_epoch.get(e) != "dowr":
                by_epoch[e] = item["type"]
    epochs = np.array(sorted(by_epoch), dtype="datetime64[ns]")
    kinds = np.array([by_epoch[e] for e in epochs])
    t = np.asarray(utc_to_tdb(epochs), float)
    clear = link_clear(truth["DRO"].state(t)[:, :3], truth["LEO"].state(t)[:, :3])
    epochs, kinds, t = epochs[clear], kinds[clear], t[clear]
    n = t.size
    both = _rows(np.concatenate([epochs, epochs]), ["dowr_sum"] * n + ["dowr_diff"] * n)
    setup = replace(meas, clocks={"DRO": clocks.poly})
    ev = compute(both, truth, setup)
    if (ev.status != "").any():
        raise RuntimeError(f"rows the models cannot compute: {set(ev.status[ev.status != ''])}")
    total, diff = ev.value[:n], ev.value[n:]
    tau = total / C_LIGHT                                    # light time, s (clock terms ~1e-6 relative)
    # pseudoranges received by the DRO (R_DL) and the LEO (R_LD): stochastic clocks, delay, thermal noise
    r_dl = (total + diff + C_LIGHT * (clocks.dro_walk(t) - clocks.leo_error(t - tau)) + c["delay_m"]
            + rng.normal(size=n) * c["thermal_m"])
    r_ld = (total - diff + C_LIGHT * (clocks.leo_error(t) - clocks.dro_walk(t - tau)) + c["delay_m"]
            + rng.normal(size=n) * c["thermal_m"])
    sig_sum = c["thermal_m"] / np.sqrt(2.0)
    sig_leo = C_LIGHT * c["leo_sigma_s"]
    dowr = kinds == "dowr"
    parts = [(t[dowr], epochs[dowr], "dowr_sum", 0.5 * (r_dl + r_ld)[dowr], sig_sum),
             (t[dowr], epochs[dowr], "dowr_diff", 0.5 * (r_dl - r_ld)[dowr], np.hypot(sig_sum, sig_leo)),
             (t[~dowr], epochs[~dowr], ONE_WAY, r_ld[~dowr], np.hypot(c["thermal_m"], sig_leo))]
    times = np.concatenate([p[0] for p in parts])
    order = np.argsort(times, kind="stable")
    rows = _rows(np.concatenate([p[1] for p in parts])[order],
                 np.concatenate([[p[2]] * p[0].size for p in parts])[order])
    rows["value"] = np.concatenate([p[3] for p in parts])[order]
    rows["sigma"] = np.concatenate([np.full(p[0].size, p[4]) for p in parts])[order]
    return rows, times[order]


# -- estimation ---------------------------------------------------------------------------------
def registry(cfg, sim, x0: dict, dyn_truth: dict, rng) -> ParameterRegistry:
    """A priori: truth + draws of the a priori sigmas (states, clock, delay, Cd and Cr when estimated)."""
    ap, c, B = cfg["apriori"], cfg["clock"], cfg["batch_s"]
    model = cfg["model"][sim["model"]]
    reg = ParameterRegistry()
    for sc in NAMES:
        sig = np.array([ap["pos_m"]] * 3 + [ap["vel_mps"]] * 3)
        reg.add_state(sc, x0[sc] + rng.normal(size=6) * sig, ap["pos_m"], ap["vel_mps"])
    step = sim.get("step_s", cfg["paper_step_s"])
    for sc in NAMES:   # paper's q per integration step -> same velocity variance rate over batch_s
        q = np.asarray(sim["snc_mps2"][sc], float)          # one value, or R/T/N
        reg.add_stochastic_acceleration(sc, q * np.sqrt(step / B), 0.0, B)
    truth_c = (c["a0_s"], c["a1"], c["a2_per_day"] / DAY)
    sig_c = (ap["a0_s"], ap["a1"], ap["a2_per_day"] / DAY)
    walk = GaussMarkov(np.inf, C_LIGHT * c["sigma_y_1s"] * np.sqrt(B), B)
    for k, tv, s in zip(CLOCK_KEYS, truth_c, sig_c):
        reg.add(f"DRO.clock.{k}", "clock", C_LIGHT * (tv + rng.normal() * s), C_LIGHT * s, owner="DRO.clock",
                process=walk if k == "a0" else None, clock=k)
    reg.add("delay", "bias", c["delay_m"] + rng.normal() * ap["delay_m"], ap["delay_m"],
            observables=("dowr_sum", ONE_WAY))
    if model["estimate_dynamic"]:
        cr_sig = ap["cr"] / cfg["spacecraft"]["cr"]
        reg.add("DRO.srp_scale", "dynamic", dyn_truth["DRO.srp_scale"] + rng.normal() * cr_sig, cr_sig,
                owner="DRO", model="srp_scale")
        reg.add("LEO.cd", "dynamic", dyn_truth["LEO.cd"] + rng.normal() * ap["cd"], ap["cd"], owner="LEO", model="cd")
    return reg


def filter_integrator(sim) -> dict:
    """:func:`propagate` settings of a simulation's filter: adaptive DOP853 unless ``integrator``
    ('RK4', or 'RKF78', for which fixed DOP853 steps stand in) and ``step_s`` fix the steps."""
    kind = sim.get("integrator")
    if kind is None:
        return {}
    if kind not in ("RK4", "RKF78"):
        raise ValueError(f"{sim['name']}: integrator must be 'RK4' or 'RKF78', not {kind!r}")
    return ({"method": "rk4", "max_step": sim["step_s"]} if kind == "RK4"
            else {"rtol": np.inf, "max_step": sim["step_s"]})


def estimate(cfg, sim, meas, rows, times, reg, t0, t1, log):
    """Staged fit (growing arcs, each relinearizing the next; ``max_iter`` iterations at most on each,
    ``final_iter`` on the whole arc; a simulation may set its own): the Solution of the whole arc."""
    stage_days, max_iter, final_iter = (sim.get(k, cfg[k]) for k in ("stage_days", "max_iter", "final_iter"))
    model = cfg["model"][sim["model"]]
    fm = force_models(cfg, meas.ephemeris, model)
    obs_all = Observations(times, rows["value"].to_numpy(float), rows["sigma"].to_numpy(float),
                           np.zeros(times.size, int))
    x_ref = None
    for days in list(stage_days) + [None]:
        end = t1 if days is None else min(t1, t0 + days * DAY)
        sel = times <= end
        opts = FitOptions(max_iter=final_iter if days is None else max_iter, block=cfg["block_s"])
        grid, _ = build_grid(reg, t0, end, opts.block)
        prob = DowrProblem(reg, rows[sel].reset_index(drop=True), times[sel], fm, meas, t0, end,
                           lookback=cfg["lookback_s"], epochs=grid, clock_sc="DRO", clock_ref=t0,
                           integrator={sc: filter_integrator(sim) for sc in NAMES})
        obs = Observations(*(a[sel] for a in (obs_all.time, obs_all.value, obs_all.sigma, obs_all.group)))
        sol = fit(prob, obs, t0, end, opts, x_ref=x_ref)
        x_ref = sol.smoothed_x[0]
        h = sol.history[-1]
        log(f"  {sim['name']}: arc to {(end - t0) / DAY:.1f} d, {len(sol.history)} iterations, post-fit RMS "
            f"{h['postfit_rms']:.2f} (whitened), {h['edited']} edited, converged {sol.converged}")
    return sol


def accuracy(cfg, sol, reg, truth, clocks, t0, t1) -> dict:
    """Filtered - truth: 3-D RMS over the last ``last_days``, convergence time, error series."""
    grid = sol.grid
    last = grid >= t1 - cfg["last_days"] * DAY
    out = {"t_days": (grid - t0) / DAY}
    for sc in NAMES:
        st = reg.slice("state", sc)
        err = sol.filtered_x[:, st] - truth[sc].state(grid)
        sig = np.sqrt(np.diagonal(sol.filtered_P, axis1=1, axis2=2)[:, st])
        big = np.nonzero(np.max(np.abs(err[:, :3]), axis=1) >= cfg["converged_m"])[0]
        conv = 0.0 if big.size == 0 else None if big[-1] == grid.size - 1 else (grid[big[-1] + 1] - t0) / DAY
        out[sc] = {"pos": float(np.sqrt(np.mean(np.sum(err[last, :3] ** 2, axis=1)))),
                   "vel": float(np.sqrt(np.mean(np.sum(err[last, 3:] ** 2, axis=1)))),
                   "converge_days": conv, "err": np.linalg.norm(err[:, :3], axis=1),
                   "sigma3": 3 * np.linalg.norm(sig[:, :3], axis=1)}
    ck = [reg.index(f"DRO.clock.{k}") for k in CLOCK_KEYS]
    dt = grid - t0
    est = (sol.filtered_x[:, ck[0]] + sol.filtered_x[:, ck[1]] * dt + 0.5 * sol.filtered_x[:, ck[2]] * dt**2) / C_LIGHT
    cerr = est - clocks.dro(grid)
    out["clock_ns"] = float(np.sqrt(np.mean(cerr[last] ** 2)) * 1e9)
    out["clock_err_ns"] = np.abs(cerr) * 1e9
    out["clock_sigma3_ns"] = 3e9 * np.sqrt(sol.filtered_P[:, ck[0], ck[0]]) / C_LIGHT
    named = {p.name: i for i, p in enumerate(reg.parameters)}
    out["dynamic"] = {k: float(sol.filtered_x[-1, named[k]]) for k in ("DRO.srp_scale", "LEO.cd") if k in named}
    out["delay_m"] = float(sol.filtered_x[-1, named["delay"]])
    return out


def _truth(cfg) -> tuple:
    """(measurement setup, t0, t1, initial states, truth trajectories) of the scenario."""
    meas = MeasurementSetup.default()
    t0 = float(utc_to_tdb(np.datetime64(cfg["epoch_utc"], "ns")))
    t1 = t0 + cfg["arc_days"] * DAY
    eph = meas.ephemeris
    le = cfg["leo_elements"]
    x0 = {"DRO": np.asarray(cfg["dro_state_km"], float) * 1e3,
          "LEO": circular_state(eph.gm("earth"), le["a_km"] * 1e3, *np.radians([le["inc_deg"], le["raan_deg"],
                                                                                 le["u_deg"]]))}
    truth_fm = force_models(cfg, eph, cfg["model"]["truth"])
    truth = {sc: propagate(x0[sc], t0, t1 + 60.0, truth_fm[sc], with_stm=False) for sc in NAMES}
    return meas, t0, t1, x0, truth


@lru_cache(maxsize=1)
def _truth_of(setup_json: str) -> tuple:
    """:func:`_truth` once per process and set-up (the configuration without its simulations, as JSON)."""
    return _truth(json.loads(setup_json))


def simulation(cfg: dict, sim: dict, log=print) -> dict:
    """One simulation of Table 13: data, fit and accuracy (the truth is made once per process)."""
    meas, t0, t1, x0, truth = _truth_of(json.dumps({k: v for k, v in cfg.items() if k != "simulation"},
                                                   sort_keys=True))
    rng = np.random.default_rng(cfg["seed"])        # the same truth noise and a priori draws for every run
    clocks = ClockTruth(cfg["clock"], t0, t1, rng)
    rows, times = simulate(cfg, meas, truth, clocks, sim["plan"], rng)
    reg = registry(cfg, sim, x0, {"DRO.srp_scale": 1.0, "LEO.cd": cfg["spacecraft"]["cd"]}, rng)
    sol = estimate(cfg, sim, meas, rows, times, reg, t0, t1, log)
    acc = accuracy(cfg, sol, reg, truth, clocks, t0, t1)
    log(f"{sim['name']}: DRO {acc['DRO']['pos']:.2f} m, LEO {acc['LEO']['pos']:.2f} m, clock "
        f"{acc['clock_ns']:.2f} ns, converged after DRO {acc['DRO']['converge_days']} d, "
        f"LEO {acc['LEO']['converge_days']} d; {acc['dynamic']}, delay {acc['delay_m']:.3f} m")
    return acc


def _quiet(*_):
    pass


def variant_spread(sims: list[dict], results: dict) -> pd.DataFrame:
    """Per simulation that others are ``variant_of`` (a choice the paper leaves open, e.g. where the DOWR
    passes fall): each Table 13 figure over the variants, odpipe's min / median / max beside the paper's and the
    spread of odpipe/paper."""
    groups: dict[str, list[dict]] = {}
    for sim in sims:
        if sim.get("variant_of"):
            groups.setdefault(sim["variant_of"], []).append(sim)
    rows = []
    for name, members in groups.items():
        paper = members[0]["paper"]
        for figure, ref, get in (("DRO pos [m]", paper["DRO"]["pos_m"], lambda a: a["DRO"]["pos"]),
                                 ("LEO pos [m]", paper["LEO"]["pos_m"], lambda a: a["LEO"]["pos"]),
                                 ("clock [ns]", paper["clock_ns"], lambda a: a["clock_ns"])):
            got = np.array([get(results[m["name"]]) for m in members])
            rows.append({"simulation": name, "variants": len(members), "figure": figure, "paper": ref,
                         "odpipe min": got.min(), "odpipe median": float(np.median(got)), "odpipe max": got.max(),
                         **spread(got / ref)})
    return pd.DataFrame(rows)


def run(cfg: dict, out, log=print) -> dict:
    """Every ``[[simulation]]`` (on a local Dask cluster with ``parallel = true``, the CLI's
    ``--parallel``), then the Table 13 report."""
    sims = cfg["simulation"]
    parallel = bool(cfg.get("montecarlo", {}).get("parallel", False))
    if parallel:
        log(f"{len(sims)} simulations on a local Dask cluster")
    accs = parallel_map(simulation, [cfg] * len(sims), sims, [_quiet if parallel else log] * len(sims),
                        parallel=parallel)
    rows_tab, panels, clock_panels = [], [], []
    results = {}
    for sim, acc in zip(sims, accs):
        results[sim["name"]] = acc
        paper = sim["paper"]
        for sc in NAMES:
            p = paper[sc]
            conv = acc[sc]["converge_days"]
            rows_tab.append({"simulation": sim["name"], "mode": sim["mode"], "model": sim["model"],
                             "integrator": f"{sim.get('integrator', 'adaptive')} {sim.get('step_s', '')}".strip(),
                             "satellite": sc,
                             "paper pos [m]": p["pos_m"], "odpipe pos [m]": acc[sc]["pos"],
                             "pos odpipe/paper": acc[sc]["pos"] / p["pos_m"],
                             "paper vel [m/s]": p["vel_mps"], "odpipe vel [m/s]": acc[sc]["vel"],
                             "paper clock [ns]": paper["clock_ns"] if sc == "DRO" else np.nan,
                             "odpipe clock [ns]": acc["clock_ns"] if sc == "DRO" else np.nan,
                             "paper conv. [d]": p.get("converge_days", "-"),
                             "odpipe conv. [d]": "-" if conv is None else round(conv, 2)})
            panels.append({"title": f"{sim['name']} ({sim['mode']}, model {sim['model']}) {sc} position (m)",
                           "t_days": acc["t_days"],
                           "curves": [("|filtered - truth|", acc[sc]["err"], {"color": "k", "lw": 0.8}),
                                      ("3-D 3-sigma", acc[sc]["sigma3"], {"color": "r", "ls": ":"})]})
        clock_panels.append({"title": f"{sim['name']} DRO clock offset (ns)", "t_days": acc["t_days"],
                             "curves": [("|filtered - truth|", acc["clock_err_ns"], {"color": "k", "lw": 0.8}),
                                        ("3-sigma", acc["clock_sigma3_ns"], {"color": "r", "ls": ":"})]})
    table = pd.DataFrame(rows_tab)
    plot_convergence(out, "position", panels, "m")
    plot_convergence(out, "clock", clock_panels, "ns", ncols=3)
    c = cfg["clock"]
    notes = (f"- truth clock: a0 {c['a0_s']} s, a1 {c['a1']}, a2 {c['a2_per_day']}/day, white FM "
             f"sigma_y(1 s) {c['sigma_y_1s']}; LEO time error Gauss-Markov {c['leo_sigma_s'] * 1e9:.0f} ns, "
             f"tau {c['leo_tau_s']} s; thermal noise {c['thermal_m']} m per pseudorange; delay D_com/2 "
             f"{c['delay_m']} m\n"
             f"- process noise: the paper's sigma per integration step ({cfg['paper_step_s']} s, or the "
             f"simulation's step_s) held over {cfg['batch_s']} s batches with the same velocity variance rate\n"
             + "\n".join(f"- {name}: final " + "".join(f"{k} {v:.4f}, " for k, v in r["dynamic"].items())
                         + f"delay {r['delay_m']:.3f} m (truth: LEO.cd {cfg['spacecraft']['cd']}, DRO.srp_scale 1, "
                         f"delay {c['delay_m']} m)" for name, r in results.items())
             + "\n- one-way ranging alone cannot tell the delay from the DRO clock offset (both enter every "
               "row alike): their split rests on the a priori")
    variants = variant_spread(sims, results)
    spread_section = ([("Choices the paper leaves open: spread over the variants (min / median / max)",
                        write_table(out, "variant_spread", variants))] if len(variants) else [])
    write_markdown(out, "Study dro_leo_dowr: DRO-LEO dual one-way ranging (Li et al., Table 13)",
                   [("Table 13: 3-D RMS over the last 8 days, paper vs odpipe",
                     write_table(out, "table13", table) + "\n![position](position.png)\n\n![clock](clock.png)\n"),
                    *spread_section, ("Set-up", notes + "\n"), ("Differences from the paper's set-up", DIFFERENCES)])
    return {"table": table, "results": results, "variant_spread": variants}
