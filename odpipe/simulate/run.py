"""One simulated case from its description to its files, seeded (same seed, same bytes)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.stations import StationCatalog
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.measurements import MeasurementSetup
from odpipe.media.model import MediaModel
from odpipe.simulate.case import load
from odpipe.simulate.files import write_case
from odpipe.simulate.calibrations import ion_text, tro_text
from odpipe.simulate.observe import dsn_passes, observe, plan_rows
from odpipe.simulate.truth import simulate_truth
from parsers.trk223 import CalibrationSet, parse_text

STATIONS_CSV = Path(__file__).resolve().parents[2] / "fixtures" / "artemis" / "stations.csv"


def run_case(case_path, out, days: float | None = None, stations_csv: Path = STATIONS_CSV):
    """Simulate the case (optionally only its first ``days``) into ``out``; returns (paths, truth, observations)."""
    case = load(case_path)
    if days is not None:
        case = case.shortened(days)
    rng = np.random.default_rng(case.seed)
    eph = Ephemeris.open("de421")
    catalog = StationCatalog.default().with_csv(stations_csv)
    setup = MeasurementSetup(eph, catalog, gcrs_to_itrs=gcrs_to_itrs)
    truth = simulate_truth(case, eph, rng)
    table, ramps = plan_rows(case, truth.trajectory, setup, rng)
    tro = tro_text([n.station for n in case.networks], case.start, case.end, case.media.sigma_wet_m,
                   case.media.sigma_dry_m, rng)
    ion = ion_text(dsn_passes(table), case.spacecraft, case.media.sigma_ion_m, rng)
    model = MediaModel(CalibrationSet(parse_text(tro, f"{case.name}.TRO") + parse_text(ion, f"{case.name}.ION")))
    obs = observe(case, table, ramps, truth.trajectory, setup, model, catalog, rng)
    paths = write_case(Path(out), case, truth, obs, {"tro": tro, "ion": ion}, setup, stations_csv)
    return paths, truth, obs
