"""fit_arc: orbit determination of one spacecraft from a TrackingTable over one arc.

The set-up follows the ARTEMIS practice (Table 4.1 of the thesis): epoch state
(100 km, 1 m/s), SRP scale (10 %), RTN stochastic accelerations, impulsive
maneuvers at logged epochs (zero a priori deviation from the design, 10 mm/s
per axis), DSN per-pass range biases (5 m), data sigmas per observable
(range 2 m, Doppler 0.1 mm/s), an iterated filter-smoother with k-sigma
editing and, optionally, data weights rescaled per station and observable by
their post-fit residual RMS after each iteration.

Rows used: ``flags == 0``, ``spacecraft`` of the arc, an observable with a data
sigma, last reception (interval end for Doppler) within ``[start, end]`` TDB,
and computable by the models (otherwise reported with the reason).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from odpipe.constants import SECONDS_PER_DAY
from odpipe.dynamics.forces import AtmosphericDrag, ForceModel, InertialPolynomialAcceleration, SolarRadiationPressure
from odpipe.dynamics.polynomial import PARAMETERS as POLY_PARAMETERS
from odpipe.estimation.fit import EDIT_INNOVATION, NONFINITE, FitOptions, Observations, Solution, build_grid, fit
from odpipe.estimation.maneuvers import maneuver_table
from odpipe.estimation.registry import GaussMarkov, ParameterRegistry
from odpipe.measurements import MeasurementSetup, oscillators
from odpipe.measurements.bands import band_name, downlink_bands
from odpipe.measurements.compute import spanning
from odpipe.od.outward import labelled
from odpipe.preprocess.flags import Flag
from odpipe.tracking.timetags import interval_bounds
from odpipe.time import utc_to_tdb

from .problem import TrackingProblem


@dataclass(frozen=True)
class ManeuverPlan:
    """A logged impulsive maneuver: label, epoch (TDB s), designed ICRF dV (m/s), a priori sigma per axis (m/s),
    a priori sigma (s) of its firing-epoch offset (None: epoch not estimated; Table 4.1: 10 s)."""

    label: str
    epoch: float
    designed: tuple = (0.0, 0.0, 0.0)
    sigma: float = 0.01
    sigma_epoch: float | None = None


DATA_SIGMA = {"range": 2.0, "doppler_2way": 1e-4}  # default data sigmas along the line of sight: m, m/s
# references of the loose-weight stages (TrackingProblem.set_coarse): over 1 h of GRAIL-B's 55-km lunar orbit
# (degree 150) 2.4 cm and 3.3e-5 m/s from the exact settings' (rtol 1e-12, atol 1e-6) with 0.61 of their
# force evaluations (benchmarks/profile_coarse_reference.py)
COARSE_INTEGRATION = {"rtol": 1e-9, "atol": 1e-5}


@dataclass
class ArcSetup:
    """Everything one arc fit needs (SI units; times TDB s past J2000).

    state0: a priori epoch state at ``start`` relative to ``force_model.center``.
    force_model: dynamics without the estimated maneuvers and stochastic accelerations.
    srp_scale_sigma: a priori sigma of the SRP scale (None: not estimated).
    stochastic: RTN Gauss-Markov accelerations (m/s^2; tau 0 = white per batch), or None.
    data_sigma: sigma along the line of sight (m or m/s) by "observable:station_rx", else by "observable";
    for angle rows (unit rad) the angle's own sigma: a number in rad or a string with its unit, "0.01 deg",
    "36 arcsec", "1.7e-4 rad" (:data:`ANGLE_UNITS`).
    angle_bias_sigma: one constant bias (rad) per receiving station and angle observable (None: none).
    range_bias_sigma: per pass and receiving station (m; None: no biases; pass_id -1 = one per station);
    ``range_bias_per`` "station": one per station over the arc whatever the passes;
    ``range_bias_stations``: only these receiving stations' ranges get biases (None: every station's).
    bias_apriori: a priori bias values (m; rad for angles) by "observable:station_rx" or "observable" (others 0).
    cd_sigma: a priori sigma of the drag coefficient (None: not estimated; a priori the model's Cd).
    polynomial_sigma: (c0 m/s^2, c1 m/s^3) a priori sigmas of every inertial polynomial acceleration's
    coefficients (None: fixed; a priori the model's values).
    outward: (epoch TDB s, first half-window s, factor): fit outward from that epoch (:mod:`.outward`).
    doppler_bias_sigma: per pass and receiving station, two-way Doppler (m/s along the line of sight; None: none).
    time_offset_sigma: a time-tag offset per receiving station (s, tags late; None: none), relative to the
    station with the most rows, whose own is zero: an offset common to every station moves the whole data set
    in time, which the epoch state absorbs (the orbit flown that much earlier).
    oscillator_sigma: (y0, y1 1/s) sigmas of the one-way oscillator's fractional frequency offset and drift,
    when doppler_1way is fitted (a priori and reference epoch from ``measurements.oscillators``): one pair for
    every band, or {band: pair} for one oscillator per band named; oscillator_per: {band: "arc" | "pass"}, "pass"
    for an oscillator re-estimated every pass of that band (:func:`oscillator_terms`).
    station_sigma: considered (not estimated) error of each station's ITRS coordinates (m per axis).
    station_position_sigma: {station: m per ITRS axis}: those stations' coordinate offsets estimated (a priori 0).
    media_sigma: considered error of the media calibration scale (fraction of ``media_m``).
    edit_k: innovation k-sigma per iteration (last repeats); reweight: ARTEMIS data reweighting; tol_dx:
    converged when the last pass's epoch correction is below this many sigma (:class:`FitOptions`).
    sigma_scale: data-weight stages (loose to tight; see :class:`FitOptions`).
    block: filter grid spacing (s); measurement_epochs: every row's epoch on the grid too (one update per
    epoch: a sequential filter's innovations); lookback: s of trajectory kept before each segment start.
    tabulate_earth_rotation: evaluate the GCRS->ITRS matrix from a per-arc Chebyshev table
    (:mod:`.rotation`, < 1e-12 rad) instead of the full model at every event.
    coarse_integration: integrator settings of the references of the fit's loose-weight stages
    (all ``sigma_scale`` stages but the last; None: exact throughout); integration: ``rtol``/``atol``
    of the exact references (empty: :class:`~.problem.TrackingProblem`'s).
    """

    spacecraft: str
    start: float
    end: float
    state0: np.ndarray
    force_model: ForceModel
    measurements: MeasurementSetup
    sigma_position: float = 100e3
    sigma_velocity: float = 1.0
    srp_scale_sigma: float | None = 0.1
    stochastic: GaussMarkov | None = None
    maneuvers: tuple = ()
    data_sigma: dict = field(default_factory=lambda: dict(DATA_SIGMA))
    range_bias_sigma: float | None = 5.0
    range_bias_per: str = "pass"
    range_bias_stations: tuple | None = None
    doppler_bias_sigma: float | None = None
    time_offset_sigma: float | None = None
    angle_bias_sigma: float | None = None
    bias_apriori: dict = field(default_factory=dict)
    cd_sigma: float | None = None
    polynomial_sigma: tuple | None = None
    oscillator_sigma: tuple | dict | None = None
    oscillator_per: dict = field(default_factory=dict)
    station_sigma: float | None = None
    station_position_sigma: dict = field(default_factory=dict)
    media_sigma: float | None = None
    edit_k: tuple = FitOptions.edit_k  # the fit's defaults have one home, FitOptions
    max_iter: int = FitOptions.max_iter
    reweight: bool = FitOptions.reweight
    sigma_scale: tuple = FitOptions.sigma_scale
    block: float = FitOptions.block
    measurement_epochs: bool = FitOptions.output_at_measurements
    edit_against_reference: bool = FitOptions.edit_against_reference
    tol_dx: float = FitOptions.tol_dx
    lookback: float = 120.0
    growing_days: float | None = 2.0  # first span of the growing-arc start (None: fit the whole arc at once)
    tabulate_earth_rotation: bool = True
    outward: tuple | None = None
    coarse_integration: dict | None = field(default_factory=lambda: dict(COARSE_INTEGRATION))
    integration: dict = field(default_factory=dict)


@dataclass
class ArcSolution:
    """Products of one arc fit.

    epochs (N,) TDB s; states (N, 6) m, m/s and covariances (N, 6, 6): smoothed, on the
    filter grid (at a maneuver epoch the state before the burn); parameters: name, kind,
    apriori, estimate, sigma (epoch values; stochastic: first batch); maneuvers: designed vs
    estimated dV; residuals: one line per row considered (see :func:`fit_arc`).
    """

    spacecraft: str
    epochs: np.ndarray
    states: np.ndarray
    covariances: np.ndarray
    parameters: pd.DataFrame
    maneuvers: pd.DataFrame
    residuals: pd.DataFrame
    history: list
    converged: bool
    solution: Solution
    registry: ParameterRegistry
    problem: TrackingProblem


ANGLE_UNITS = {"rad": 1.0, "deg": np.pi / 180.0, "mdeg": np.pi / 180e3, "arcsec": np.pi / 648e3}


def sigma_value(key: str, value) -> float:
    """A data_sigma entry as a number: angles may carry their unit ("0.01 deg"); bare numbers as given.
    ValueError saying why when a string is not one."""
    if not isinstance(value, str):
        return float(value)
    number, _, unit = value.strip().partition(" ")
    try:
        x = float(number)
    except ValueError:
        x = None
    if not key.startswith("angle_"):
        raise ValueError(f"{value!r} is not a number (only angle observables take a unit)")
    if x is None or unit.strip() not in ANGLE_UNITS:
        raise ValueError(f"{value!r} is not an angle with its unit, one of {sorted(ANGLE_UNITS)}")
    return x * ANGLE_UNITS[unit.strip()]


def data_sigma(rows: pd.DataFrame, sigmas: dict) -> np.ndarray:
    """Per-row sigma (m or m/s; rad for angle rows): the "observable:station_rx" entry if there is one, else
    the "observable:band_down" one (e.g. "doppler_1way:S"), else the observable's."""
    values = {}
    for k, v in sigmas.items():
        try:
            values[k] = sigma_value(k, v)
        except ValueError as exc:
            raise ValueError(f"data_sigma.{k}: {exc}") from None
    by_station = (rows["observable"] + ":" + rows["station_rx"].astype(str)).map(values)
    if "band_down" in rows.columns:
        by_station = by_station.fillna((rows["observable"] + ":" + rows["band_down"].astype(str)).map(values))
    return by_station.fillna(rows["observable"].map(values)).to_numpy(float)


def reception_times(rows: pd.DataFrame) -> np.ndarray:
    """TDB s of each row's last reception (interval end for count-averaged rows)."""
    _, end = interval_bounds(rows["epoch"].to_numpy("datetime64[ns]").astype(np.int64),
                             rows["count_time"].to_numpy(float), rows["tag"].to_numpy(object))
    return np.asarray(utc_to_tdb(end.astype("datetime64[ns]")), float)


def select_rows(table: pd.DataFrame, setup: ArcSetup) -> tuple[pd.DataFrame, np.ndarray]:
    """Rows of the arc in reception-time order (original index kept) and their TDB times."""
    sel = ((table["flags"].to_numpy() == 0) & table["observable"].isin([k.split(":")[0] for k in setup.data_sigma]).to_numpy()
           & (table["spacecraft"].astype(str).to_numpy() == setup.spacecraft))
    rows = table[sel]
    t = reception_times(rows)
    inside = (t >= setup.start) & (t <= setup.end)
    order = np.argsort(t[inside], kind="stable")
    return rows[inside].iloc[order], t[inside][order]


def oscillator_terms(setup: ArcSetup, rows: pd.DataFrame) -> list[tuple[str, tuple, tuple]]:
    """The estimated one-way oscillators of the fitted ``rows``: (name, a priori (y0, y1, t_ref TDB s), sigmas).

    ``oscillator_sigma`` a pair: one oscillator for every band; a table: one per band it names (bands it does
    not name are not estimated). A band whose ``oscillator_per`` is "pass" gets one oscillator per pass of its
    rows, about the pass's mean reception time, a priori 0; the others take the a priori of
    ``measurements.oscillators`` (default 0 about the arc start).
    """
    one_way = rows[rows["observable"] == "doppler_1way"]
    if setup.oscillator_sigma is None or one_way.empty:
        return []
    sc, known = setup.spacecraft, setup.measurements.oscillators
    if not isinstance(setup.oscillator_sigma, dict):
        return [(sc, known.get(sc, (0.0, 0.0, setup.start)), tuple(setup.oscillator_sigma))]
    out = []
    bands = one_way["band_down"].map(band_name)
    per = {band_name(b): v for b, v in setup.oscillator_per.items()}
    for band, sigmas in setup.oscillator_sigma.items():
        mine = one_way[(bands == band_name(band)).to_numpy()]
        if mine.empty:
            continue
        if per.get(band_name(band), "arc") == "pass":
            for pid, g in mine.groupby("pass_id", sort=True):
                out.append((oscillators.name(sc, band, pid), (0.0, 0.0, float(reception_times(g).mean())),
                            tuple(sigmas)))
        else:
            osc = oscillators.name(sc, band)
            out.append((osc, known.get(osc, (0.0, 0.0, setup.start)), tuple(sigmas)))
    return out


def build_registry(setup: ArcSetup, rows: pd.DataFrame) -> ParameterRegistry:
    """Estimated and considered parameters of the arc (Table 4.1 structure)."""
    sc = setup.spacecraft
    reg = ParameterRegistry()
    reg.add_state(sc, setup.state0, setup.sigma_position, setup.sigma_velocity)
    if setup.srp_scale_sigma is not None:
        srp = setup.force_model.of_type(SolarRadiationPressure)
        if not srp:
            raise ValueError("srp_scale_sigma given but the force model has no SRP")
        reg.add(f"{sc}.srp_scale", "dynamic", srp[0].scale, setup.srp_scale_sigma, owner=sc, model="srp_scale")
    if setup.cd_sigma is not None:
        drag = setup.force_model.of_type(AtmosphericDrag)
        if not drag:
            raise ValueError("cd_sigma given but the force model has no drag")
        reg.add(f"{sc}.cd", "dynamic", drag[0].cd, setup.cd_sigma, owner=sc, model="cd")
    if setup.polynomial_sigma is not None:
        polys = setup.force_model.of_type(InertialPolynomialAcceleration)
        if not polys:
            raise ValueError("polynomial_sigma given but the force model has no polynomial acceleration")
        for k, poly in enumerate(polys):
            for name, value in zip(POLY_PARAMETERS, (*poly.c0, *poly.c1)):
                reg.add(f"{sc}.poly[{k}].{name}", "dynamic", float(value), setup.polynomial_sigma[name[-1] == "1"],
                        owner=sc, model=f"poly[{k}].{name}")
    if setup.stochastic is not None:
        g = setup.stochastic
        reg.add_stochastic_acceleration(sc, g.sigma, g.tau, g.batch)
    for m in setup.maneuvers:
        reg.add_maneuver(sc, m.label, m.epoch, m.sigma, m.designed, sigma_epoch=m.sigma_epoch)
    for obs, sigma in (("range", setup.range_bias_sigma), ("doppler_2way", setup.doppler_bias_sigma)):
        if sigma is None:
            continue
        sel = rows.loc[rows["observable"] == obs, ["station_rx", "pass_id"]]
        if obs == "range" and setup.range_bias_per == "station":
            sel = sel.assign(pass_id=-1)
        if obs == "range" and setup.range_bias_stations is not None:
            sel = sel[sel["station_rx"].isin(setup.range_bias_stations)]
        for st, pid in sel.drop_duplicates().itertuples(index=False):
            info = {"observable": obs, "station": st, "spacecraft": sc}
            if pid >= 0:
                info["pass_id"] = pid
            reg.add(f"bias.{obs}.{st}.pass{pid}", "bias", _bias_apriori(setup, obs, st), sigma, owner=st, **info)
    if setup.time_offset_sigma is not None:   # relative to the station with the most rows (a common offset is the orbit's)
        counts = rows.loc[rows["station_rx"] != "", "station_rx"].value_counts()
        for st in sorted(counts.index[1:]):
            reg.add_time_offset(st, setup.time_offset_sigma, spacecraft=sc)
    if setup.angle_bias_sigma is not None:
        ang = rows[rows["unit"] == "rad"]
        for obs, st in ang[["observable", "station_rx"]].drop_duplicates().itertuples(index=False):
            reg.add(f"bias.{obs}.{st}", "bias", _bias_apriori(setup, obs, st), setup.angle_bias_sigma, owner=st,
                    observable=obs, station=st, spacecraft=sc)
    for osc, (y0, y1, t_ref), sigmas in oscillator_terms(setup, rows):
        reg.add(f"{osc}.osc_y0", "clock", y0, sigmas[0], owner=osc, oscillator="y0", t_ref=t_ref)
        reg.add(f"{osc}.osc_y1", "clock", y1, sigmas[1], owner=osc, oscillator="y1", t_ref=t_ref)
    tx = rows["station_tx"] if "station_tx" in rows else ()
    tracking = (set(rows["station_rx"]) | set(tx)) - {""}
    for st in sorted(tracking & set(setup.station_position_sigma)):
        for axis in "xyz":
            reg.add(f"station.{st}.{axis}", "station", 0.0, setup.station_position_sigma[st], owner=st, axis=axis)
    if setup.station_sigma is not None:
        stations = sorted(tracking - set(setup.station_position_sigma))
        for st in stations:
            for axis in "xyz":
                reg.add(f"station.{st}.{axis}", "station", 0.0, setup.station_sigma, owner=st, consider=True,
                        axis=axis)
    if setup.media_sigma is not None:
        reg.add("media_scale", "media", 0.0, setup.media_sigma, consider=True)
    return reg


def _bias_apriori(setup: ArcSetup, observable: str, station) -> float:
    a = setup.bias_apriori
    return float(a.get(f"{observable}:{station}", a.get(observable, 0.0)))


class ReferenceChain:
    """One spacecraft's reference over ``[t0, t1]`` (TDB s) from consecutive segments: ``state(t)`` (N, 6)
    m, m/s relative to ``center``, from the segment whose span holds ``t`` (before its start: the first
    one's look-back); ``n_eval`` force evaluations."""

    def __init__(self, starts, trajectories, t0: float, t1: float):
        self.starts, self.trajectories = np.asarray(starts, float), list(trajectories)
        self.center = self.trajectories[0].center
        self.t0, self.t1 = float(t0), float(t1)
        self.n_eval = sum(tr.n_eval for tr in self.trajectories)

    def state(self, t) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, float))
        k = np.clip(np.searchsorted(self.starts, t, "right") - 1, 0, len(self.trajectories) - 1)
        order = np.argsort(k, kind="stable")   # each segment's epochs as one slice
        bounds = np.searchsorted(k[order], np.arange(len(self.trajectories) + 1))
        out = np.empty((t.size, 6))
        for j in np.flatnonzero(np.diff(bounds)):
            at = order[bounds[j]:bounds[j + 1]]
            out[at] = self.trajectories[j].state(t[at])
        return out


def a_priori_reference(setup: ArcSetup, shared: dict) -> ReferenceChain:
    """The a priori reference over the arc (every parameter at its a priori value, designed maneuvers
    applied: at a maneuver epoch the state after the burn), integrated segment by segment as the fit's
    first pass flies it, into ``shared``: ``fit_arc(..., shared=shared)`` then starts from these
    integrations instead of integrating again. For the geometry of the rows before they are edited."""
    reg = build_registry(setup, pd.DataFrame(columns=["observable", "unit", "station_rx", "station_tx",
                                                      "pass_id"]))
    grid, _ = build_grid(reg, setup.start, setup.end, setup.block)
    problem = TrackingProblem(reg, pd.DataFrame(), np.zeros(0), {setup.spacecraft: setup.force_model},
                              setup.measurements, setup.start, setup.end, setup.lookback, epochs=grid,
                              shared=shared, coarse=setup.coarse_integration, **setup.integration)
    problem.set_coarse(len(setup.sigma_scale) > 1)   # as the fit flies its first pass
    starts, trajs = [], []
    t, x = setup.start, reg.apriori
    while t < setup.end:
        seg = problem.segment(t, x)
        starts.append(seg.a)
        trajs.append(seg.trajs[setup.spacecraft])
        x, _ = problem.transition(t, seg.b, x)
        t = seg.b
    # its span starts with the first segment's look-back: an arc's first count window may open before the arc
    return ReferenceChain(starts, trajs, setup.start - setup.lookback, setup.end)


def fit_arc(table: pd.DataFrame, setup: ArcSetup, shared: dict | None = None) -> ArcSolution:
    """Fit the arc; see :class:`ArcSetup` and :class:`ArcSolution`.

    Residual table columns: row (index in ``table``), epoch, observable, station_rx, pass_id,
    time (TDB s), unit (the row's, when the table has one), apriori (observed - computed on the a
    priori reference: the first iteration's pre-fit residual, row units), prefit/postfit (row units,
    last iteration), to_los (m or m/s per unit), apriori_los/prefit_los/postfit_los, sigma (row units, after reweighting), flags (Flag.RESIDUAL when
    edited by the fit), status (why a row could not be computed; such rows are not fitted).
    ``shared``: reference segments already integrated for this arc (:func:`a_priori_reference`).
    """
    if setup.outward is not None:
        from .outward import fit_outward  # it fits windows of this arc through this function

        return fit_outward(table, setup)
    rows, times = select_rows(table, setup)
    reg = build_registry(setup, rows)
    options = FitOptions(max_iter=setup.max_iter, block=setup.block, edit_k=tuple(setup.edit_k),
                         reweight=setup.reweight, sigma_scale=tuple(setup.sigma_scale),
                         output_at_measurements=setup.measurement_epochs,
                         edit_against_reference=setup.edit_against_reference, tol_dx=setup.tol_dx)
    grid, _ = build_grid(reg, setup.start, setup.end, options.block, options.extra_epochs)

    meas = setup.measurements
    if setup.tabulate_earth_rotation and meas.gcrs_to_itrs is not None:
        span = (setup.start - setup.lookback - 3600.0, setup.end + 3600.0)
        meas = spanning(meas, *span)

    shared = {} if shared is None else shared

    def problem_for(r, t):
        prob = TrackingProblem(reg, r, t, {setup.spacecraft: setup.force_model}, meas, setup.start, setup.end,
                               setup.lookback, epochs=grid, shared=shared, coarse=setup.coarse_integration,
                               **setup.integration)
        prob.set_coarse(len(options.sigma_scale) > 1)   # as the fit flies its first pass
        return prob

    problem = problem_for(rows, times)
    computed, to_los, status = problem.reference(reg.apriori)
    good = status == ""
    if not good.all():
        problem = problem_for(rows[good], times[good])
    used = rows[good]
    # angle rows: sigma and value in rad; others along the line of sight (a sigma <= 0 is the config's, and edited)
    sig = data_sigma(used, setup.data_sigma) / np.abs(np.where(used["unit"] == "rad", 1.0, to_los[good]))
    group = (used["observable"] + ":" + used["station_rx"].astype(str)).to_numpy(object)
    obs = Observations(times[good], used["value"].to_numpy(float), sig, group)
    grown, history = None, []
    for end in growing_ends(setup):  # unstable orbits: reach the full arc through shorter ones
        grown = fit(problem, obs, setup.start, end, replace(options, edit_k=(np.inf,)),
                    x_ref=None if grown is None else grown.x0, earlier=grown)
        history += labelled([{**h, "window": (setup.start, end)} for h in grown.history], "growing arc")
    sol = fit(problem, obs, setup.start, setup.end, options, x_ref=None if grown is None else grown.x0,
              earlier=grown)
    sol.history = history + sol.history   # every fit's iterations (odpipe.od.outward.iteration_stages)
    return _solution(setup, reg, problem, sol, rows, times, to_los, status, rows["value"].to_numpy(float) - computed)


def growing_ends(setup: ArcSetup) -> list[float]:
    """Ends (TDB s) of the shorter arcs fitted first: ``growing_days``, doubling, below the arc's end, and
    again from every maneuver inside the arc.

    Over a long arc of an unstable orbit (libration orbits) an a priori a kilometre off is far outside the
    linear regime at the arc's end; each fit starts from the previous one's smoothed epoch estimate and
    the original a priori, so nothing is counted twice. A burn known to its a priori sigma (10 mm/s, Table
    4.1) leaves the orbit after it as uncertain as at an arc's start: the doubling restarts there, so no
    window ends hours after a burn and is then extrapolated days past it.
    """
    if not setup.growing_days:
        return []
    d0 = setup.growing_days * SECONDS_PER_DAY
    burns = sorted({m.epoch for m in setup.maneuvers if setup.start < m.epoch < setup.end})
    starts = [setup.start] + burns
    ends = []
    for a, b in zip(starts, starts[1:] + [setup.end]):
        d = d0
        while a + d < min(b, setup.end - 0.5 * d):
            ends.append(a + d)
            d *= 2.0
    return ends


def _solution(setup, reg, problem, sol, rows, times, to_los, status, apriori) -> ArcSolution:
    st = reg.slice("state", setup.spacecraft)
    good = status == ""
    res = pd.DataFrame({"row": rows.index.to_numpy(), "epoch": rows["epoch"].to_numpy(),
                        "observable": rows["observable"].to_numpy(), "station_rx": rows["station_rx"].to_numpy(),
                        "pass_id": rows["pass_id"].to_numpy(), "time": times, "to_los": to_los,
                        "status": status})
    res.insert(4, "band", downlink_bands(rows))
    if "unit" in rows:
        res.insert(4, "unit", rows["unit"].astype(str).to_numpy())
    res["apriori"] = np.where(good, apriori, np.nan)
    for col in ("prefit", "postfit", "sigma", "innovation", "innovation_sigma"):
        res[col] = np.nan
        res.loc[good, col] = sol.residuals[col].to_numpy()
    res["apriori_los"] = res["apriori"] * res["to_los"]
    res["prefit_los"] = res["prefit"] * res["to_los"]
    res["postfit_los"] = res["postfit"] * res["to_los"]
    res["flags"] = 0
    edited = np.zeros(len(res), bool)
    edited[good] = (sol.residuals["flags"].to_numpy() & EDIT_INNOVATION) != 0
    res.loc[edited, "flags"] = int(Flag.RESIDUAL)
    nonfinite = np.zeros(len(res), bool)
    nonfinite[good] = (sol.residuals["flags"].to_numpy() & NONFINITE) != 0
    res.loc[nonfinite, "flags"] |= int(Flag.NONFINITE)
    est = sol.parameters()
    params = pd.DataFrame({"name": reg.names, "kind": [p.kind for p in reg.parameters], "apriori": reg.apriori,
                           "estimate": est["estimate"].to_numpy(), "sigma": est["sigma"].to_numpy()})
    return ArcSolution(setup.spacecraft, sol.grid, sol.smoothed_x[:, st], sol.smoothed_P_consider[:, st, st],
                       params, maneuver_table(reg, sol.x0, sol.P0), res, sol.history, sol.converged, sol, reg,
                       problem)
