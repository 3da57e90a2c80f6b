"""Run configuration (``runs/NAME.toml``): the schema, checked strictly.

Times are UTC ISO strings; relative paths resolve against the config's folder;
units are SI (m, m/s, s, m²) unless a key says otherwise (``*_deg``).
Unknown keys, wrong types, missing required keys and bad values (a time that
does not exist, an end before the start, a sigma or step that is not positive
and finite, a data file that is missing, unreadable or not recognised, a run
name that would leave the output folder) are found at load, all of them at
once: one :class:`odpipe.operations.schema.ConfigError` names the file and each key
with its line.
"""

from __future__ import annotations

import functools
import importlib
import re
import typing
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from odpipe.estimation.fit import FitOptions
from odpipe.measurements.bands import ONE_WAY_SCALE, band_name
from odpipe.od.arc import DATA_SIGMA, ArcSetup
from odpipe.operations.schema import (at_least, between, checked, file_name, finite, internal, load, positive,
                                      read_toml, readable, readable_files)


@functools.cache
def tracking_readers() -> tuple[str, ...]:
    """The reader modules of :mod:`parsers.formats` whose ``read`` returns TrackingData."""
    from parsers import formats
    from parsers.table import TrackingData

    return tuple(n for n in formats.available()
                 if typing.get_type_hints(importlib.import_module(n).read).get("return") is TrackingData)


def utc_time(value: str) -> list[tuple[str, str]]:
    """Check: a UTC ISO time (``YYYY-MM-DD[THH:MM:SS[.fff]]``) that exists."""
    if not re.match(r"^\d{4}-\d{2}-\d{2}", value):
        return [("", f"{value!r} is not a UTC ISO time (YYYY-MM-DDTHH:MM:SS)")]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a 'Z' suffix: numpy warns it drops the zone (UTC here anyway)
            np.datetime64(value, "ns")
    except ValueError as exc:
        return [("", f"{value!r} is not a valid time: {str(exc).split(' in datetime string')[0].lower()}")]
    return []


def _utc(value: str) -> np.datetime64:
    return np.datetime64(value.rstrip("Z"), "ns")


def _recognised(path: Path, readers: tuple[str, ...], what: str) -> str | None:
    """Why ``path`` is not a readable file that one of ``readers`` recognises (modules without a
    ``sniff`` are taken on trust), or None."""
    from parsers import formats  # pandas, only when a configuration is checked (not for `odpipe --help`)

    why = readable(path)
    if why:
        return why
    if path.suffix == ".parquet" and what == "tracking":
        with open(path, "rb") as f:
            return None if f.read(4) == b"PAR1" else f"{path} is not a Parquet file"
    sniffing = [r for r in readers if r in formats.available()]
    if len(sniffing) < len(readers):
        return None
    found = formats.detect(path)
    if found in readers:
        return None
    return f"{path} is not a {what} file (" + (f"recognised as {found})" if found else
                                                "no reader recognises it)")


def _data_sigmas(value: dict) -> list[tuple[str, str]]:
    """Check: each data_sigma entry a positive number, or for an angle observable a positive angle with its unit."""
    from odpipe.od.arc import sigma_value  # the fit's own reading of the entries (imports numerics: only when checked)

    out = []
    for key, v in value.items():
        try:
            s = sigma_value(key, v)
        except ValueError as exc:
            out.append((f".{key}", str(exc)))
            continue
        if not (s > 0 and np.isfinite(s)):
            out.append((f".{key}", f"{v!r} must be positive and finite"))
    return out


def _files_of(readers, what: str):
    """Check: a path (or every path of a list) is a readable file of one of ``readers()``."""
    return lambda paths: [("", why) for p in (paths if isinstance(paths, list) else [paths])
                          if (why := _recognised(p, readers(), what))]


@dataclass
class RunSection:
    name: str = checked(file_name)  # a plain folder name (no '/', '..'): the run's folder is OUTPUT/NAME
    output: Path = Path("out")  # runs go to OUTPUT/NAME (attempt folders and 'current')


@dataclass
class ArcSection:
    spacecraft: str  # id as the tracking files give it, e.g. "181"
    start: str = checked(utc_time)  # UTC ISO time, e.g. "2012-04-09T04:00:00"
    end: str = checked(utc_time)  # UTC ISO time, after the start

    def problems(self):
        if _utc(self.end) <= _utc(self.start):
            yield "end", f"{self.end} is not after the start {self.start}"


@dataclass
class SinexSection:
    """Stations of a SINEX solution (e.g. ILRS SLRF2014), named by site code ('7090'), added to the catalog."""

    # SINEX with SITE/ID and SOLUTION/ESTIMATE positions (velocities: plate motion from the reference epoch)
    file: Path = checked(_files_of(lambda: ("parsers.sinex",), "SINEX"))
    # SINEX SITE/ECCENTRICITY file: each marker moved to its instrument's reference point
    eccentricities: Path | None = checked(_files_of(lambda: ("parsers.sinex",), "SINEX"), default=None)
    epoch: str | None = checked(utc_time, default=None)  # UTC time choosing solution and eccentricity (none: arc start)


@dataclass
class DataSection:
    # tracking files (globs allowed): any format parsers.formats reads as tracking data, or TrackingTable .parquet
    files: list[Path] = checked(_files_of(tracking_readers, "tracking"))
    # station CSVs added to the default catalog
    stations: list[Path] = checked(readable_files, default_factory=list)
    sinex: SinexSection | None = None  # stations from a SINEX solution (none: catalog and CSVs only)
    # observables fitted; "observable:BAND" keeps only rows of that downlink band (e.g. "doppler_1way:X")
    observables: list[str] = field(default_factory=lambda: ["doppler_2way", "range"])
    errors: Literal["raise", "report"] = "report"  # nightly: report a corrupt record and go on


@dataclass
class CalibrationSection:
    media: bool = True  # false: the table's values are already corrected (or simulated without media)
    # DSN TRK-2-23 troposphere cards (.TRO); without them the DSN seasonal model (or Saastamoinen)
    tro: list[Path] = checked(_files_of(lambda: ("parsers.trk223",), "TRK-2-23"), default_factory=list)
    # DSN TRK-2-23 ionosphere cards (.ION)
    ion: list[Path] = checked(_files_of(lambda: ("parsers.trk223",), "TRK-2-23"), default_factory=list)
    # IONEX maps (TEC -> delay at each leg's frequency), where no .ION card covers
    ionex: list[Path] = checked(_files_of(lambda: ("parsers.ionex",), "IONEX"), default_factory=list)
    smoothing_order: int = checked(at_least(-1), default=10)  # per-pass polynomial; -1 = none
    # radio troposphere of stations without calibrations (not DSN, not laser): Saastamoinen zenith delays of
    # a standard atmosphere (18 degC) mapped with Niell, or Orekit's modified Saastamoinen on its own (20 degC)
    standard_troposphere: Literal["saastamoinen-niell", "modified-saastamoinen"] = "saastamoinen-niell"


@dataclass
class EditWindowSection:
    """Rows the analyst removes (flag USER), with the reason on record: tagged in [start, end] (UTC),
    optionally only one receiving station and observable."""

    start: str = checked(utc_time)  # UTC ISO time, first tag removed
    end: str = checked(utc_time)  # UTC ISO time, last tag removed
    reason: str  # why the rows are removed (what shows they are wrong), kept in the configuration
    station_rx: str = ""  # e.g. "DSS-14"; empty: every station
    observable: str = ""  # e.g. "range"; empty: every observable

    def problems(self):
        if _utc(self.end) < _utc(self.start):
            yield "end", f"{self.end} is before the start {self.start}"
        if not self.reason.strip():
            yield "reason", "say why the rows are removed"


@dataclass
class UplinkEpochSection:
    """Range rows tagged in [start, end] (UTC) read the uplink phase ``into_ramp_s`` s into the ramp record
    holding their tag (``uplink_epoch`` of :func:`odpipe.measurements.dsn.dsn_range`); rows tagged earlier in
    their record are removed (flag USER). MESSENGER's odf07155: docs/validation.md."""

    start: str = checked(utc_time)  # UTC ISO time, first tag
    end: str = checked(utc_time)  # UTC ISO time, last tag
    reason: str  # what shows the rows read the uplink phase there, kept in the configuration
    into_ramp_s: float = checked(positive)  # s after the start of the ramp record (measured per file: 599 in odf07155)
    station_rx: str = ""  # e.g. "DSS-14"; empty: every station

    problems = EditWindowSection.problems


@dataclass
class PreprocessSection:
    count_time: float = checked(positive, default=60.0)  # s, Doppler compression target
    # compressed windows cut short (gaps, ramp segments): keep them, flag them, or drop them
    partial: Literal["keep", "flag", "drop"] = "keep"
    elevation_mask_deg: float = checked(between(-90.0, 90.0), default=10.0)  # deg, at the receiving station
    blunder_k: float = checked(positive, default=10.0)  # robust sigmas of a pass's detrended values: BLUNDER
    # robust sigmas of a pass's a priori residuals, detrended the same way: BLUNDER (none: not tested)
    apriori_blunder_k: float | None = checked(positive, default=None)
    # robust sigmas of a raw Doppler series' fourth differences: its first samples before they settle within
    # them (a receiver lock transient, within 60 s of the series' start) are BLUNDER (none: not tested)
    lock_transient_k: float | None = checked(positive, default=None)
    min_pass_samples: int = checked(at_least(1), default=10)  # passes with fewer rows are flagged SHORT_PASS
    edit_windows: list[EditWindowSection] = field(default_factory=list)  # analyst edits (flag USER), each with its reason
    range_uplink_epoch: list[UplinkEpochSection] = field(default_factory=list)  # range read at an earlier uplink phase


@dataclass
class GravitySection:
    body: str  # the field's body, e.g. "moon" or "earth"
    file: Path = checked(readable_files)  # ICGEM, GMAT .cof, PDS SHADR, EGM or plain-table field
    degree: int = checked(at_least(0))  # degree and order evaluated
    partial_degree: int | None = checked(at_least(0), default=None)  # degree of the STM partials (none: degree)
    # UTC time at which an ICGEM field's time-variable terms (gfct, trnd, acos, asin) are taken (none: arc start)
    epoch: str | None = checked(utc_time, default=None)


@dataclass
class CylinderSection:
    radius: float = checked(positive)  # m
    length: float = checked(positive)  # m
    rho_s: float = checked(between(0.0, 1.0), default=0.0)  # specular reflectivity
    rho_d: float = checked(between(0.0, 1.0), default=0.0)  # diffuse reflectivity
    axis: str | list[float] = "sun"  # spin axis: ICRF unit vector or 'sun'


@dataclass
class SrpSection:
    cr_area: float = checked(at_least(0.0), default=0.0)  # Cr·A, m² (cannonball)
    cylinder: CylinderSection | None = None  # a spin-stabilised cylinder instead of the cannonball
    occulters: list[str] = field(default_factory=lambda: ["earth", "moon"])  # bodies casting shadows (conical)


@dataclass
class DragSection:
    """Atmospheric drag in an atmosphere co-rotating with the Earth (Earth-centred only): Harris-Priester
    density (mean solar activity) or NRLMSISE-00 with F10.7 and Ap from a space-weather file."""

    cd: float = checked(finite)  # drag coefficient (the a priori when estimation.cd_sigma is set)
    area: float = checked(positive)  # m², cross-section
    n_bulge: float = checked(positive, default=6.0)  # Harris-Priester cosine exponent: 2 low, 6 high inclinations
    atmosphere: Literal["harris_priester", "nrlmsise00"] = "harris_priester"  # density model (nrlmsise00 evaluated below 1500 km)
    space_weather: Path | None = checked(readable_files, default=None)  # nrlmsise00: F10.7/Ap, MSFC MSAFE table or CelesTrak CSSI file
    solar_activity_level: Literal["95%", "50%", "5%"] = "50%"  # the MSAFE table's percentile columns used
    # nrlmsise00: its Ap history (3-hourly Ap of a CSSI file; an MSAFE table's Ap seven times) for the daily Ap
    ap_history: bool = False

    def problems(self):
        if self.atmosphere == "nrlmsise00" and self.space_weather is None:
            yield "space_weather", "atmosphere = \"nrlmsise00\" needs a space_weather file"


@dataclass
class PolynomialAccelerationSection:
    """A constant plus a linear drift along the ICRF axes, a = c0 + c1 (t - epoch): e.g. a propellant leak."""

    epoch: str | None = checked(utc_time, default=None)  # UTC ISO reference time (none: initial_state.epoch, else arc.start)
    c0: list[float] = checked(finite, default_factory=lambda: [0.0, 0.0, 0.0])  # m/s², x y z (the a priori when estimated)
    c1: list[float] = checked(finite, default_factory=lambda: [0.0, 0.0, 0.0])  # m/s³, x y z (the a priori when estimated)

    def problems(self):
        for name in ("c0", "c1"):
            if len(getattr(self, name)) != 3:
                yield name, "expected 3 components (x, y, z)"


@dataclass
class DynamicsSection:
    center: str  # central body of the integration, e.g. "earth", "moon", "ssb"
    ephemeris: str = "de440"  # 'de440', 'de421' or a .bsp path
    third_bodies: list[str] = field(default_factory=list)  # point masses, e.g. ["sun", "moon"]
    gravity: list[GravitySection] = field(default_factory=list)  # spherical-harmonic fields ([[dynamics.gravity]])
    srp: SrpSection | None = None  # solar radiation pressure (none: off)
    drag: DragSection | None = None  # atmospheric drag (none: off)
    polynomial_acceleration: PolynomialAccelerationSection | None = None  # inertial polynomial acceleration (none: off)
    mass: float = checked(positive, default=1000.0)  # kg
    relativity: bool = False  # the central body's post-Newtonian term

    def problems(self):
        if self.drag is not None and self.center.lower() != "earth":
            yield "drag", f"drag needs center = \"earth\", not {self.center!r}"


@dataclass
class MeasurementsSection:
    """Corrections of the measurement models that belong to the spacecraft or the stations' antennas."""

    # m: the ranging reflector (or antenna) this far ahead of the centre of mass towards the stations
    # (LAGEOS 0.251): every range is that much shorter
    com_offset: float = checked(finite, default=0.0)
    # m: a fixed bias added to every range (transponder delay; Orekit's onboard.range.bias), not estimated
    onboard_range_bias: float = checked(finite, default=0.0)
    # angle_el rows are apparent elevations: the free-space one bent by the ITU-R P.834 refraction at the
    # station's height
    elevation_refraction: bool = False
    # stations displaced by the solid Earth tide (IERS 2010 §7.1.1; conventional tide free coordinates)
    station_tides: bool = False
    # BLQ ocean-loading coefficients: stations named like a site (or its part before '/') displaced (§7.1.2)
    ocean_loading: Path | None = checked(readable_files, default=None)


@dataclass
class DopplerAprioriSection:
    """How the a priori orbit is found in the arc's two-way Doppler (lunar orbiters; ``odpipe apriori``)."""

    station: str | None = None  # receiving station used (none: the one with most 60-s points in the first 8 h)
    span_hours: float = checked(positive, default=5.5)  # h of that station's Doppler used
    degree: int = checked(at_least(2), default=12)  # degree of the central body's field in the search


@dataclass
class FlybyAprioriSection:
    """How the a priori orbit is found in the arc's two-way Doppler and a flyby's epoch, for a spacecraft in
    cruise towards a planet (:mod:`odpipe.od.flyby_apriori`); its epoch is the first Doppler point's."""

    body: str  # the planet flown by, e.g. "venus" (its gm and ephemeris from dynamics.ephemeris)
    epoch: str = checked(utc_time)  # UTC ISO time of closest approach (published), e.g. "2007-06-05T23:08:00"
    # point masses perturbing the approach in the search (the run's full force model takes over after it)
    perturbers: list[str] = field(default_factory=lambda: ["sun", "earth", "mercury", "jupiter"])


@dataclass
class InitialStateSection:
    """The a priori state at ``epoch``: given (``state``) or read from an OEM (``from_oem``), e.g. the
    previous arc's ``OUTPUT/NAME/current/trajectory.oem`` (a nightly chain; ``odpipe batch`` runs
    that arc first, so the file need not exist when the configuration is loaded)."""

    epoch: str | None = checked(utc_time, default=None)  # UTC ISO time of the state (from_doppler/from_flyby: none)
    state: list[float] | None = None  # m, m/s, ICRF axes about dynamics.center
    from_oem: Path | None = None  # OEM whose state at epoch is the a priori (e.g. the previous arc's)
    # find the a priori orbit in the arc's own two-way Doppler (odpipe apriori); its epoch is the data's
    from_doppler: DopplerAprioriSection | None = None
    # find it in the arc's own two-way Doppler and a planetary flyby's epoch; its epoch is the data's
    from_flyby: FlybyAprioriSection | None = None
    # axes of ``state``: "ICRF" (GCRS about the Earth) or "EME2000" (mean equator and equinox of J2000,
    # turned to ICRF by the IAU 2006 frame bias)
    frame: Literal["ICRF", "EME2000"] = "ICRF"

    def problems(self):
        if sum(x is not None for x in (self.state, self.from_oem, self.from_doppler, self.from_flyby)) != 1:
            yield "", "give one of state, from_oem, from_doppler or from_flyby"
        elif self.state is not None and (len(self.state) != 6 or not np.all(np.isfinite(self.state))):
            yield "state", "needs 6 finite numbers (m, m/s)"
        if self.epoch is None and self.from_doppler is None and self.from_flyby is None:
            yield "epoch", "required key is missing"
        if self.frame != "ICRF" and self.state is None:
            yield "frame", "only a given state takes a frame (an OEM names its own; from_doppler is ICRF)"


@dataclass
class StochasticSection:
    sigma: float = checked(positive)  # m/s², steady state, per RTN axis
    tau: float = checked(at_least(0.0))  # s (0 = white per batch)
    batch: float = checked(positive)  # s


@dataclass
class OutwardSection:
    """Fit outward from the a priori epoch: first the rows within ``first_hours`` of initial_state.epoch,
    then windows ``factor`` times wider, each from the last one's estimate (with the a priori sigmas),
    until the whole arc is fitted. For an a priori good at its epoch but far from the data's start (an
    orbit propagated days back is kilometres off and the whole arc at once does not converge)."""

    first_hours: float = checked(positive, default=12.0)  # h either side of the a priori epoch fitted first
    factor: float = checked(between(1.01, 100.0), default=2.0)  # each next window this many times wider


def _bands(value: dict) -> list[tuple[str, str]]:
    """Each key a downlink band name."""
    return [(f".{k}", f"{k!r} is not a band ({', '.join(ONE_WAY_SCALE)})") for k in value
            if band_name(k) not in ONE_WAY_SCALE]


def _oscillator_sigmas(value) -> list[tuple[str, str]]:
    """[y0, y1] positive, or {band: [y0, y1]}."""
    pairs = value.items() if isinstance(value, dict) else [("", value)]
    out = _bands(value) if isinstance(value, dict) else []
    for band, pair in pairs:
        where = f".{band}" if band else ""
        out += [(where + w, r) for w, r in positive(pair)]
        if len(pair) != 2:
            out.append((where, f"{pair!r} must be two sigmas: [y0, y1 (1/s)]"))
    return out


def _angles(value, positive_only: bool = False) -> list[tuple[str, str]]:
    """Check: an angle (a number in rad, or a string with its unit) or each of a table, finite (and > 0)."""
    from odpipe.od.arc import sigma_value  # the fit's own reading of angles (imports numerics: only when checked)

    out = []
    for key, v in (value.items() if isinstance(value, dict) else [("", value)]):
        where = f".{key}" if key else ""
        try:
            x = sigma_value("angle_", v)
        except ValueError as exc:
            out.append((where, str(exc)))
            continue
        if not (np.isfinite(x) and (x > 0 or not positive_only)):
            out.append((where, f"{v!r} must be {'positive and ' if positive_only else ''}finite"))
    return out


@dataclass
class EstimationSection:
    sigma_position: float = checked(positive, default=ArcSetup.sigma_position)  # m, a priori, per axis
    sigma_velocity: float = checked(positive, default=ArcSetup.sigma_velocity)  # m/s, a priori, per axis
    srp_scale_sigma: float | None = checked(positive, default=ArcSetup.srp_scale_sigma)  # a priori sigma of the SRP scale (none: fixed)
    stochastic: StochasticSection | None = None  # Gauss-Markov RTN accelerations (none: off)
    # LOS sigma (m, m/s) by "observable", "observable:band" (downlink band, e.g. "doppler_1way:S") or
    # "observable:station" (the station's entry wins, then the band's); angle observables:
    # the angle's own sigma, a number in rad or a string with its unit ("0.01 deg", "36 arcsec", "1e-4 rad")
    data_sigma: dict[str, float | str] = checked(lambda v: _data_sigmas(v),
                                                 default_factory=lambda: dict(DATA_SIGMA))
    # m, a per-pass range bias (none: not estimated)
    range_bias_sigma: float | None = checked(positive, default=ArcSetup.range_bias_sigma)
    # one range bias per pass and station, or one per station over the arc (SLR, Orekit's station biases)
    range_bias_per: Literal["pass", "station"] = ArcSetup.range_bias_per
    # receiving stations whose ranges get biases, e.g. ["YARL"] (none: every station's)
    range_bias_stations: list[str] | None = None
    # m per ITRS axis, a priori 0: stations whose coordinates are estimated, e.g. { YARL = 1.0 } (Orekit's
    # estimated station offsets); stations without rows in the arc are left out
    station_position_sigma: dict[str, float] = checked(positive, default_factory=dict)
    # m, a priori range bias by receiving station (the others 0), e.g. { Fucino = 13468.956 }
    range_bias_apriori: dict[str, float] = checked(finite, default_factory=dict)
    # a priori sigma of one constant bias per station and angle observable: rad, or with its unit ("0.5 deg")
    angle_bias_sigma: float | str | None = checked(lambda v: _angles(v, positive_only=True), default=None)
    # a priori angle biases by "observable:station" or "observable" (the station's entry wins): rad or with
    # its unit, e.g. { angle_az = "0.01 deg" } (the others 0)
    angle_bias_apriori: dict[str, float | str] = checked(_angles, default_factory=dict)
    cd_sigma: float | None = checked(positive, default=None)  # a priori sigma of the drag Cd (none: fixed)
    # a priori sigmas of the polynomial acceleration's c0 (m/s²) and c1 (m/s³), each axis (none: fixed)
    polynomial_sigma: list[float] | None = checked(positive, default=None)
    # m/s, a per-pass two-way Doppler bias (none: not estimated; odpipe.analysis.station_diagnostics)
    doppler_bias_sigma: float | None = checked(positive, default=ArcSetup.doppler_bias_sigma)
    # s, a time-tag offset per receiving station, tags late, relative to the station with the most rows (none: not estimated)
    station_time_offset_sigma: float | None = checked(positive, default=ArcSetup.time_offset_sigma)
    # one-way Doppler's oscillator, estimated when set: a priori sigmas of its fractional frequency offset y0
    # (1) and drift y1 (1/s) about the arc start (a priori 0: the rows' reference): [y0, y1] one oscillator
    # for every band it drives, or a table by downlink band, e.g. { X = [1e-6, 1e-12], S = [1e-5, 1e-10] },
    # one oscillator per band named (the other bands' one-way rows get no oscillator terms)
    oscillator_sigma: list[float] | dict[str, list[float]] | None = checked(lambda v: _oscillator_sigmas(v),
                                                                            default=None)
    # by downlink band, "pass": that band's oscillator re-estimated every pass, about the pass's mid-time (an
    # oscillator re-tuned at each acquisition, e.g. a transponder's auxiliary one), e.g. { S = "pass" };
    # "arc" (default): one over the arc
    oscillator_per: dict[str, Literal["arc", "pass"]] = checked(lambda v: _bands(v), default_factory=dict)
    # planned maneuvers (parsers.maneuvers schema)
    maneuver_plan: Path | None = checked(_files_of(lambda: ("parsers.maneuvers",), "maneuver plan"), default=None)
    # s: estimate planned burns' epochs (a plan's sigma_time wins)
    maneuver_epoch_sigma: float | None = checked(positive, default=None)
    # innovation editing threshold (sigmas) per iteration, the last repeated; inf edits nothing
    edit_k: list[float] = checked(lambda v: positive(v, allow_inf=True),
                                  default_factory=lambda: list(FitOptions.edit_k))
    max_iter: int = checked(at_least(1), default=FitOptions.max_iter)  # filter-smoother iterations at most
    reweight: bool = FitOptions.reweight  # data weights from each station's post-fit RMS (the ARTEMIS practice); see README
    # data-weight stages multiplying every sigma, loose to tight (e.g. [30, 5, 1]): the next stage starts once
    # the epoch correction is below 1 sigma, so a far-off a priori is not fitted at full weight at once
    sigma_scale: list[float] = checked(positive, default_factory=lambda: list(FitOptions.sigma_scale))
    block: float = checked(positive, default=FitOptions.block)  # s, filter grid step
    # converged when the epoch correction of an exact pass is below this many sigma (the products apply
    # that last correction to first order)
    tol_dx: float = checked(positive, default=FitOptions.tol_dx)
    reference_rtol: float | None = checked(positive, default=None)  # relative tolerance of the fit's exact references (none: 1e-12)
    reference_atol: float | None = checked(positive, default=None)  # m, m/s: their absolute tolerance (none: 1e-6)
    # relative tolerance of the references of the loose-weight stages (every sigma_scale stage but the last; none: 1e-9)
    coarse_rtol: float | None = checked(positive, default=None)
    coarse_atol: float | None = checked(positive, default=None)  # m, m/s: their absolute tolerance (none: 1e-5)
    # every measurement epoch on the filter grid too: one update per epoch, so the innovations are a
    # sequential filter's, measurement by measurement (Orekit's Kalman); false: the rows of a block at once
    measurement_epochs: bool = FitOptions.output_at_measurements
    # edit a row only when it misses the last smoothed solution as well as the filter's prediction (arcs across
    # burns with unmodelled accelerations after them); false: the innovation test alone (a far-off start)
    edit_against_reference: bool = FitOptions.edit_against_reference
    # unlogged maneuvers: the filter's innovations are always tested (findings in the report); with a sigma
    # (m/s per axis) each finding also becomes an estimated impulsive maneuver and the arc is fitted again
    detected_maneuver_sigma: float | None = checked(positive, default=None)
    outward: OutwardSection | None = None  # fit outward from the a priori epoch (none: the whole arc at once)

    def problems(self):
        for key in self.angle_bias_apriori:
            if key.split(":")[0] not in ("angle_az", "angle_el", "angle_x", "angle_y"):
                yield f"angle_bias_apriori.{key}", "not an angle observable (angle_az, angle_el, angle_x, angle_y)"
        if not self.sigma_scale:
            yield "sigma_scale", "needs at least one stage"
        if not self.edit_k:
            yield "edit_k", "needs at least one value"


@dataclass
class ProductsSection:
    oem: bool = True  # write trajectory.oem (CCSDS OEM with covariance)
    spk: bool = True  # write trajectory.bsp (SPK type 13)
    naif_id: int = -999  # the SPK's body id
    object_name: str = ""  # OEM OBJECT_NAME (default: the spacecraft id)
    step: float = checked(positive, default=60.0)  # s between trajectory product states
    plots: bool = True  # residual plots per station and observable


@dataclass
class RunConfig:
    run: RunSection
    arc: ArcSection
    data: DataSection
    dynamics: DynamicsSection
    initial_state: InitialStateSection
    calibration: CalibrationSection = field(default_factory=CalibrationSection)
    measurements: MeasurementsSection = field(default_factory=MeasurementsSection)
    preprocess: PreprocessSection = field(default_factory=PreprocessSection)
    estimation: EstimationSection = field(default_factory=EstimationSection)
    products: ProductsSection = field(default_factory=ProductsSection)
    path: Path | None = internal(None)  # the file read (set by load_config)
    text: str = internal("")  # its text

    def problems(self):
        est = self.estimation
        if est.cd_sigma is not None and self.dynamics.drag is None:
            yield "estimation.cd_sigma", "needs [dynamics.drag] (no drag to estimate a Cd of)"
        if est.polynomial_sigma is not None:
            if self.dynamics.polynomial_acceleration is None:
                yield "estimation.polynomial_sigma", "needs [dynamics.polynomial_acceleration]"
            if len(est.polynomial_sigma) != 2:
                yield "estimation.polynomial_sigma", "expected 2 sigmas: [c0 m/s², c1 m/s³]"
        if est.outward is not None and self.initial_state.epoch is None:
            yield "estimation.outward", "needs initial_state.epoch (the fit grows outward from it)"
        if est.angle_bias_apriori and est.angle_bias_sigma is None:
            yield "estimation.angle_bias_apriori", "needs estimation.angle_bias_sigma (biases are not estimated)"


def load_config(path) -> RunConfig:
    """Read and check a run configuration file: one ConfigError lists every problem (key and line)."""
    path = Path(path).resolve()
    data, text = read_toml(path)
    cfg = load(RunConfig, data, path, text=text)
    cfg.path, cfg.text = path, text
    return cfg


def reference() -> str:
    """The run configuration reference (Markdown), generated from the classes above."""
    from odpipe.operations.reference import markdown

    return markdown(RunConfig, "Run configuration reference", skip=("path", "text"))
