"""From a run configuration to the dynamics and the arc-fit set-up."""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.dynamics import forces as F
from odpipe.dynamics.propagator import propagate
from odpipe.analysis.overlap import oem_trajectory
from odpipe.environment.atmosphere.space_weather import open_space_weather
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.gravity import read_gravity
from odpipe.environment.station_displacement import StationDisplacement, sites_by_station
from odpipe.environment.stations import StationCatalog
from odpipe.estimation.registry import GaussMarkov
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.frames.eme2000 import eme2000_to_gcrs
from odpipe.frames.local import rtn_matrix
from odpipe.measurements import MeasurementSetup
from odpipe.od.arc import COARSE_INTEGRATION, ArcSetup, ManeuverPlan, sigma_value
from odpipe.pipeline.config import RunConfig
from odpipe.operations.schema import ConfigError
from odpipe.time import utc_to_tdb
from parsers import blq
from parsers.maneuvers import read_plan


def tdb(utc_iso: str) -> float:
    """TDB s past J2000 of a UTC ISO string."""
    return float(utc_to_tdb(np.datetime64(utc_iso, "ns")))


def force_model(cfg: RunConfig) -> F.ForceModel:
    """The configured dynamics (without estimated maneuvers and stochastic accelerations)."""
    dyn = cfg.dynamics
    eph = Ephemeris.open(str(dyn.ephemeris))
    comps = []
    if dyn.third_bodies:
        comps.append(F.PointMasses(list(dyn.third_bodies)))
    for g in dyn.gravity:
        field = read_gravity(g.file, epoch=tdb(g.epoch or cfg.arc.start))
        comps.append(F.SphericalHarmonics(g.body, field, g.degree, g.partial_degree))
    if dyn.srp is not None:
        surfaces = []
        if dyn.srp.cylinder is not None:
            c = dyn.srp.cylinder
            axis = c.axis if isinstance(c.axis, str) else np.asarray(c.axis, float)
            surfaces.append(F.Cylinder(axis, c.radius, c.length, c.rho_s, c.rho_d))
        comps.append(F.SolarRadiationPressure(dyn.srp.cr_area, surfaces, tuple(dyn.srp.occulters)))
    if dyn.drag is not None:
        d = dyn.drag
        weather = open_space_weather(d.space_weather, d.solar_activity_level) if d.space_weather else None
        comps.append(F.AtmosphericDrag(d.cd, d.area, d.n_bulge, d.atmosphere, weather, d.ap_history))
    if dyn.polynomial_acceleration is not None:
        poly = dyn.polynomial_acceleration
        t_ref = tdb(poly.epoch or cfg.initial_state.epoch or cfg.arc.start)
        comps.append(F.InertialPolynomialAcceleration(t_ref, tuple(poly.c0), tuple(poly.c1)))
    if dyn.relativity:
        comps.append(F.Relativity())
    return F.ForceModel(dyn.center, comps, dyn.mass, eph)


def maneuver_plans(cfg: RunConfig, fm: F.ForceModel, state0: np.ndarray, t0: float) -> list[ManeuverPlan]:
    """Planned impulsive maneuvers in the arc, their ΔV turned to ICRF along the a priori trajectory."""
    path = cfg.estimation.maneuver_plan
    if path is None:
        return []
    plan = read_plan(path)
    t1 = tdb(cfg.arc.end)
    plans, applied = [], []
    for row in plan.sort_values("epoch").itertuples(index=False):
        if row.kind != "impulsive":
            raise ValueError(f"{path}: maneuver {row.name} is a finite burn; the arc fit estimates impulsive ones")
        t = tdb(str(np.datetime64(row.epoch, "ns")))
        if not t0 < t < t1:
            continue
        dv = np.array([row.dv1, row.dv2, row.dv3], float)
        if row.frame != "ICRF":
            model = F.ForceModel(fm.center, fm.components + applied, fm.mass, fm.ephemeris, fm.central_gm)
            x = propagate(state0, t0, t, model, with_stm=False).state(t)[0]
            rot = rtn_matrix(x[:3], x[3:]) if row.frame == "RTN" else _vnb_matrix(x)
            dv = rot.T @ dv
        applied.append(F.ImpulsiveManeuver(t, dv))
        sigma = row.sigma_dv if np.isfinite(row.sigma_dv) else 0.01
        # the epoch is estimated when the plan gives its sigma (sigma_time) or the config a default
        sigma_t = row.sigma_time if np.isfinite(row.sigma_time) else cfg.estimation.maneuver_epoch_sigma
        plans.append(ManeuverPlan(str(row.name), t, tuple(dv), float(sigma),
                                  None if sigma_t is None else float(sigma_t)))
    return plans


def _vnb_matrix(x):
    v = x[3:] / np.linalg.norm(x[3:])
    n = np.cross(x[:3], x[3:])
    n /= np.linalg.norm(n)
    return np.array([v, n, np.cross(v, n)])


def station_catalog(cfg: RunConfig) -> StationCatalog:
    """The default catalog plus the run's own station files, then the SINEX solution's sites."""
    catalog = StationCatalog.default()
    for path in cfg.data.stations:
        catalog = catalog.with_csv(path)
    sx = cfg.data.sinex
    if sx is not None:
        catalog = catalog.with_sinex(sx.file, sx.epoch or cfg.arc.start, eccentricities=sx.eccentricities)
    return catalog


def initial_state(cfg: RunConfig) -> tuple[float, np.ndarray]:
    """The configured a priori epoch (TDB s) and state (m, m/s, ICRF about the dynamics centre): given, read
    from an OEM at the epoch, or found in the arc's own Doppler, alone or with a flyby's epoch (then at the first
    Doppler point used)."""
    init = cfg.initial_state
    if init.from_doppler is not None:
        from odpipe.pipeline.apriori import doppler_apriori  # it reads the data through this module

        result, _ = doppler_apriori(cfg)
        return result.epoch, result.state
    if init.from_flyby is not None:
        from odpipe.pipeline.apriori import flyby_apriori

        return flyby_apriori(cfg)
    t_tdb = tdb(init.epoch)
    if init.from_oem is None:
        return t_tdb, (eme2000_to_gcrs(init.state) if init.frame == "EME2000" else np.asarray(init.state, float))
    traj = oem_trajectory(init.from_oem)
    if traj.center != cfg.dynamics.center.lower():
        raise ConfigError(cfg.path, "initial_state.from_oem",
                          f"{init.from_oem} is about {traj.center}, the dynamics about {cfg.dynamics.center}")
    try:
        return t_tdb, traj.state(t_tdb)[0]
    except ValueError as err:
        raise ConfigError(cfg.path, "initial_state.epoch", f"{init.epoch} is not covered by {init.from_oem}: {err}")


def station_displacement(m) -> StationDisplacement | None:
    """The configured station displacements (``[measurements] station_tides``, ``ocean_loading``), or None."""
    if not m.station_tides and m.ocean_loading is None:
        return None
    sites = {} if m.ocean_loading is None else sites_by_station(blq.read(m.ocean_loading))
    return StationDisplacement(m.station_tides, sites)


def arc_setup(cfg: RunConfig, fm: F.ForceModel, ramps, catalog: StationCatalog) -> ArcSetup:
    est = cfg.estimation
    start, end = tdb(cfg.arc.start), tdb(cfg.arc.end)
    t_state, state0 = initial_state(cfg)
    if abs(t_state - start) > 1e-6:  # move the a priori state to the arc start
        state0 = propagate(state0, t_state, start, fm, with_stm=False).state(start)[0]
    m = cfg.measurements
    # a fixed onboard range bias lengthens every range as a reflector that far behind the centre of mass would
    com = {cfg.arc.spacecraft: m.com_offset - m.onboard_range_bias} if m.com_offset or m.onboard_range_bias else {}
    meas = MeasurementSetup(fm.ephemeris, catalog, ramps=ramps, gcrs_to_itrs=gcrs_to_itrs,
                            com_offsets=com, elevation_refraction=m.elevation_refraction,
                            station_displacement=station_displacement(m))
    stochastic = None if est.stochastic is None else GaussMarkov(est.stochastic.tau, est.stochastic.sigma,
                                                                 est.stochastic.batch)
    return ArcSetup(spacecraft=cfg.arc.spacecraft, start=start, end=end, state0=state0, force_model=fm,
                    measurements=meas, sigma_position=est.sigma_position, sigma_velocity=est.sigma_velocity,
                    srp_scale_sigma=est.srp_scale_sigma if cfg.dynamics.srp is not None else None,
                    stochastic=stochastic, maneuvers=tuple(maneuver_plans(cfg, fm, state0, start)),
                    data_sigma=dict(est.data_sigma), range_bias_sigma=est.range_bias_sigma,
                    range_bias_per=est.range_bias_per, bias_apriori=bias_apriori(est),
                    range_bias_stations=None if est.range_bias_stations is None else tuple(est.range_bias_stations),
                    station_position_sigma=dict(est.station_position_sigma),
                    angle_bias_sigma=None if est.angle_bias_sigma is None
                    else sigma_value("angle_", est.angle_bias_sigma),
                    cd_sigma=est.cd_sigma if cfg.dynamics.drag is not None else None,
                    polynomial_sigma=tuple(est.polynomial_sigma) if est.polynomial_sigma else None,
                    outward=None if est.outward is None else (t_state, est.outward.first_hours * 3600.0,
                                                               est.outward.factor),
                    doppler_bias_sigma=est.doppler_bias_sigma, time_offset_sigma=est.station_time_offset_sigma,
                    oscillator_sigma=tuple(est.oscillator_sigma) if isinstance(est.oscillator_sigma, list)
                    else est.oscillator_sigma, oscillator_per=dict(est.oscillator_per),
                    edit_k=tuple(est.edit_k), max_iter=est.max_iter, reweight=est.reweight,
                    sigma_scale=tuple(est.sigma_scale), block=est.block,
                    measurement_epochs=est.measurement_epochs,
                    edit_against_reference=est.edit_against_reference, tol_dx=est.tol_dx,
                    integration=_tolerances({}, est.reference_rtol, est.reference_atol),
                    coarse_integration=_tolerances(COARSE_INTEGRATION, est.coarse_rtol, est.coarse_atol))


def _tolerances(default: dict, rtol: float | None, atol: float | None) -> dict:
    """Integrator settings: ``default`` with the ``rtol``/``atol`` given (None: the default's)."""
    return {**default, **{k: v for k, v in (("rtol", rtol), ("atol", atol)) if v is not None}}


def bias_apriori(est) -> dict:
    """The a priori biases of the configuration as ArcSetup.bias_apriori: m for ranges, rad for angles."""
    out = {f"range:{st}": v for st, v in est.range_bias_apriori.items()}
    return out | {k: sigma_value("angle_", v) for k, v in est.angle_bias_apriori.items()}


def input_files(cfg: RunConfig) -> list:
    """Every file whose bytes decide the run's result."""
    files = list(cfg.data.files) + cfg.data.stations + cfg.calibration.tro + cfg.calibration.ion + cfg.calibration.ionex
    files += [g.file for g in cfg.dynamics.gravity]
    if cfg.data.sinex is not None:
        files += [f for f in (cfg.data.sinex.file, cfg.data.sinex.eccentricities) if f is not None]
    if cfg.estimation.maneuver_plan is not None:
        files.append(cfg.estimation.maneuver_plan)
    if cfg.initial_state.from_oem is not None:
        files.append(cfg.initial_state.from_oem)
    return files
