"""One entry point: computed values and partials for the rows of a TrackingTable.

``compute(rows, trajectories, setup) -> Evaluation``

Rows are grouped by (observable, unit, stations, spacecraft, tag) into a :class:`Group` and each
group is evaluated vectorized by the model registered for its observable (:data:`MODELS`). A new
observable is one function ``@model("name") def f(group) -> (Computed, roles)`` in this module;
light time (``group.solve``) and media (below) are applied the same way for every model.
Supported observables and their row fields:

=================  ==========================================================================
range              two/three-way range, ``unit`` 'RU', 'm' or 's', tagged at reception; band_up
                   gives the range-unit factor; uplink from the ramp store when ``ramped``,
                   else ``uplink_hz``; optional columns ``range_modulus`` or ``range_modulus_ru`` (RU), ``delay_s``.
doppler_2way/3way  count-averaged Doppler (Hz), interval from ``epoch``/``tag``/``count_time``;
                   M2 = ``transponder_ratio`` or the band pair's. Reference f_R: ramped rows with
                   a ``reference_hz`` (ODF, TDM FREQ_OFFSET) use it (constant); other ramped three-way rows the
                   receiver's own ramp when the store has it; else the transmitter's uplink.
doppler_1way       f_ref = ``uplink_hz`` (ODF rows: times 880/240 for X, 3344/240 for Ka downlinks, as
                   the ODF gives it at S-band scale, row by row); each row's oscillator from
                   ``setup.oscillators`` by :func:`.oscillators.row_names` (spacecraft, band, pass;
                   default: nominal f_ref, no bias or drift).
angle_az/el/x/y    antenna angles at reception (rad); elevations apparent with ``setup.elevation_refraction``.
range_rate         instantaneous station-spacecraft range-rate at reception (m/s), for studies.
sst_range          crosslink two-way range (m); ``spacecraft`` = sc1 (transmits and receives,
sst_doppler        time tag at its reception), extra column ``spacecraft_2`` = sc2;
                   sst_doppler is the round-trip path change over ``count_time`` (m/s).
dowr_sum/diff      dual one-way ranging combinations (m) of ``spacecraft`` (sc1) and
                   ``spacecraft_2`` (sc2), both received at ``epoch``; clocks from ``setup.clocks``.
=================  ==========================================================================

Media: a ``media_m`` column (odpipe.media: round-trip path delay for range,
its change over the count interval for Doppler) enters the model as
``setup.media_scale * media`` in the observable's unit when
``setup.media_in_model`` (then the observed values must not be corrected
too); its partial is the group 'media_scale' either way.

Partial groups in :attr:`Evaluation.partials` (N rows x k columns, zero for
rows that do not involve the group):
``state:<sc>`` (6, d/d epoch state of the trajectory), ``dynamic:<sc>``
(p, ``traj.param_names``), ``station:<name>`` (3, ITRS m), ``bias`` (1, unit of
the row), ``delay`` (1, per s of range delay), ``media_scale`` (1),
``oscillator:<name>`` (2: fractional offset y0, drift y1 1/s; names of :mod:`.oscillators`),
``clock:<sc>`` (3: c*a0, c*a1, c*a2).
Trajectories without ``stm`` (reference ephemerides) give values but no state groups.
Rows that cannot be computed get NaN and a reason in :attr:`Evaluation.status`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable, Mapping

import numpy as np
import pandas as pd

from odpipe.constants import C_LIGHT, SECONDS_PER_DAY
from odpipe.environment.ephemeris import SpanEphemeris
from odpipe.frames.tabulated import TabulatedRotation, node_count
from odpipe.tracking.timetags import interval_bounds

from . import angles, crosslink, dsn, instantaneous, oscillators, refraction
from .bands import ONE_WAY_SCALE, band_name, range_unit_factor, turnaround_ratio
from .computed import Computed, ConstantUplink
from .lighttime import anchor_from_utc, solve_path
from .nodes import SpacecraftNode, StationNode, proper_rate_offset
from .partials import dynamic_partials, epoch_state_partials, station_partials

_ANGLES = {"angle_az": "azimuth", "angle_el": "elevation", "angle_x": "x", "angle_y": "y"}


@dataclass
class MeasurementSetup:
    """Everything the models need besides rows and trajectories; built once per run.

    oscillators: oscillator name (:mod:`.oscillators`: a spacecraft, one band of it, one pass of that band) ->
    (y0, y1 1/s, t_ref TDB s): fractional frequency offset from each one-way row's reference frequency and its
    drift (:func:`.dsn.one_way_doppler`).
    clocks: spacecraft -> :class:`.crosslink.ClockModel` for dual one-way ranging.
    com_offsets: spacecraft -> centre-of-mass offset (m) of its ranging reflector or antenna towards the
    stations (LAGEOS: 0.251 m): each leg of a ``range`` row is that much shorter than to the centre of mass.
    elevation_refraction: ``angle_el`` rows are apparent elevations, the free-space one bent by the ITU-R P.834
    reference atmosphere at the station's height (:mod:`.refraction`).
    station_displacement: a :class:`odpipe.environment.station_displacement.StationDisplacement` (solid tide,
    ocean loading) added to every station's catalogue position at each epoch; None: catalogue positions.
    station_partials: compute the ``station:<name>`` partial groups (off where no station position is estimated:
    they cost a rotation per event).
    """

    ephemeris: object
    stations: object
    ramps: object = None
    gcrs_to_itrs: Callable | None = None
    origin: str = "ssb"
    shapiro_bodies: tuple = ("sun", "earth")
    media_scale: float = 1.0
    media_in_model: bool = True
    oscillators: dict = field(default_factory=dict)
    clocks: dict = field(default_factory=dict)
    com_offsets: dict = field(default_factory=dict)
    elevation_refraction: bool = False
    station_displacement: object = None
    station_partials: bool = True

    @classmethod
    def default(cls, **kw) -> "MeasurementSetup":
        """DE440, the default station catalog and the IAU 2006/2000A Earth orientation with EOP."""
        from odpipe.environment.ephemeris import Ephemeris
        from odpipe.environment.stations import StationCatalog
        from odpipe.frames.earth import gcrs_to_itrs

        return cls(Ephemeris.open("de440"), StationCatalog.default(), gcrs_to_itrs=gcrs_to_itrs, **kw)

    def station(self, name: str) -> StationNode:
        st = self.stations[name]
        disp, eph, rot = self.station_displacement, self.ephemeris, self.gcrs_to_itrs
        position = st.position_itrs if disp is None else (lambda t: disp.position(st, t, eph, rot))
        return StationNode(position, rot, eph, self.origin, name)

    def spacecraft(self, traj, name: str) -> SpacecraftNode:
        return SpacecraftNode(traj, self.ephemeris, self.origin, name)


@dataclass
class Evaluation:
    """Computed values (row units), LOS scale (m or m/s per unit), reasons, partial groups, column names."""

    value: np.ndarray
    to_los: np.ndarray
    status: np.ndarray
    partials: dict[str, np.ndarray]
    names: dict[str, list[str]]


class _Unsupported(Exception):
    pass


@dataclass
class Prepared:
    """Rows grouped once for :func:`compute`, for callers that evaluate the same rows again with other
    trajectories (a fit's segment at every iteration): the rows (index reset), their groups (key values,
    positions, rows, and a dict in which the group keeps what does not depend on the trajectories:
    :attr:`Group.memo`) and the TDB span (s) of their epochs (None without rows)."""

    rows: pd.DataFrame
    groups: list
    span: tuple | None


def prepare(rows: pd.DataFrame) -> Prepared:
    """The :class:`Prepared` grouping of ``rows`` (a TrackingTable slice)."""
    df = rows.reset_index(drop=True)
    n = len(df)
    if not n:
        return Prepared(df, [], None)
    sc2 = df["spacecraft_2"] if "spacecraft_2" in df.columns else pd.Series([""] * n)
    keys = [df["observable"], df["unit"], df["station_tx"], df["station_rx"], df["spacecraft"].astype(str),
            sc2.astype(str), df["tag"]]
    t, _ = anchor_from_utc(np.array([df["epoch"].min(), df["epoch"].max()], dtype="datetime64[ns]"))
    return Prepared(df, [(key, idx, df.iloc[idx], {}) for key, idx in _groups(keys)], (float(t[0]), float(t[1])))


def compute(rows: pd.DataFrame, trajectories: Mapping, setup: MeasurementSetup,
            prepared: Prepared | None = None) -> Evaluation:
    """Computed observables and partials of ``rows`` (a TrackingTable slice) given trajectories by spacecraft id;
    ``prepared``: :func:`prepare` of these rows, when the caller keeps it."""
    prep = prepare(rows) if prepared is None else prepared
    n = len(prep.rows)
    out = Evaluation(np.full(n, np.nan), np.full(n, np.nan), np.full(n, "", dtype=object), {}, {})
    if prep.span is not None:
        setup = spanning(setup, prep.span[0] - SPAN_MARGIN_S, prep.span[1] + SPAN_MARGIN_S, n)
    setup = _remembering(setup)
    for key, idx, g, memo in prep.groups:
        grp = _group(key, g, trajectories, setup, memo)
        try:
            comp, roles = _evaluate(grp)
        except _Unsupported as exc:
            out.status[idx] = str(exc)
            continue
        _store(out, idx, n, comp, roles, grp)
    return out


def _groups(keys: list) -> list[tuple[tuple, np.ndarray]]:
    """(key values, row positions) of each distinct combination of the ``keys`` columns, in order of first
    appearance; rows with a missing key are left out (as pandas' ``groupby`` does, at a fraction of its cost)."""
    code = np.zeros(len(keys[0]), np.int64)
    missing = np.zeros(code.size, bool)
    for col in keys:
        c, u = pd.factorize(col)
        missing |= c < 0
        code = code * (len(u) + 1) + (c + 1)
    code[missing] = -1
    uniq, first, inverse = np.unique(code, return_index=True, return_inverse=True)
    return [(tuple(col.iloc[first[j]] for col in keys), np.flatnonzero(inverse == j))
            for j in np.argsort(first) if uniq[j] >= 0]


class _RememberedEphemeris:
    """An ephemeris whose states are remembered by (target, centre, epochs) for one :func:`compute` call: its
    light-time solutions ask for the Earth at the same epochs for stations, the spacecraft, the Shapiro delay
    and station clocks. Remembered arrays are read-only."""

    def __init__(self, ephemeris):
        self._ephemeris, self._states = ephemeris, {}

    def state(self, target, center, t):
        t = np.asarray(t, dtype=float)
        key = (target, center, t.shape, t.tobytes())
        out = self._states.get(key)
        if out is None:
            out = np.asarray(self._ephemeris.state(target, center, t), dtype=float)
            out.setflags(write=False)
            self._states[key] = out
        return out

    def __getattr__(self, name):
        return getattr(self._ephemeris, name)


class _RememberedRotation:
    """The GCRS-to-ITRS matrices remembered by epochs for one :func:`compute` call (read-only)."""

    def __init__(self, rotation):
        self._rotation, self._matrices = rotation, {}

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        key = (t.shape, t.tobytes())
        out = self._matrices.get(key)
        if out is None:
            out = np.asarray(self._rotation(t), dtype=float)
            out.setflags(write=False)
            self._matrices[key] = out
        return out


def _remembering(setup: MeasurementSetup) -> MeasurementSetup:
    eph = None if setup.ephemeris is None else _RememberedEphemeris(setup.ephemeris)
    rot = None if setup.gcrs_to_itrs is None else _RememberedRotation(setup.gcrs_to_itrs)
    return replace(setup, ephemeris=eph, gcrs_to_itrs=rot)


SPAN_MARGIN_S = SECONDS_PER_DAY  # s around the rows' epochs: light times (hours) and count intervals
ROTATION_EPOCHS_PER_ROW = 12     # Earth-orientation epochs a row asks for: up to 3 events x 4 light-time iterations


def spanning(setup: MeasurementSetup, t0: float, t1: float, n_rows: int | None = None) -> MeasurementSetup:
    """``setup`` tabulated over [t0, t1] TDB s: ephemeris from Chebyshev pieces (:class:`SpanEphemeris`),
    Earth orientation from a Chebyshev table (:class:`TabulatedRotation`). Parts already tabulated are kept.
    With ``n_rows``, the Earth orientation is tabulated only if those rows would ask for it at more epochs than
    the table's nodes (a few rows a month apart: each epoch computed directly, not a month of hourly pieces)."""
    eph, rot = setup.ephemeris, setup.gcrs_to_itrs
    if hasattr(eph, "interpolant") and not isinstance(eph, SpanEphemeris):
        eph = SpanEphemeris(eph, t0, t1)
    sparse = n_rows is not None and n_rows * ROTATION_EPOCHS_PER_ROW < node_count(t0, t1)
    if rot is not None and not isinstance(rot, TabulatedRotation) and not sparse:
        rot = TabulatedRotation(rot, t0, t1)
    return replace(setup, ephemeris=eph, gcrs_to_itrs=rot)


@dataclass
class Group:
    """Rows sharing one observable, unit, link (tx, rx), spacecraft (sc, sc2) and time tag, with what a model
    needs: the trajectories by spacecraft id and the set-up. ``memo``: what the group's rows alone decide (their
    columns as arrays, epochs, count intervals, anchor epochs, M2, range-unit factors, media), kept by
    :class:`Prepared` across evaluations; its arrays are read-only."""

    obs: str
    unit: str
    tx: str
    rx: str
    sc: str
    sc2: str
    tag: str
    rows: pd.DataFrame
    trajectories: Mapping
    setup: MeasurementSetup
    memo: dict = field(default_factory=dict)

    def _kept(self, key, make):
        """``make()``, made once per group (its arrays read-only)."""
        if key not in self.memo:
            got = make()
            for a in got if isinstance(got, tuple) else (got,):
                a.setflags(write=False)
            self.memo[key] = got
        return self.memo[key]

    @property
    def epoch(self) -> np.ndarray:
        return self.column("epoch", "datetime64[ns]")

    def column(self, name: str, dtype=float) -> np.ndarray:
        """Column ``name`` of the rows as a ``dtype`` array, read once per group (read-only)."""
        return self._kept(("column", name, np.dtype(dtype).str), lambda: self.rows[name].to_numpy(dtype, copy=True))

    def has(self, name: str) -> bool:
        """Whether the rows have column ``name``."""
        return name in self.rows.columns

    def trajectory(self, sc: str):
        return _trajectory(self.trajectories, sc)

    def solve(self, nodes, utc, anchor: str = "receive"):
        """The light-time solution of the path through ``nodes`` anchored at UTC ``utc``."""
        utc = np.asarray(utc, dtype="datetime64[ns]")
        t, c = self._kept(("anchor", utc.tobytes()), lambda: anchor_from_utc(utc))
        return solve_path(nodes, t, anchor=anchor, t_corr=c, shapiro_bodies=self.setup.shapiro_bodies,
                          ephemeris=self.setup.ephemeris, origin=self.setup.origin)

    def solve_interval(self, nodes, anchor: str = "receive"):
        """Count-interval starts and ends (UTC) and the light-time solutions there, each distinct epoch solved
        once (consecutive counts share their bounds)."""
        s, e = self.interval()
        epochs, which = self._kept("interval_epochs", lambda: np.unique(np.concatenate([s, e]), return_inverse=True))
        sol = self.solve(nodes, epochs, anchor)
        return s, e, sol.take(which[:s.size]), sol.take(which[s.size:])

    def interval(self):
        """Start and end (UTC) of each row's count interval."""
        def bounds():
            s, e = interval_bounds(self.epoch.astype(np.int64), self.column("count_time"), self.column("tag", object))
            return s.astype("datetime64[ns]"), e.astype("datetime64[ns]")
        return self._kept("interval", bounds)


MODELS: dict[str, Callable[[Group], tuple]] = {}  # observable -> model(group) -> (Computed, roles): the registry


def model(*observables: str):
    """Register a measurement model for ``observables``: ``f(group: Group) -> (Computed, roles)``, roles naming
    each participant's partials (``{"station_rx": ("station", id, node), "spacecraft": ("sc", id, trajectory)}``)."""
    def register(fn):
        for name in observables:
            MODELS[name] = fn
        return fn
    return register


def _group(key, g, trajectories, setup, memo) -> Group:
    obs, unit, tx, rx, sc, sc2, tag = key
    return Group(obs, unit, tx or rx, rx, sc, sc2, tag, g, trajectories, setup, memo)


def _evaluate(grp: Group):
    if grp.obs not in MODELS:
        raise _Unsupported(f"observable {grp.obs!r} has no model")
    return MODELS[grp.obs](grp)


def _receiver(grp: Group, st_rx, traj) -> dict:
    """The roles of a one-station observable: the receiving station and the spacecraft."""
    return {"station_rx": ("station", grp.rx, st_rx), "spacecraft": ("sc", grp.sc, traj)}


@model("range", "doppler_2way", "doppler_3way")
def _dsn_two_way(grp: Group):
    """DSN two- and three-way range and ramped Doppler (Moyer)."""
    setup, tx, rx, sc = grp.setup, grp.tx, grp.rx, grp.sc
    if grp.obs == "range" and grp.tag not in ("receive", "interval_end"):
        raise _Unsupported(f"range tagged {grp.tag!r}: only reception tags are modelled")
    traj = grp.trajectory(sc)
    st_tx, st_rx = setup.station(tx), setup.station(rx)
    nodes = [st_tx, setup.spacecraft(traj, sc), st_rx]
    up = _uplink(grp, tx, setup)
    roles = {"station_tx": ("station", tx, st_tx), "station_rx": ("station", rx, st_rx), "spacecraft": ("sc", sc, traj)}
    if grp.obs == "range":
        ru = grp._kept("range_unit_factor", lambda: range_unit_factor(grp.column("band_up", object)))
        modulus = _column(grp, ("range_modulus", "range_modulus_ru"))
        delay = np.nan_to_num(grp.column("delay_s")) if grp.has("delay_s") else 0.0
        delay = delay - 2.0 * setup.com_offsets.get(sc, 0.0) / C_LIGHT
        if grp.unit not in ("RU", "m", "s"):
            raise _Unsupported(f"range in unit {grp.unit!r}: only RU, m and s are modelled")
        read = grp.column("uplink_epoch", "datetime64[ns]") if grp.has("uplink_epoch") else None
        return dsn.dsn_range(grp.solve(nodes, grp.epoch), up, tx, grp.epoch, ru, grp.unit, delay, modulus,
                             read), roles
    m2 = grp._kept("m2", lambda: _turnaround(grp))
    s, e, sol_s, sol_e = grp.solve_interval(nodes)
    ref = None
    if grp.has("reference_hz") and grp.column("ramped", bool).all() and np.isfinite(grp.column("reference_hz")).all():
        ref = grp.column("reference_hz")  # ODF (or TDM FREQ_OFFSET) ramped Doppler: M2 f_REF - f_received
    elif grp.obs == "doppler_3way" and setup.ramps is not None and rx in getattr(setup.ramps, "stations", []) \
            and grp.column("ramped", bool).all():
        ref = setup.ramps
    return dsn.dsn_doppler(sol_s, sol_e, up, tx, s, e, m2, ref, rx), roles


@model("doppler_1way")
def _one_way_doppler(grp: Group):
    """One-way Doppler from the spacecraft's oscillator, transmitting in its proper time."""
    g, setup, sc = grp.rows, grp.setup, grp.sc
    traj, st_rx = grp.trajectory(sc), setup.station(grp.rx)
    nodes = [setup.spacecraft(traj, sc), st_rx]
    f_ref = grp.column("uplink_hz")
    if grp.has("odf_data_type"):  # ODF gives the one-way reference at S-band scale (parsers.odf)
        f_ref = f_ref * g["band_down"].map(lambda b: ONE_WAY_SCALE.get(band_name(b), np.nan)).to_numpy(float)
    names = oscillators.row_names(sc, g, setup.oscillators)
    known, which = np.unique(names.astype(str), return_inverse=True)
    y0, y1, t_ref = np.array([setup.oscillators.get(k, (0.0, 0.0, 0.0)) for k in known], float)[which.ravel()].T
    s, e = grp.interval()
    sols = grp.solve(nodes, s), grp.solve(nodes, e)
    proper = 0.5 * sum(proper_rate_offset(setup.ephemeris, setup.origin, p.epochs[:, 0] + p.epoch_corr[:, 0],
                                          p.states[:, 0]) for p in sols)
    comp = dsn.one_way_doppler(*sols, f_ref, grp.column("count_time"), y0, y1, t_ref, proper)
    d = np.stack([comp.params.pop("osc_y0"), comp.params.pop("osc_y1")], 1)
    for k in dict.fromkeys(names):   # one partial group per oscillator, zero on the other rows
        comp.params[f"oscillator:{k}"] = d * (names == k)[:, None]
    return comp, _receiver(grp, st_rx, traj)


@model(*_ANGLES)
def _antenna_angle(grp: Group):
    """Antenna angles at the receiving station (elevation refracted when the set-up asks)."""
    setup, traj = grp.setup, grp.trajectory(grp.sc)
    st_rx = setup.station(grp.rx)
    comp = angles.antenna_angle(grp.solve([setup.spacecraft(traj, grp.sc), st_rx], grp.epoch), st_rx, _ANGLES[grp.obs])
    if grp.obs == "angle_el" and setup.elevation_refraction:
        comp = refraction.refracted(comp, setup.stations[grp.rx].geodetic()[2])
    return comp, _receiver(grp, st_rx, traj)


@model("range_rate")
def _instantaneous_range_rate(grp: Group):
    """Instantaneous station-to-spacecraft range rate (no light time)."""
    setup, traj, st_rx = grp.setup, grp.trajectory(grp.sc), grp.setup.station(grp.rx)
    t, _ = anchor_from_utc(grp.epoch)
    comp = instantaneous.instantaneous_range_rate(st_rx.state(t), setup.spacecraft(traj, grp.sc).state(t), t,
                                                  ("station_rx", "spacecraft"))
    return comp, _receiver(grp, st_rx, traj)


@model("sst_range", "sst_doppler", "dowr_sum", "dowr_diff")
def _crosslink(grp: Group):
    """Spacecraft-to-spacecraft two-way range and Doppler, and dual one-way ranging with clocks."""
    setup, sc, sc2 = grp.setup, grp.sc, grp.sc2
    traj, traj2 = grp.trajectory(sc), grp.trajectory(sc2)
    n1, n2 = setup.spacecraft(traj, sc), setup.spacecraft(traj2, sc2)
    roles = {"sc1": ("sc", sc, traj), "sc2": ("sc", sc2, traj2)}
    if grp.obs == "sst_range":
        return crosslink.two_way_range(grp.solve([n1, n2, n1], grp.epoch)), roles
    if grp.obs == "sst_doppler":
        s, e = grp.interval()
        return crosslink.two_way_doppler(grp.solve([n1, n2, n1], s), grp.solve([n1, n2, n1], e),
                                         grp.column("count_time")), roles
    c1, c2 = setup.clocks.get(sc, crosslink.ClockModel()), setup.clocks.get(sc2, crosslink.ClockModel())
    total, diff = crosslink.dual_one_way(grp.solve([n2, n1], grp.epoch), grp.solve([n1, n2], grp.epoch), c1, c2)
    comp = total if grp.obs == "dowr_sum" else diff
    for who in ("sc1", "sc2"):
        name = sc if who == "sc1" else sc2
        comp.params[f"clock:{name}"] = np.stack([comp.params.pop(f"clock_{who}_{k}") for k in ("a0", "a1", "a2")], 1)
    return comp, roles


def _turnaround(grp: Group) -> np.ndarray:
    """M2 per row: ``transponder_ratio`` where given, else the band pair's."""
    m2 = grp.column("transponder_ratio")
    return np.where(np.isfinite(m2), m2, turnaround_ratio(grp.column("band_up", object), grp.column("band_down", object)))


def _column(grp: Group, names):
    """The first of ``names`` present in the rows as floats (TRK-2-34 and ODF name the range modulus differently),
    else NaN."""
    for name in names:
        if grp.has(name):
            return grp.column(name)
    return np.full(len(grp.rows), np.nan)


def _trajectory(trajectories, sc):
    if sc not in trajectories:
        raise _Unsupported(f"no trajectory for spacecraft {sc!r}")
    return trajectories[sc]


def _uplink(grp: Group, station, setup):
    ramped = grp.column("ramped", bool)
    if ramped.any():
        if setup.ramps is None or station not in setup.ramps.stations:
            raise _Unsupported(f"ramped rows but no ramps for {station!r}")
        if not ramped.all():
            raise _Unsupported("a group mixes ramped and constant uplink rows")
        return setup.ramps
    return ConstantUplink(grp.column("uplink_hz"))


def _media(comp: Computed, grp: Group) -> np.ndarray | None:
    """The media column in the observable's unit, or None."""
    if not grp.has("media_m"):
        return None
    m = grp._kept("media_m", lambda: np.nan_to_num(grp.column("media_m")))
    if grp.obs == "range":
        return m / 2 / comp.to_los
    if grp.obs in ("doppler_2way", "doppler_3way"):
        return m / (2 * grp.column("count_time")) / comp.to_los
    if grp.obs == "doppler_1way":
        return m / grp.column("count_time") / comp.to_los
    return None


def _store(out: Evaluation, idx, n, comp: Computed, roles, grp: Group):
    setup = grp.setup
    value = np.asarray(comp.value, dtype=float).copy()
    media = _media(comp, grp)
    if media is not None:
        _put(out, "media_scale", ["media_scale"], idx, n, media[:, None])
        if setup.media_in_model:
            value += setup.media_scale * media
    out.value[idx] = value
    out.to_los[idx] = np.broadcast_to(comp.to_los, value.shape)
    out.status[idx] = np.where(np.isfinite(value), "", "not computable (ramp coverage, band or frequency missing)")
    for k, v in comp.params.items():
        v = np.asarray(v, dtype=float)
        v = v[:, None] if v.ndim == 1 else v
        names = {"bias": ["bias"], "delay": ["delay_s"]}.get(k.split(":")[0])
        if k.startswith("oscillator:"):
            names = ["y0", "y1_per_s"]
        elif k.startswith("clock:"):
            names = ["c_a0", "c_a1", "c_a2"]
        _put(out, k, names, idx, n, v)
    done = set()
    for role, (kind, name, obj) in roles.items():
        if kind == "station":
            if setup.station_partials:
                _put(out, f"station:{name}", ["x", "y", "z"], idx, n, station_partials(comp, role, obj))
        elif (name, role) not in done and getattr(obj, "with_stm", hasattr(obj, "stm")):  # no STM: values only
            done.add((name, role))
            _put(out, f"state:{name}", ["x", "y", "z", "vx", "vy", "vz"], idx, n, epoch_state_partials(comp, role, obj))
            if getattr(obj, "param_names", None):
                _put(out, f"dynamic:{name}", list(obj.param_names), idx, n, dynamic_partials(comp, role, obj))


def _put(out: Evaluation, key, names, idx, n, block):
    if key not in out.partials:
        out.partials[key] = np.zeros((n, block.shape[1]))
        out.names[key] = list(names) if names else [key]
    out.partials[key][idx] += block
