"""Study configurations (``runs/study_*.toml``): one strict schema per scenario, on the run configs' loader.

``scenario`` names the study (a module of :mod:`odpipe.studies`, a class of :data:`KINDS`); every
other key is checked against that class by :func:`odpipe.operations.schema.load`: an unknown key
(a misspelling, a key of another study), a wrong type or a missing required key is an error that
names the file, the key and its line, all problems at once. Paths are relative to the file that
sets them and must name readable files. ``base = "other.toml"`` starts from that configuration:
tables merge key by key, everything else (values, lists, arrays of tables) is replaced; an error
names the file of the base or of the override that set the key.

The scenario modules read the configuration as plain tables (:func:`load_config`: the checked
dataclasses as dicts, keys left unset omitted, paths as strings).
"""

from __future__ import annotations

import dataclasses
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from odpipe.operations.schema import (ConfigError, Problem, at_least, checked, load, positive, read_toml,
                                      readable_files)

section = dataclass(kw_only=True)  # every section: required keys and keys with defaults in any order
_at_least_zero = at_least(0)


def _gravity_file():
    return field(metadata={"check": readable_files})


# --- shared sections ------------------------------------------------------------------------------------


@section
class Scenario:
    """Every study configuration."""

    scenario: str  # the study: a name of KINDS (a module of odpipe.studies)


@section
class CrosslinkNoise:
    """White noise of the instantaneous crosslink data, 1 sigma."""

    range_m: float = checked(positive)  # m, crosslink range
    range_rate_mps: float = checked(positive)  # m/s, crosslink range-rate


@section
class HaloFamily:
    """A halo family continued in z0 (CRTBP, nondimensional) from a small member; the member of the wanted
    period is picked."""

    x0: float  # guess of x at the first member's x-z crossing
    vy0: float  # guess of vy there
    z_start: float  # z0 of the first member
    z_stop: float  # z0 where the continuation stops
    dz: float = checked(positive, default=0.01)  # continuation step in z0


@section
class HaloByPeriod(HaloFamily):
    """The halo of the given period."""

    period_days: float = checked(positive)  # d, the halo's period


@section
class HaloOverride:
    """Keys of ``[halo]`` that a variant changes (unset: the run's)."""

    period_days: float | None = None  # d, the halo's period
    x0: float | None = None  # guess of x at the first member's x-z crossing
    vy0: float | None = None  # guess of vy there
    z_start: float | None = None  # z0 of the first member
    z_stop: float | None = None  # z0 where the continuation stops
    dz: float | None = None  # continuation step in z0


@section
class GeoOrbit:
    """A circular orbit of one sidereal day about the Earth, in the rotating frame."""

    inclination_deg: float  # deg, to the Earth-Moon plane
    phase_deg: float = 0.0  # deg, argument of latitude at the epoch


@section
class GeoOverride:
    """Keys of ``[geo]`` that a variant changes (unset: the run's)."""

    inclination_deg: float | None = None  # deg, to the Earth-Moon plane
    phase_deg: float | None = None  # deg, argument of latitude at the epoch


@section
class MonteCarlo:
    """Monte Carlo runs of the fit (``odpipe study --runs N --parallel`` override these)."""

    runs: int = checked(_at_least_zero, default=0)  # number of runs (0: none)
    seed: int = 0  # seed of the runs' draws
    parallel: bool = False  # on a local Dask cluster


# --- halo_geo_crtbp: Fujimoto et al. sec. 2.1 ---------------------------------------------------------


@section
class CrtbpUnits:
    """Earth-Moon CRTBP units."""

    length_km: float = checked(positive)  # km, Earth-Moon distance
    gm_earth_km3s2: float = checked(positive)  # km^3/s^2
    gm_moon_km3s2: float = checked(positive)  # km^3/s^2


@section
class HaloGeoFilter:
    """The fit (the truth's CRTBP dynamics)."""

    apriori_pos_m: float = checked(positive)  # m, a priori sigma per axis
    apriori_vel_mps: float = checked(positive)  # m/s, a priori sigma per axis
    deviation_halo: list[float]  # m, m/s: the halo's initial deviation (6)
    deviation_geo: list[float]  # m, m/s: the GEO satellite's initial deviation (6)
    snc_mps2: list[float]  # m/s^2, state-noise compensation of halo and GEO, in the CRLB only
    block_h: float = checked(positive)  # h, fit grid spacing
    max_iter: int = checked(positive)  # iterations of the fit at most


@section
class HaloGeoVariant:
    """``[[variant]]``: one more set-up for the CRLB sensitivity table (choices the paper leaves open)."""

    name: str  # its row label
    halo: HaloOverride | None = None  # keys of [halo] it changes
    geo: GeoOverride | None = None  # keys of [geo] it changes


@section
class HaloGeoPaper:
    """The paper's sec. 2.1 statements."""

    position_sigma_m: float  # m, "converges to about one meter"
    days_to_level: float  # d, "within about eight days"
    level_m: float  # m, "about one meter" read as below this, per axis
    postfit_range_rms_m: float  # m, the post-fit range residual RMS


@section
class HaloGeoCrtbp(Scenario):
    """``scenario = "halo_geo_crtbp"``: an L1 halo and a GEO satellite tracked only by each other, instantaneous
    crosslink range and range-rate in the CRTBP (Fujimoto et al. 2012, sec. 2.1)."""

    arc_days: float = checked(positive)  # d, length of the arc
    cadence_s: float = checked(positive)  # s, between crosslink epochs
    seed: int  # noise draws of the single run
    compare_day: float = checked(positive)  # d, day of the paper's "about one meter"
    units: CrtbpUnits
    noise: CrosslinkNoise
    filter: HaloGeoFilter
    halo: HaloByPeriod
    geo: GeoOrbit
    variant: list[HaloGeoVariant] = field(default_factory=list)  # CRLB sensitivity set-ups
    montecarlo: MonteCarlo = field(default_factory=MonteCarlo)
    paper: HaloGeoPaper


# --- formation_observability: Turan et al. ------------------------------------------------------------------


@section
class MassRatioUnits:
    """CRTBP units with a prescribed mass ratio."""

    length_km: float = checked(positive)  # km, Earth-Moon distance
    gm_earth_km3s2: float = checked(positive)  # km^3/s^2
    mu: float = checked(positive)  # Moon / (Earth + Moon) mass ratio


@section
class Cadence:
    """Crosslink sampling."""

    dt_tu: float = checked(positive)  # CRTBP time units between samples


@section
class FormationFilter:
    """The Monte Carlo fit."""

    apriori_pos_m: float = checked(positive)  # m, a priori sigma per component
    apriori_vel_mps: float = checked(positive)  # m/s, a priori sigma per component
    error_pos_m: float = checked(positive)  # m, sigma of the drawn initial error per component
    error_vel_mps: float = checked(positive)  # m/s, sigma of the drawn initial error per component
    block_h: float = checked(positive)  # h, fit grid spacing
    max_iter: int = checked(positive)  # iterations of the fit at most


@section
class HaloPeriods(HaloFamily):
    """One halo per period of Table 1."""

    periods_tu: list[float] = checked(positive)  # CRTBP time units, in Table 1's column order


@section
class FormationHalos:
    """The L1 and L2 halos and where they start."""

    start: Literal["apolune", "perilune"]  # the x-z crossing each halo starts at
    north: bool  # the start crossing north of the Earth-Moon plane
    L1: HaloPeriods  # the L1 halos
    L2: HaloPeriods  # the L2 halos


@section
class LunarOrbiter:
    """The lunar orbiter (the paper gives its period only)."""

    period_days: float = checked(positive)  # d
    ecc: float  # eccentricity
    inc_deg: float  # deg, to the Earth-Moon plane
    raan_deg: float = 0.0  # deg
    argp_deg: float = 0.0  # deg, argument of periselene
    true_anomaly_deg: float = 0.0  # deg, at the epoch
    phase_band_deg: list[float] = field(default_factory=list)  # deg, start phases of the Table 1 sensitivity band


@section
class Sweep:
    """Noise and state-noise levels of the CRLB sweeps (Figs. 4-5)."""

    range_m: list[float] = checked(positive)  # m
    range_rate_mps: list[float] = checked(positive)  # m/s
    snc_mps2: list[float]  # m/s^2, state-noise compensation levels


@section
class Table1:
    """Turan et al. Table 1, its 12 columns in the order the study builds the formations."""

    xi_mean: list[float]  # mean SNR ratio of range to range-rate (eq. 25)
    cond_range: list[float]  # Gramian condition number, range only
    cond_range_rate: list[float]  # Gramian condition number, range-rate only
    inv_min_eig_range: list[float]  # unobservability index 1/min eig, range only
    inv_min_eig_range_rate: list[float]  # unobservability index 1/min eig, range-rate only


@section
class FormationPaper:
    """The paper's figures."""

    table1: Table1  # Table 1


@section
class FormationMonteCarlo(MonteCarlo):
    """Monte Carlo runs of the fit on some formations."""

    workers: int | None = None  # Dask workers (default: one per core)
    columns: list[int]  # formations (Table 1 column index, from 0) to run


@section
class FormationObservability(Scenario):
    """``scenario = "formation_observability"``: range-only against range-rate-only crosslinks in halo/halo
    and halo/lunar-orbiter formations (Turan et al. 2022, Table 1, Figs. 4-5)."""

    units: MassRatioUnits
    cadence: Cadence
    noise: CrosslinkNoise
    filter: FormationFilter
    halo: FormationHalos
    lunar: LunarOrbiter
    montecarlo: FormationMonteCarlo
    sweep: Sweep
    paper: FormationPaper


# --- halo_geo_doppler: Fujimoto et al. secs. 3-4 -------------------------------------------------------------


@section
class DopplerTruth:
    """Truth dynamics."""

    bodies: list[str]  # point masses besides the Earth
    earth_degree: dict[str, int] = field(default_factory=dict)  # Earth field degree by spacecraft (0: point mass)


@section
class DopplerFilter(DopplerTruth):
    """Filter dynamics and estimation."""

    apriori_pos_m: float = checked(positive)  # m, a priori sigma per axis
    apriori_vel_mps: float = checked(positive)  # m/s, a priori sigma per axis
    snc_sigma_mps2: float = checked(positive)  # m/s^2, white RTN accelerations per data interval
    bias_sigma_los_mps: float = checked(positive)  # m/s, a priori sigma of the Doppler bias on the line of sight
    max_iter: int = checked(positive)  # iterations per fit stage at most
    stage_days: list[float] = field(default_factory=list)  # d, growing arcs fitted first
    geo_cutoff_vx_mps: float = 0.0  # m/s, no data while the GEO satellite's |v_x| is below this
    known_pos_m: float = 1e-3  # m, a priori sigma per axis of a spacecraft whose state is known (Table 6: "0")
    known_vel_mps: float = 1e-6  # m/s, the same for velocity


@section
class DopplerBand:
    """``[band.NAME]``: one band's Doppler errors on the round-trip path rate."""

    sigma_mps: float = checked(positive)  # m/s, white noise
    bias_mps: float  # m/s, constant bias


@section
class DopplerPaper:
    """``[paper.NAME]`` (a band, or ``<band>_L1_known``): the paper's Table 4/5/6 rows, x, y, z, 3-D RMS."""

    L1_pos: list[float] | None = None  # m (Table 6 has none)
    L1_vel: list[float] | None = None  # m/s
    GEO_pos: list[float]  # m
    GEO_vel: list[float]  # m/s
    postfit_rms_mps: float | None = None  # m/s, the paper's post-fit residual RMS


@section
class HaloGeoDoppler(Scenario):
    """``scenario = "halo_geo_doppler"``: the L1 halo and GEO satellite with two-way crosslink Doppler and
    high-fidelity dynamics, S and X band (Fujimoto et al. 2012, secs. 3-4, Tables 4-5)."""

    epoch_utc: str  # UTC ISO time of the initial states
    interval_s: float = checked(positive)  # s, between Doppler points
    arc_days: float = checked(positive)  # d
    count_time_s: float = checked(positive)  # s, Doppler count time
    seed: int  # noise draws
    bands: list[str]  # the [band.X] tables to run, in order
    # run on every case (the first one plotted): odpipe's iterated filter-smoother, the paper's single EKF
    # pass with SNC per data interval, or with eqs. 10-11 over each gap between data
    estimators: list[Literal["filter_smoother", "ekf", "ekf_gap_snc"]] = field(
        default_factory=lambda: ["filter_smoother"])
    known_bands: list[str] = field(default_factory=list)  # bands also run with the L1 state known (Table 6)
    gravity_file: Path = _gravity_file()  # Earth field (truth and filter)
    state: dict[str, list[float]]  # m, m/s: Earth-centred ICRF initial state by spacecraft (L1, GEO)
    deviation: dict[str, list[float]]  # m, m/s: initial deviation of the a priori by spacecraft
    truth: DopplerTruth
    filter: DopplerFilter
    band: dict[str, DopplerBand]  # by band name
    paper: dict[str, DopplerPaper]  # by case: band name, or <band>_L1_known


# --- dro_leo_dowr: Li et al. --------------------------------------------------------------------------------


@section
class LeoElements:
    """The circular LEO at the epoch."""

    a_km: float = checked(positive)  # km, radius
    inc_deg: float  # deg
    raan_deg: float  # deg
    u_deg: float  # deg, argument of latitude


@section
class DowrSpacecraft:
    """Both spacecraft's surfaces."""

    mass_kg: float = checked(positive)  # kg
    area_m2: float = checked(positive)  # m^2, SRP and drag area
    cr: float  # SRP coefficient
    cd: float  # drag coefficient (LEO)
    n_bulge: float  # Harris-Priester exponent


@section
class DowrClock:
    """Truth clocks and pseudorange errors."""

    a0_s: float  # s, DRO clock offset at the epoch
    a1: float  # DRO clock rate
    a2_per_day: float  # 1/d, DRO clock drift
    sigma_y_1s: float = checked(positive)  # DRO white frequency noise, Allan deviation at 1 s
    leo_sigma_s: float = checked(positive)  # s, LEO time error (Gauss-Markov sigma)
    leo_tau_s: float = checked(positive)  # s, its correlation time
    lattice_s: float = checked(positive)  # s, sampling of the simulated clock processes
    thermal_m: float = checked(positive)  # m, white noise per pseudorange
    delay_m: float  # m, equipment delay D_com/2


@section
class DowrApriori:
    """A priori sigmas (the initial errors are drawn from them)."""

    pos_m: float = checked(positive)  # m, per axis
    vel_mps: float = checked(positive)  # m/s, per axis
    a0_s: float = checked(positive)  # s
    a1: float = checked(positive)  # clock rate
    a2_per_day: float = checked(positive)  # 1/d
    delay_m: float = checked(positive)  # m
    cd: float = checked(positive)  # LEO drag coefficient
    cr: float = checked(positive)  # DRO SRP coefficient


@section
class DowrModel:
    """``[model.NAME]``: a dynamics model (Table 10), field degrees by spacecraft."""

    earth_degree: dict[str, int]  # by spacecraft (DRO, LEO)
    moon_degree: dict[str, int] = field(default_factory=dict)  # by spacecraft (0 or absent: point mass)
    estimate_dynamic: bool = False  # estimate the LEO's Cd and the DRO's SRP scale


@section
class LinkPlan:
    """An entry of ``plan``: links of one type, one pass every ``every_h`` hours from ``first_h``."""

    type: Literal["dowr", "oneway"]  # dual one-way ranging or one-way ranging
    every_h: float = checked(positive)  # h
    first_h: float = checked(_at_least_zero, default=0.0)  # h past the epoch, start of the first pass


@section
class SatelliteFigures:
    """One satellite's Table 13 figures."""

    pos_m: float  # m, 3-D RMS over the last days
    vel_mps: float  # m/s, 3-D RMS over the last days
    converge_days: float | None = None  # d, when the position stays below converged_m (absent: never)


@section
class SimulationPaper:
    """The paper's Table 13 row."""

    clock_ns: float  # ns, DRO clock accuracy
    DRO: SatelliteFigures  # the DRO's figures
    LEO: SatelliteFigures  # the LEO's figures


@section
class DowrSimulation:
    """``[[simulation]]``: one simulation of Table 13."""

    name: str  # its label (e.g. "Simu. 2")
    mode: str  # its link mode, for the report
    model: str  # the filter's [model.X]
    plan: list[LinkPlan]  # the links
    snc_mps2: dict[str, float | list[float]]  # m/s^2 per integration step, by spacecraft (one, or R/T/N)
    integrator: Literal["RK4", "RKF78"] | None = None  # the filter's fixed-step integrator (default: adaptive)
    step_s: float | None = checked(positive, default=None)  # s, its step (and the process-noise step)
    stage_days: list[float] | None = None  # d, growing arcs (default: the top-level one)
    max_iter: int | None = None  # iterations per stage (default: the top-level one)
    final_iter: int | None = None  # iterations on the whole arc (default: the top-level one)
    paper: SimulationPaper  # the paper's Table 13 row
    variant_of: str | None = None  # the Table 13 simulation whose open choice this one varies (spread reported)


@section
class Parallel:
    """How the simulations run."""

    parallel: bool = False  # on a local Dask cluster (``odpipe study --parallel``)


@section
class DroLeoDowr(Scenario):
    """``scenario = "dro_leo_dowr"``: DRO-LEO autonomous navigation by dual one-way ranging with clocks
    (Li et al. 2023, Table 13)."""

    epoch_utc: str  # UTC ISO time of the initial states
    arc_days: float = checked(positive)  # d
    last_days: float = checked(positive)  # d, the accuracy window at the end of the arc
    converged_m: float = checked(positive)  # m, convergence level of each position component
    seed: int  # truth noise and a priori draws (the same for every simulation)
    earth_gravity: Path = _gravity_file()  # Earth field file
    moon_gravity: Path = _gravity_file()  # lunar field file
    sample_s: float = checked(positive)  # s, between pseudoranges in a pass
    pass_s: float = checked(positive)  # s, pass length
    batch_s: float = checked(positive)  # s, stochastic-acceleration batch and clock random-walk step
    paper_step_s: float = checked(positive)  # s, the paper's integration step its process noise is per
    block_s: float = checked(positive)  # s, filter output grid
    lookback_s: float = checked(positive)  # s, light-time margin of the trajectories
    stage_days: list[float]  # d, growing arcs fitted first
    max_iter: int = checked(positive)  # iterations per stage at most
    final_iter: int = checked(positive)  # iterations on the whole arc at most
    dro_state_km: list[float]  # km, km/s: the DRO's ICRF state at the epoch
    leo_elements: LeoElements
    spacecraft: DowrSpacecraft
    clock: DowrClock
    apriori: DowrApriori
    model: dict[str, DowrModel]  # "truth" and the filter models by name
    simulation: list[DowrSimulation]  # the simulations, run in order
    montecarlo: Parallel = field(default_factory=Parallel)


# --- ground_and_crosslink, schedule_trade: Leonard 2015 sec. 8.1 ------------------------------------------


@section
class GeoSite:
    """The GEO satellite's sub-satellite point at the epoch."""

    lat_deg: float  # deg
    lon_deg: float  # deg east


@section
class Srp:
    """Cannonball SRP of both spacecraft."""

    area_to_mass: float = checked(positive)  # m^2/kg
    cr: float  # SRP coefficient


@section
class GroundDynamics:
    """A dynamics model."""

    gravity_file: Path = _gravity_file()  # Earth field file
    bodies: list[str]  # point masses besides the Earth
    earth_degree: dict[str, int] = field(default_factory=dict)  # Earth field degree by spacecraft


@section
class GroundFilter(GroundDynamics):
    """Filter dynamics and estimation (thesis Table 8.3)."""

    apriori_pos_m: float = checked(positive)  # m, per axis
    apriori_vel_mps: float = checked(positive)  # m/s, per axis
    srp_sigma: float = checked(positive)  # a priori sigma of the SRP scale
    acc_sigma_rtn: list[float] = checked(positive)  # m/s^2, Gauss-Markov steady-state sigmas R, T, N
    acc_tau_s: float = checked(positive)  # s, their correlation time
    acc_batch_s: float = checked(positive)  # s, their constant batches
    sst_bias_m: float = checked(positive)  # m, crosslink range bias sigma
    dsn_bias_m: float = checked(positive)  # m, DSN range bias sigma per station
    geo_bias_m: float = checked(positive)  # m, GEO station range bias sigma
    block_s: float = checked(positive)  # s, filter output grid
    max_iter: int = checked(positive)  # iterations at most


@section
class GroundNoise:
    """White noise along the line of sight, 1 sigma."""

    sst_range: float = checked(positive)  # m, crosslink range
    sst_rate: float = checked(positive)  # m/s, crosslink Doppler
    dsn_range: float = checked(positive)  # m, DSN range
    dsn_rate: float = checked(positive)  # m/s, DSN Doppler
    geo_range: float = checked(positive)  # m, GEO station range
    geo_rate: float = checked(positive)  # m/s, GEO station Doppler


@section
class Schedule:
    """``[cases.NAME]``: a tracking schedule, gaps after each pass (inf: that data type unused)."""

    liaison_gap_h: float = checked(_at_least_zero)  # h, after each crosslink pass
    ground_gap_h: float = checked(_at_least_zero)  # h, after each ground pass
    ground_offset_h: float = 0.0  # h, the ground passes start this late


@section
class ThesisFigures:
    """``[paper.NAME]`` (a case): the thesis' figures (absent: not given)."""

    L1_rms_sig3: float | None = None  # m, 3-D 3-sigma RMS over the window, halo orbiter
    GEO_rms_sig3: float | None = None  # m, the same for the GEO satellite
    L1_final_sig3: float | None = None  # m, 3-D 3-sigma at the end, halo orbiter
    GEO_final_sig3: float | None = None  # m, the same for the GEO satellite
    L1_below100_d: float | None = None  # d, after which the halo's 3-sigma stays below 100 m
    GEO_below100_d: float | None = None  # d, the same for the GEO satellite
    note: str | None = None  # how the figure was read


@section
class ReportText:
    """Text for the report."""

    differences: str  # the differences from the thesis' set-up (Markdown)


@section
class Sensitivity:
    """Cases refitted with the filter's accelerations scaled, and over the choices the thesis leaves open."""

    acc_scale: float = checked(positive)  # factor on acc_sigma_rtn
    cases: list[str] = field(default_factory=list)  # the [cases.X] names refitted with the accelerations scaled
    acc_tau_s: list[float] = checked(positive, default_factory=list)  # s, correlation times tau_cases are refitted with
    tau_cases: list[str] = field(default_factory=list)  # the [cases.X] names refitted over acc_tau_s
    geo_apriori_vel_mps: list[float] = checked(positive, default_factory=list)  # m/s, "ground" refitted with these


@section
class GroundAndCrosslink(Scenario):
    """``scenario = "ground_and_crosslink"``: ground tracking of an L1 halo orbiter and a GEO satellite with
    and without crosslinks (Leonard 2015, sec. 8.1)."""

    epoch_utc: str  # UTC ISO time of the initial states
    arc_days: float = checked(positive)  # d
    interval_s: float = checked(positive)  # s, between observations
    count_time_s: float = checked(positive)  # s, Doppler count time
    pass_h: float = checked(positive)  # h, pass length of every schedule
    window_days: list[float]  # d, start and end of the RMS window
    mask_deg: float  # deg, elevation mask
    dsn: list[str]  # stations tracking the halo orbiter (the highest one above the mask)
    geo_station: str  # the station tracking the GEO satellite
    seed: int  # noise, bias and a priori draws
    state: dict[str, list[float]]  # m, m/s: GCRS initial state of the halo orbiter (L1)
    geo: GeoSite
    stations: dict[str, list[float]]  # geodetic lat (deg), lon (deg east), height (km) by station name
    srp: Srp
    truth: GroundDynamics
    filter: GroundFilter
    noise: GroundNoise
    cases: dict[str, Schedule] = field(default_factory=dict)  # the schedules fitted, by case name
    paper: dict[str, ThesisFigures] = field(default_factory=dict)  # the thesis' figures by case name
    report: ReportText
    sensitivity: Sensitivity


@section
class Gaps:
    """Gaps (h) after each 3-h pass."""

    gaps_h: list[float] = checked(_at_least_zero)  # h (inf: that data type unused)


@section
class TradeStudy:
    """``scenario = "schedule_trade"``: every key of ``ground_and_crosslink`` (usually through ``base``) and
    the trade study's grids (Leonard 2015, secs. 8.1.2.3-8.1.2.4)."""

    mesh: Gaps  # every (crosslink gap, ground gap) pair of these is fitted (Fig. 8.4)
    offset: Gaps  # equal gaps, ground passes simultaneous and offset by half a gap (Fig. 8.9)


@section
class ScheduleTrade(TradeStudy, GroundAndCrosslink):
    """The trade study's whole configuration."""


KINDS: dict[str, type] = {"halo_geo_crtbp": HaloGeoCrtbp, "halo_geo_doppler": HaloGeoDoppler,
                          "formation_observability": FormationObservability, "dro_leo_dowr": DroLeoDowr,
                          "ground_and_crosslink": GroundAndCrosslink, "schedule_trade": ScheduleTrade}
DOCUMENTED = {**KINDS, "schedule_trade": TradeStudy}  # schedule_trade's own keys; the rest are ground_and_crosslink's


# --- loading --------------------------------------------------------------------------------------------


def _resolve(node, cls, folder: Path):
    """``node`` (a table of ``cls``) with its path entries made absolute from ``folder`` (unknown keys kept)."""
    if not isinstance(node, dict) or not dataclasses.is_dataclass(cls):
        return node
    hints = typing.get_type_hints(cls)
    return {k: _resolve_value(v, hints[k], folder) if k in hints else v for k, v in node.items()}


def _resolve_value(value, hint, folder: Path):
    if hint is Path:
        return str(folder / value) if isinstance(value, str) and not Path(value).is_absolute() else value
    args = [a for a in typing.get_args(hint) if a is not type(None)]
    if dataclasses.is_dataclass(hint):
        return _resolve(value, hint, folder)
    if typing.get_origin(hint) is list and isinstance(value, list) and args:
        return [_resolve_value(v, args[0], folder) for v in value]
    if typing.get_origin(hint) is dict and isinstance(value, dict) and len(args) == 2:
        return {k: _resolve_value(v, args[1], folder) for k, v in value.items()}
    if len(args) == 1:  # X | None
        return _resolve_value(value, args[0], folder)
    return value


def _merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def _read(path: Path, seen: tuple) -> tuple[dict, list]:
    """The merged raw table at ``path`` and its files as (path, text, own table) pairs, top first."""
    if path in seen:
        raise ConfigError(path, "base", "configuration bases form a cycle: "
                          + " -> ".join(p.name for p in (*seen, path)))
    own, text = read_toml(path)
    if "base" not in own:
        return own, [(path, text, own)]
    if not isinstance(own["base"], str):
        raise ConfigError(path, "base", f"expected a file name, got {own['base']!r}").located(text)
    base, files = _read((path.parent / own["base"]).resolve(), (*seen, path))
    own = {k: v for k, v in own.items() if k != "base"}
    return _merge(base, own), [(path, text, own)] + files


def _sets(table: dict, key: str) -> bool:
    """True if ``table`` sets the key path ``key`` (e.g. ``simulation[1].plan``)."""
    node = table
    for part in key.split("."):
        name, _, index = part.partition("[")
        if not isinstance(node, dict) or name not in node:
            return False
        node = node[name]
        if index:
            i = int(index.rstrip("]"))
            if not isinstance(node, list) or i >= len(node):
                return False
            node = node[i]
    return True


def _located(err: ConfigError, files: list) -> ConfigError:
    """``err`` (problems of the merged configuration) on the file that set the first problem's key, with the
    problems of that file, each with its line."""
    def origin(p: Problem) -> int:
        return next((i for i, (_, _, own) in enumerate(files) if p.key and _sets(own, p.key)), 0)

    first = origin(err.problems[0])
    path, text, _ = files[first]
    return ConfigError(path, problems=[p for p in err.problems if origin(p) == first]).located(text)


def plain(value):
    """A loaded section as plain tables: dataclasses as dicts without their unset (None) keys, paths as str."""
    if dataclasses.is_dataclass(value):
        return {f.name: plain(v) for f in dataclasses.fields(value) if (v := getattr(value, f.name)) is not None}
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [plain(v) for v in value]
    return str(value) if isinstance(value, Path) else value


def load_scenario(path):
    """The study configuration at ``path`` on its ``base``, checked against its scenario's class: that
    dataclass (ConfigError naming the file, key and line of every problem)."""
    path = Path(path).resolve()
    _, files = _read(path, ())
    name = next((own["scenario"] for _, _, own in files if "scenario" in own), None)
    if name not in KINDS:
        where = next(((p, text) for p, text, own in files if "scenario" in own), files[0][:2])
        reason = f"must be one of {', '.join(KINDS)}, got {name!r}" if name is not None else \
            f"required key is missing (one of {', '.join(KINDS)})"
        raise ConfigError(where[0], "scenario", reason).located(where[1])
    cls = KINDS[name]
    merged: dict = {}
    for file, _, own in reversed(files):
        merged = _merge(merged, _resolve(own, cls, file.parent))
    try:
        return load(cls, merged, path)
    except ConfigError as err:
        raise _located(err, files) from None


def load_config(path) -> dict:
    """The study configuration at ``path`` as plain tables for the scenario modules (:func:`load_scenario`)."""
    return plain(load_scenario(path))


def reference() -> str:
    """The study configurations' reference (Markdown), generated from the classes above."""
    head = ("# Study configuration reference\n\n"
            "`odpipe study runs/study_NAME.toml` runs the study that `scenario` names; each has its own keys, "
            "below. `base = \"other.toml\"` starts from another configuration (tables merge key by key, "
            "everything else is replaced); paths are relative to the file that sets them.\n")
    return head + "".join(_kind(name, cls) for name, cls in DOCUMENTED.items())


def _kind(name: str, cls) -> str:
    """One study's reference: its heading and class docstring, then its sections one level down."""
    import inspect

    from odpipe.operations.reference import markdown

    doc = inspect.getdoc(cls)
    _, body = markdown(cls, name, skip=("scenario",)).split("\n", 1)
    body = body.replace(f"{doc}\n\n", "", 1)
    return f"\n## Study `{name}`\n\n{doc}\n" + "".join("#" + line if line.startswith("#") else line
                                                       for line in body.splitlines(keepends=True))
