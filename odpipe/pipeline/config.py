"""Run configuration (``runs/NAME.toml``): the schema, checked strictly.

Times are UTC ISO strings; relative paths resolve against the config's folder;
units are SI (m, m/s, s, m²) unless a key says otherwise (``*_deg``).
Unknown keys, wrong types and missing required keys are errors naming the key
and the file (:class:`odpipe.runs.schema.ConfigError`).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from odpipe.od.arc import sigma_value
from odpipe.runs.schema import ConfigError, load


@dataclass
class RunSection:
    name: str
    output: Path = Path("out")  # runs go to OUTPUT/NAME (attempt folders and 'current')


@dataclass
class ArcSection:
    spacecraft: str  # id as the tracking files give it, e.g. "181"
    start: str
    end: str


@dataclass
class DataSection:
    files: list[Path]
    stations: list[Path] = field(default_factory=list)  # station CSVs added to the default catalog
    # observables fitted; "observable:BAND" keeps only rows of that downlink band (e.g. "doppler_1way:X")
    observables: list[str] = field(default_factory=lambda: ["doppler_2way", "range"])
    errors: Literal["raise", "report"] = "report"  # nightly: report a corrupt record and go on


@dataclass
class CalibrationSection:
    media: bool = True  # false: the table's values are already corrected (or simulated without media)
    tro: list[Path] = field(default_factory=list)
    ion: list[Path] = field(default_factory=list)
    ionex: list[Path] = field(default_factory=list)
    smoothing_order: int = 10  # per-pass polynomial; -1 = none


@dataclass
class PreprocessSection:
    count_time: float = 60.0  # s, Doppler compression target
    partial: Literal["keep", "flag", "drop"] = "keep"
    elevation_mask_deg: float = 10.0
    blunder_k: float = 10.0
    min_pass_samples: int = 10


@dataclass
class GravitySection:
    body: str
    file: Path
    degree: int
    partial_degree: int | None = None


@dataclass
class CylinderSection:
    radius: float
    length: float
    rho_s: float = 0.0
    rho_d: float = 0.0
    axis: str | list[float] = "sun"  # spin axis: ICRF unit vector or 'sun'


@dataclass
class SrpSection:
    cr_area: float = 0.0  # Cr·A, m² (cannonball)
    cylinder: CylinderSection | None = None
    occulters: list[str] = field(default_factory=lambda: ["earth", "moon"])


@dataclass
class DynamicsSection:
    center: str
    ephemeris: str = "de440"  # 'de440', 'de421' or a .bsp path
    third_bodies: list[str] = field(default_factory=list)
    gravity: list[GravitySection] = field(default_factory=list)
    srp: SrpSection | None = None
    mass: float = 1000.0  # kg
    relativity: bool = False


@dataclass
class InitialStateSection:
    """The a priori state at ``epoch``: given (``state``) or read from an OEM (``from_oem``), e.g. the
    previous arc's ``OUTPUT/NAME/current/trajectory.oem`` (a nightly chain; ``odpipe batch`` runs
    that arc first)."""

    epoch: str  # UTC
    state: list[float] | None = None  # m, m/s, ICRF axes about dynamics.center
    from_oem: Path | None = None


@dataclass
class StochasticSection:
    sigma: float  # m/s², steady state, per RTN axis
    tau: float  # s (0 = white per batch)
    batch: float  # s


@dataclass
class EstimationSection:
    sigma_position: float = 100e3
    sigma_velocity: float = 1.0
    srp_scale_sigma: float | None = 0.1
    stochastic: StochasticSection | None = None
    # LOS sigma (m, m/s) by "observable" or "observable:station" (the station's entry wins); angle observables:
    # the angle's sigma, rad or with its unit ("0.01 deg", "36 arcsec")
    data_sigma: dict[str, float | str] = field(default_factory=lambda: {"range": 2.0, "doppler_2way": 1e-4})
    range_bias_sigma: float | None = 5.0
    # one-way Doppler's oscillator, estimated when set: sigmas of its fractional frequency offset y0 and drift
    # y1 (1/s) about the arc start, one pair for every band it drives (a priori 0: the rows' reference)
    oscillator_sigma: list[float] | None = None
    maneuver_plan: Path | None = None  # planned maneuvers (parsers.maneuvers schema)
    maneuver_epoch_sigma: float | None = None  # s: estimate planned burns' epochs (a plan's sigma_time wins)
    edit_k: list[float] = field(default_factory=lambda: [float("inf"), 10.0, 5.0])
    max_iter: int = 10
    reweight: bool = False  # ARTEMIS reweighting from post-fit RMS; see README (known instability)
    # data-weight stages multiplying every sigma, loose to tight (e.g. [30, 5, 1]): the next stage starts once
    # the epoch correction is below 1 sigma, so a far-off a priori is not fitted at full weight at once
    sigma_scale: list[float] = field(default_factory=lambda: [1.0])
    block: float = 600.0
    # unlogged maneuvers: the filter's innovations are always tested (findings in the report); with a sigma
    # (m/s per axis) each finding also becomes an estimated impulsive maneuver and the arc is fitted again
    detected_maneuver_sigma: float | None = None


@dataclass
class ProductsSection:
    oem: bool = True
    spk: bool = True
    naif_id: int = -999
    object_name: str = ""
    step: float = 60.0  # s between trajectory product states
    plots: bool = True


@dataclass
class RunConfig:
    run: RunSection
    arc: ArcSection
    data: DataSection
    dynamics: DynamicsSection
    initial_state: InitialStateSection
    calibration: CalibrationSection = field(default_factory=CalibrationSection)
    preprocess: PreprocessSection = field(default_factory=PreprocessSection)
    estimation: EstimationSection = field(default_factory=EstimationSection)
    products: ProductsSection = field(default_factory=ProductsSection)
    path: Path | None = None
    text: str = ""


def load_config(path) -> RunConfig:
    """Read and check a run configuration file."""
    path = Path(path).resolve()
    text = path.read_text()
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(path, "", f"not valid TOML: {exc}") from None
    for reserved in ("path", "text"):
        if reserved in data:
            raise ConfigError(path, reserved, "unknown key")
    cfg = load(RunConfig, data, path)
    init = cfg.initial_state
    if (init.state is None) == (init.from_oem is None):
        raise ConfigError(path, "initial_state", "give either state or from_oem")
    if init.state is not None and len(init.state) != 6:
        raise ConfigError(path, "initial_state.state", "needs 6 numbers (m, m/s)")
    for key, value in cfg.estimation.data_sigma.items():
        try:
            sigma_value(key, value)
        except ValueError as exc:
            raise ConfigError(path, f"estimation.data_sigma.{key}", str(exc)) from None
    cfg.path, cfg.text = path, text
    return cfg


def reference() -> str:
    """The run configuration reference (Markdown), generated from the classes above."""
    from odpipe.runs.reference import markdown

    return markdown(RunConfig, "Run configuration reference", skip=("path", "text"))
