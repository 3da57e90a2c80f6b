"""A simulated case description (TOML), e.g. ``runs/artemis_p2_like.toml``: the schema, checked strictly.

SI units unless a key says otherwise; times are UTC ISO 8601. The sections are dataclasses that
:mod:`odpipe.operations.schema` loads: an unknown key, a wrong type, a missing required key or a bad
value is a :class:`~odpipe.operations.schema.ConfigError` naming the file, the key and its line.
``odpipe reference`` documents every key (``docs/config.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Literal

import numpy as np

from odpipe.constants import NS_PER_DAY
from odpipe.operations.schema import at_least, checked, finite, load as load_schema, positive, read_toml
from odpipe.pipeline.config import utc_time


def _vector(value: list) -> list[tuple[str, str]]:
    return [] if len(value) == 3 else [("", f"expected 3 components [x, y, z], got {len(value)}")]


def _networks(value: list) -> list[tuple[str, str]]:
    """At least one network, one rule per station."""
    if not value:
        return [("", "at least one [[network]] is required")]
    names = [n.station for n in value]
    return [(f"[{i}].station", f"{name!r} has a rule already") for i, name in enumerate(names) if name in names[:i]]


@dataclass(frozen=True)
class Orbit:
    """A CRTBP libration orbit about L1/L2 (odpipe.simulate.libration), put into the ephemeris' Earth-Moon geometry
    at the start: the planar Lyapunov orbit, started ``z_amplitude`` out of the plane (0: planar)."""

    point: Literal[1, 2]  # Earth-Moon L1 or L2
    amplitude: float = checked(positive)  # CRTBP length units (Earth-Moon distances) Earthward of the point at the start
    z_amplitude: float = checked(at_least(0.0), default=0.0)  # CRTBP length units, z at the start; 0: planar


@dataclass(frozen=True)
class SpacecraftModel:
    """The spacecraft as the truth's force model and the Doppler's spin signature see it: a spinning cylinder."""

    mass_kg: float = checked(positive)  # kg
    radius_m: float = checked(positive)  # m, cylinder radius
    length_m: float = checked(positive)  # m, cylinder length
    rho_s: float = checked(at_least(0.0))  # specular reflectivity
    rho_d: float = checked(at_least(0.0))  # diffuse reflectivity
    spin_axis: list[float] = checked(_vector)  # ICRF direction [x, y, z], fixed
    spin_rpm: float = checked(at_least(0.0), default=0.0)  # revolutions per minute
    antenna_offset_m: float = checked(at_least(0.0), default=0.0)  # m off the spin axis; 0: no spin signature


@dataclass(frozen=True)
class TruthBody:
    """How the real spin-stabilised body differs from the filter's cylinder ([spacecraft_model]), truth only:
    a square bus (spin-averaged: a cylinder of width 4/pi its side) with one-sided top and bottom plates, its
    spin axis tilted from the nominal one by ``axis_tilt_deg`` (one draw of the direction)."""

    bus_side_m: float = checked(positive)  # m, side of the square bus (its length is the model's length_m)
    plate_area_m2: float = checked(at_least(0.0))  # m^2, each of the top and bottom plates (normals +-axis)
    axis_tilt_deg: float = checked(at_least(0.0))  # deg, spin axis off the nominal direction


@dataclass(frozen=True)
class Unmodelled:
    """Truth-only accelerations the filter has no model of: outgassing along the spin axis (exponential decay)
    and a thruster-plume acceleration after every burn (along its delta-v, constant for ``plume_hours``)."""

    outgassing_m_s2: float = checked(at_least(0.0))  # m/s^2 at the start, along the spin axis
    outgassing_tau_days: float = checked(positive)  # d, e-folding time of the outgassing
    plume_fraction: float = checked(at_least(0.0))  # delta-v added by the plume after a burn, fraction of its |dv|
    plume_hours: float = checked(positive)  # h over which the plume delta-v is spread


@dataclass(frozen=True)
class Stochastic:
    """Stochastic accelerations of the truth: piecewise-constant RTN batches, first-order Gauss-Markov."""

    sigma: float = checked(at_least(0.0))  # m/s^2 per RTN axis
    tau_s: float = checked(at_least(0.0))  # s, correlation time; 0: white
    batch_s: float = checked(positive)  # s, batch length


@dataclass(frozen=True)
class StationKeeping:
    """Station-keeping maneuvers, designed at run time for a perpendicular x-z plane crossing
    (odpipe.simulate.stationkeeping)."""

    first_days: float = checked(at_least(0.0))  # d after the start, first maneuver
    every_days: float = checked(positive)  # d between maneuvers
    gap_days: list[float] = checked(positive)  # d from a burn to its x-z crossing, tried in order
    horizon_days: float = checked(positive)  # d, search window past each gap
    # m/s: a design above it is not flown, the next gap is tried (Newton can converge on a far root); none: any
    max_dv_m_s: float | None = checked(positive, default=None)
    # navigation errors of the state the burns are designed on (operations design from OD; none: on the truth,
    # and no draws are made)
    nav_sigma_m: float | None = checked(at_least(0.0), default=None)  # m per ICRF axis
    nav_sigma_m_s: float | None = checked(at_least(0.0), default=None)  # m/s per ICRF axis


@dataclass(frozen=True)
class Maneuver:
    """A maneuver with a given delta-v ([[maneuver]], e.g. attitude burns)."""

    name: str  # label in the maneuver files
    epoch: str = checked(utc_time)  # UTC ISO time
    kind: str  # e.g. "attitude"
    dv: list[float] = checked(lambda v: _vector(v) + finite(v))  # designed delta-v, ICRF m/s
    planned_dv: bool = False  # the maneuver plan carries its delta-v (false: its time only, delta-v 0)


@dataclass(frozen=True)
class Execution:
    """Execution errors of every maneuver, one draw each."""

    sigma_magnitude: float = checked(at_least(0.0))  # fraction of the delta-v
    sigma_pointing_deg: float = checked(at_least(0.0))  # deg, about a random axis normal to the delta-v


@dataclass(frozen=True)
class Media:
    """Media errors: what the simulated TRK-2-23 calibrations deviate from the models by."""

    sigma_wet_m: float = checked(at_least(0.0))  # m, per-day deviation of the zenith wet delay from the DSN model
    sigma_dry_m: float = checked(at_least(0.0))  # m, per-day deviation of the zenith dry delay
    sigma_ion_m: float = checked(at_least(0.0))  # m, S-band line-of-sight range delay scale per DSN pass (.ION cards)
    # calibration errors: the true delays differ from the written cards by a random quadratic per card, RMS m
    # (none: the cards are the truth, and no draws are made)
    error_wet_m: float | None = checked(at_least(0.0), default=None)  # m, zenith wet
    error_dry_m: float | None = checked(at_least(0.0), default=None)  # m, zenith dry
    error_ion_m: float | None = checked(at_least(0.0), default=None)  # m, S-band line of sight


@dataclass(frozen=True)
class Network:
    """A tracking station's rule ([[network]]): on days offset_days + k every_days after the start, passes
    inside the longest visibility above the mask (odpipe.simulate.schedule)."""

    station: str  # station name in the catalog, e.g. "DSS-24"
    format: Literal["trk234", "utdf"] = "trk234"  # the file its data are written to
    pad: int = 0  # UTDF pad id
    band: str = "S"  # up- and downlink band
    uplink_hz: float = checked(positive, default=2.0e9)  # Hz, reference uplink
    every_days: float = checked(positive, default=2.0)  # d between tracking days
    offset_days: float = checked(at_least(0.0), default=0.0)  # d from the start to the first tracking day
    passes: int = checked(at_least(1), default=1)  # passes per tracking day
    pass_s: float = checked(positive, default=12600.0)  # s, pass length
    mask_deg: float = 10.0  # deg, elevation mask
    doppler_count_s: float = checked(positive, default=60.0)  # s, Doppler count time
    sigma_doppler: float = checked(positive, default=1e-4)  # m/s, Doppler noise
    range_step_s: float = checked(at_least(0.0), default=0.0)  # s between range points; 0: no range
    sigma_range: float = checked(positive, default=2.0)  # m, range noise
    range_bias_sigma: float = checked(at_least(0.0), default=0.0)  # m, range bias, one draw per pass
    ramp_rate_sigma: float = checked(at_least(0.0), default=0.0)  # Hz/s, uplink ramp rate per pass; > 0: ramped
    fitted: bool = True  # its data go into the demo's fits (false: simulated and written only)


@dataclass(frozen=True)
class CaseFile:
    """The top level of a case file."""

    name: str  # case name: file stems of the simulated data
    seed: int  # random seed: the same seed gives the same bytes
    start: str = checked(utc_time)  # UTC ISO time
    days: float = checked(positive)  # d, case length
    spacecraft: int  # spacecraft id in the tracking files (DSN id)
    naif_id: int  # NAIF id of the truth SPK (negative)
    orbit: Orbit
    spacecraft_model: SpacecraftModel
    stochastic: Stochastic
    execution: Execution
    media: Media
    station_keeping: StationKeeping
    # tracking stations and their rules ([[network]], at least one)
    network: list[Network] = checked(_networks)
    # maneuvers with a given delta-v, besides the station keeping
    maneuver: list[Maneuver] = field(default_factory=list)
    # the real body's differences from the model (none: the truth flies the model's body)
    truth_body: TruthBody | None = None
    # truth-only accelerations (none: none)
    unmodelled: Unmodelled | None = None


@dataclass(frozen=True)
class Case:
    """A loaded case: the file's sections, times as UTC datetime64[ns], maneuvers in time order as dicts
    (name, epoch, kind, dv: ICRF m/s array, planned: whether the plan carries the delta-v)."""

    name: str
    seed: int
    start: np.datetime64
    days: float
    spacecraft: int
    naif_id: int
    orbit: Orbit
    body: SpacecraftModel
    stochastic: Stochastic
    maneuvers: list
    execution: Execution
    media: Media
    station_keeping: StationKeeping
    networks: tuple = field(default_factory=tuple)
    truth_body: TruthBody | None = None
    unmodelled: Unmodelled | None = None

    @property
    def end(self) -> np.datetime64:
        return self.start + np.timedelta64(int(self.days * NS_PER_DAY), "ns")

    def station_keeping_epochs(self) -> np.ndarray:
        """UTC epochs of the station-keeping maneuvers inside the case span."""
        sk = self.station_keeping
        days = np.arange(sk.first_days, self.days, sk.every_days)
        return self.start + (days * NS_PER_DAY).astype("timedelta64[ns]")

    def shortened(self, days: float) -> "Case":
        """The same case over its first ``days`` (maneuvers after the end dropped)."""
        end = self.start + np.timedelta64(int(days * NS_PER_DAY), "ns")
        return replace(self, days=days, maneuvers=[m for m in self.maneuvers if m["epoch"] < end])


def _utc(value: str) -> np.datetime64:
    return np.datetime64(value.replace("Z", "").replace("+00:00", ""), "ns")


def load(path) -> Case:
    """Read and check a case file: one ConfigError names the file and every wrong key with its line."""
    path = Path(path)
    data, text = read_toml(path)
    f = load_schema(CaseFile, data, path, text=text)
    mans = [{"name": m.name, "epoch": _utc(m.epoch), "kind": m.kind, "dv": np.asarray(m.dv, float),
             "planned": m.planned_dv}
            for m in f.maneuver]
    return Case(f.name, f.seed, _utc(f.start), f.days, f.spacecraft, f.naif_id, f.orbit, f.spacecraft_model,
                f.stochastic, sorted(mans, key=lambda m: m["epoch"]), f.execution, f.media, f.station_keeping,
                tuple(f.network), f.truth_body, f.unmodelled)


def reference() -> str:
    """The case file reference (Markdown), generated from the classes above."""
    from odpipe.operations.reference import markdown

    return markdown(CaseFile, "Simulated case reference (`odpipe simulate CASE`)")
