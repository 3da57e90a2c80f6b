"""The step-by-step commands give the numbers ``odpipe run`` gives, on the real Cassini ODF (2006-02-27).

``odpipe convert -> calibrate -> compress -> edit`` through the CLI, against the run pipeline's own
stages called as :func:`odpipe.pipeline.run._run` calls them (ingest, geometry from the trajectory,
media calibration, compression at the median light time, fitted observables, editing), with the
real TRK-2-23 .TRO/.ION files. No Cassini trajectory is among the shared data: Saturn's barycentre
from DE440 stands in (Cassini stays within ~1e-3 rad of it seen from Earth), written as an OEM about
the solar-system barycentre so the ephemeris path of the geometry is exercised too. To keep the
runtime down, both start from the converted file's X-band downlink rows (both stations, all three
observables, 40070 of 79903 rows), written as a TrackingTable file that ``odpipe run`` ingests as well.
"""

import numpy as np
import pandas as pd
import pytest

from odpipe.analysis.overlap import oem_trajectory
from odpipe.cli import main
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.stations import StationCatalog, topocentric
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.constants import C_LIGHT
from odpipe.media.apply import calibrate
from odpipe.media.model import MediaModel
from odpipe.pipeline.config import PreprocessSection
from odpipe.pipeline.geometry import add_geometry, apparent_itrs, median_round_trip
from odpipe.pipeline.ingest import ingest
from odpipe.pipeline.run import fitted_rows
from odpipe.pipeline.setup import tdb
from odpipe.preprocess import store
from odpipe.preprocess.compress import compress
from odpipe.preprocess.edit import EditConfig, edit
from odpipe.preprocess.flags import Flag
from odpipe.products.segments import EphemerisSegment
from odpipe.products.oem import write_oem
from odpipe.time import utc_to_tdb
from parsers.trk223 import read_trk223

pytestmark = pytest.mark.realdata

ODF = "S18TIGM2006_058_0005X25MV1.ODF"
TRO, ION = "S18TIGE2006_032_2006_059.TRO", "S18TIGE2006_032_2006_059.ION"
ARC = ("2006-02-27T03:00:00", "2006-02-27T14:10:00")
OBSERVABLES = ["doppler_2way", "doppler_3way", "range"]
MEDIA = ["elevation_rx", "azimuth_rx", "rtlt_s", "tropo_m", "iono_m", "media_m", "media_ru"]


@pytest.fixture(scope="module")
def chain(shared_data, tmp_path_factory):
    """(CLI calibrated table, CLI edited table, run-pipeline calibrated table, run-pipeline edited table)."""
    d, w = shared_data / "cassini", tmp_path_factory.mktemp("chain")
    eph = Ephemeris.open("de440")
    t = np.arange(tdb("2006-02-26T18:00:00"), tdb("2006-02-27T18:00:00"), 600.0)
    oem = write_oem(w / "saturn.oem", [EphemerisSegment(t, eph.state(6, 0, t), "ssb")], "SATURN", "6")
    pre = PreprocessSection()
    assert main(["convert", str(d / ODF), "-o", str(w / "cas.parquet")]) == 0
    full, ramps = store.read(w / "cas.parquet")
    store.write(w / "x.parquet", full[full["band_down"] == "X"], ramps)
    assert main(["calibrate", str(w / "x.parquet"), "--tro", str(d / TRO), "--ion", str(d / ION),
                 "--trajectory", str(oem), "-o", str(w / "cal.parquet")]) == 0
    assert main(["compress", str(w / "cal.parquet"), "-o", str(w / "c60.parquet"),
                 "--count-time", str(pre.count_time), "--partial", pre.partial]) == 0
    assert main(["edit", str(w / "c60.parquet"), "-o", str(w / "edited.parquet"), "--arc", *ARC,
                 "--min-elevation", str(pre.elevation_mask_deg), "--blunder-k", str(pre.blunder_k),
                 "--min-pass-samples", str(pre.min_pass_samples)]) == 0

    # the run pipeline's stages, in the order and with the arguments odpipe.pipeline.run._run uses
    data = ingest([w / "x.parquet"])
    table = data.table[data.table["spacecraft"].astype(str) == "82"].reset_index(drop=True)
    catalog, traj = StationCatalog.default(), oem_trajectory(oem)
    table = add_geometry(table, traj, eph, catalog)
    cal, _ = calibrate(table, MediaModel(read_trk223(d / TRO, d / ION), None), target_itrs=apparent_itrs(traj, eph),
                       ramps=data.store, catalog=catalog, order=10)
    table, _ = compress(cal, pre.count_time, ramps=data.ramps, partial=pre.partial,
                        ramp_delay=median_round_trip(cal))
    table = table[fitted_rows(table, OBSERVABLES)].reset_index(drop=True)
    cfg = EditConfig(min_elevation=np.radians(pre.elevation_mask_deg), blunder_k=pre.blunder_k,
                     min_pass_samples=pre.min_pass_samples, arc=tuple(np.datetime64(a, "ns") for a in ARC))
    edited, _ = edit(table, data.ramps, cfg)
    return store.read(w / "cal.parquet")[0], store.read(w / "edited.parquet")[0], cal, edited


def _by_row(t: pd.DataFrame) -> pd.DataFrame:
    """Rows in one order: convert keeps the file's record order, ingest sorts by time."""
    key = "record_first" if "record_first" in t else "record"
    return t.sort_values([key, "epoch", "observable", "band_down"], kind="stable").reset_index(drop=True)


def test_calibrate_gives_the_run_pipelines_delays(chain):
    step, _, run, _ = (_by_row(t) for t in chain)
    assert len(step) == len(run) == 40070
    assert np.array_equal(step["record"], run["record"])
    for col in MEDIA:
        np.testing.assert_array_equal(step[col], run[col], err_msg=col)   # the same code on the same numbers
    assert (step["media_source"].astype(str) == run["media_source"].astype(str)).all()
    # every row corrected: the ODF's passes lie inside the .TRO/.ION cards and the trajectory
    assert np.isfinite(step["media_m"]).all() and (step["media_note"].astype(str) == "").all()


def test_edit_gives_the_run_pipelines_flags(chain):
    _, step, _, run = (_by_row(t) for t in chain)
    assert len(step) == len(run) and np.array_equal(step["record_first"], run["record_first"])
    assert np.array_equal(step["flags"], run["flags"])
    for col in ["value"] + MEDIA:
        np.testing.assert_array_equal(step[col], run[col], err_msg=col)   # the same code on the same numbers


def test_elevation_is_saturns_seen_from_the_stations_and_masks_the_edit(chain):
    """Each row's elevation against Saturn's apparent direction computed here from DE440: Saturn at emission
    seen from the Earth at emission (light time and annual aberration, 8e-5 rad, both in); the edit flags
    exactly the compressed rows below the mask."""
    step, edited, _, _ = chain
    eph, cat = Ephemeris.open("de440"), StationCatalog.default()
    e = step["epoch"].to_numpy("datetime64[ns]")
    t = np.asarray(utc_to_tdb(e), float)
    lt = np.linalg.norm(eph.position(6, 399, t), axis=-1) / C_LIGHT
    r = np.einsum("nij,nj->ni", gcrs_to_itrs(e), eph.position(6, 0, t - lt) - eph.position(399, 0, t - lt))
    el = np.full(len(step), np.nan)
    for name, idx in step.groupby("station_rx").indices.items():
        el[idx] = topocentric(cat[name], r[idx], e[idx])[1]
    # rad; the station's light time differs from the geocentre's by < 22 ms
    np.testing.assert_allclose(step["elevation_rx"], el, rtol=0, atol=1e-7)
    low = (edited["flags"].to_numpy() & int(Flag.ELEVATION)) != 0
    mask = np.radians(PreprocessSection().elevation_mask_deg)
    assert low.sum() > 0 and np.array_equal(low, edited["elevation_rx"].to_numpy() < mask)
