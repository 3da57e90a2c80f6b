"""The a priori orbit of a run from its own two-way Doppler (:func:`odpipe.od.apriori.determine_orbit`).

For a spacecraft with no ephemeris: the arc's data are read, the two-way Doppler of one station (by
default the one with the most 60-s points in the arc's first 8 h) over its first ``span_hours`` is
taken, and a circular-orbit grid search refined through a low-degree field of the run's central body
gives the epoch state (ICRF about the centre, m, m/s). Lunar orbiters only: the grid search needs the
body's principal-axis frame.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.dynamics import forces as F
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.gravity import read_gravity
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.frames.moon import moon_pa_to_icrf
from odpipe.measurements import MeasurementSetup
from odpipe.od.apriori import AprioriResult, determine_orbit, doppler_rows
from odpipe.od.flyby_apriori import FlybyApriori, determine_flyby_orbit
from odpipe.pipeline.config import DopplerAprioriSection, RunConfig
from odpipe.pipeline.ingest import ingest
from odpipe.pipeline.setup import station_catalog, tdb
from odpipe.operations.schema import ConfigError
from odpipe.time import tdb_to_utc

FRAMES = {"moon": moon_pa_to_icrf}  # central body -> its body-fixed (PA) frame to ICRF, for the grid search


def doppler_apriori(cfg: RunConfig, how: DopplerAprioriSection | None = None) -> tuple[AprioriResult, pd.DataFrame]:
    """The a priori epoch state of ``cfg``'s arc from its Doppler, and the rows it used (``how``: the
    configuration's ``initial_state.from_doppler``, else the defaults)."""
    how = how or cfg.initial_state.from_doppler or DopplerAprioriSection()
    center = cfg.dynamics.center.lower()
    if center not in FRAMES:
        raise ConfigError(cfg.path, "dynamics.center", f"an a priori orbit from Doppler needs a lunar orbiter, "
                                                       f"not one about {cfg.dynamics.center}")
    fields = [g for g in cfg.dynamics.gravity if g.body.lower() == center]
    if not fields:
        raise ConfigError(cfg.path, "dynamics.gravity", f"an a priori orbit from Doppler needs a field of {center}")
    data = ingest(list(cfg.data.files), spacecraft=cfg.arc.spacecraft)
    catalog = station_catalog(cfg)
    rows = doppler_rows(data.table, data.ramps, cfg.arc.spacecraft)
    t0, t1 = pd.Timestamp(cfg.arc.start), pd.Timestamp(cfg.arc.end)
    rows = rows[(rows["epoch"] >= t0) & (rows["epoch"] <= t1) & rows["station_rx"].isin(catalog.stations)]
    if rows.empty:
        raise ConfigError(cfg.path, "data.files", f"no two-way Doppler of spacecraft {cfg.arc.spacecraft} from a "
                                                  f"catalogued station between {cfg.arc.start} and {cfg.arc.end}")
    station = how.station
    if station is None:
        first = rows[rows["epoch"] < rows["epoch"].min() + pd.Timedelta(hours=8)]
        station = first["station_rx"].value_counts().idxmax()
    rows = rows[rows["station_rx"] == station]
    if rows.empty:
        raise ConfigError(cfg.path, "initial_state.from_doppler.station", f"no two-way Doppler from {station}")
    rows = rows[rows["epoch"] < rows["epoch"].min() + pd.Timedelta(hours=how.span_hours)].reset_index(drop=True)
    field = read_gravity(fields[0].file)
    model = F.ForceModel(center, [F.PointMasses(list(cfg.dynamics.third_bodies)),
                                  F.SphericalHarmonics(center, field, min(how.degree, fields[0].degree))],
                         ephemeris=Ephemeris.open(str(cfg.dynamics.ephemeris)), central_gm=field.gm)
    setup = MeasurementSetup(model.ephemeris, catalog, ramps=data.store, gcrs_to_itrs=gcrs_to_itrs)
    return determine_orbit(rows, setup, model, cfg.arc.spacecraft, FRAMES[center], F.BODY_RADIUS[center]), rows


def flyby_search(cfg: RunConfig) -> FlybyApriori:
    """The flyby search of ``cfg``'s ``initial_state.from_flyby`` on the arc's two-way Doppler
    (:func:`determine_flyby_orbit`): the state about the flown-by body, its closest approach and candidates."""
    how = cfg.initial_state.from_flyby
    key = "initial_state.from_flyby"
    eph = Ephemeris.open(str(cfg.dynamics.ephemeris))
    body = how.body.lower()
    try:
        eph.state(body, cfg.dynamics.center.lower(), np.array([tdb(how.epoch)]))
    except (KeyError, ValueError) as err:
        raise ConfigError(cfg.path, f"{key}.body", f"{how.body!r} is not in {cfg.dynamics.ephemeris}: {err}")
    data = ingest(list(cfg.data.files), spacecraft=cfg.arc.spacecraft)
    catalog = station_catalog(cfg)
    rows = doppler_rows(data.table, data.ramps, cfg.arc.spacecraft)
    rows = rows[(rows["epoch"] >= pd.Timestamp(cfg.arc.start)) & (rows["epoch"] <= pd.Timestamp(cfg.arc.end))
                & rows["station_rx"].isin(catalog.stations)].reset_index(drop=True)
    if rows.empty:
        raise ConfigError(cfg.path, "data.files", f"no two-way Doppler of spacecraft {cfg.arc.spacecraft} from a "
                                                  f"catalogued station between {cfg.arc.start} and {cfg.arc.end}")
    model = F.ForceModel(body, [F.PointMasses([b for b in how.perturbers if b.lower() != body])], ephemeris=eph)
    setup = MeasurementSetup(eph, catalog, ramps=data.store, gcrs_to_itrs=gcrs_to_itrs)
    try:
        return determine_flyby_orbit(rows, setup, model, tdb(how.epoch))
    except RuntimeError as err:
        raise ConfigError(cfg.path, key, f"no orbit flies by {how.body} at {how.epoch}: {err}")


def flyby_apriori(cfg: RunConfig, found: FlybyApriori | None = None) -> tuple[float, np.ndarray]:
    """The a priori epoch (TDB s, the first Doppler point's) and state (m, m/s, ICRF about dynamics.center) of
    ``cfg``'s arc from its two-way Doppler and ``initial_state.from_flyby`` (``found``: that search's result)."""
    found = found or flyby_search(cfg)
    eph = Ephemeris.open(str(cfg.dynamics.ephemeris))
    center = eph.state(cfg.initial_state.from_flyby.body.lower(), cfg.dynamics.center.lower(), np.array([found.epoch]))
    return found.epoch, found.state + center[0]


def initial_state_toml(result: AprioriResult) -> str:
    """The ``[initial_state]`` entries of a run configuration for ``result`` (UTC epoch to the ms)."""
    utc = str(np.datetime64(tdb_to_utc(np.array([result.epoch]))[0], "ms"))
    pos = ", ".join(f"{v:.3f}" for v in result.state[:3])
    vel = ", ".join(f"{v:.6f}" for v in result.state[3:])
    return f'[initial_state]\nepoch = "{utc}"\nstate = [{pos}, {vel}]   # m, m/s, ICRF about the centre\n'
