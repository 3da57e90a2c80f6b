"""One simulated case from its description to its files, seeded (same seed, same bytes)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.stations import StationCatalog
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.measurements import MeasurementSetup
from odpipe.media.model import MediaModel
from odpipe.simulate.case import Case, load
from odpipe.simulate.files import write_case
from odpipe.simulate.calibrations import ion_text, tro_text
from odpipe.simulate.observe import dsn_passes, observe, plan_rows
from odpipe.simulate.truth import simulate_truth
from parsers.trk223 import CalibrationSet, parse_text

STATIONS_CSV = Path(__file__).resolve().parents[2] / "fixtures" / "artemis" / "stations.csv"


def run_case(case_path, out, days: float | None = None, stations_csv: Path = STATIONS_CSV):
    """Simulate the case (a file or a loaded :class:`~odpipe.simulate.case.Case`; optionally only its first
    ``days``) into ``out``; returns (paths, truth, observations)."""
    case = case_path if isinstance(case_path, Case) else load(case_path)
    if days is not None:
        case = case.shortened(days)
    rng = np.random.default_rng(case.seed)
    eph = Ephemeris.open("de421")
    catalog = StationCatalog.default().with_csv(stations_csv)
    setup = MeasurementSetup(eph, catalog, gcrs_to_itrs=gcrs_to_itrs)
    truth = simulate_truth(case, eph, rng)
    table, ramps = plan_rows(case, truth.trajectory, setup, rng)
    md = case.media
    tro, tro_true = tro_text([n.station for n in case.networks], case.start, case.end, md.sigma_wet_m, md.sigma_dry_m,
                             rng, md.error_wet_m, md.error_dry_m)
    ion, ion_true = ion_text(dsn_passes(table), case.spacecraft, md.sigma_ion_m, rng, md.error_ion_m)
    # the observables see the true delays; the files carry the written calibrations
    model = MediaModel(CalibrationSet(parse_text(tro_true, f"{case.name}.TRO") + parse_text(ion_true, f"{case.name}.ION")))
    obs = observe(case, table, ramps, truth.trajectory, setup, model, catalog, rng)
    paths = write_case(Path(out), case, truth, obs, {"tro": tro, "ion": ion}, setup, stations_csv)
    return paths, truth, obs
