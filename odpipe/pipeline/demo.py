"""The embedded default case end to end: ``make demo`` / ``odpipe demo``.

1. Simulate the ARTEMIS-P2-like case (``runs/artemis_p2_like.toml``) into real-format
   files (TRK-2-34, UTDF, TRO, maneuver plan, truth SPK/OEM), unless already there.
2. Write one run configuration per arc, as the ARTEMIS overlap studies cut them
   (seed 004 §4.5–4.6): short arcs of a few days between station-keeping
   maneuvers, and long arcs each spanning one station-keeping maneuver.
3. Fit every arc with ``odpipe run`` on a local Dask cluster (resumable).
4. Overlap precision (RIC, 3D RMS) of consecutive short and long arcs, the
   maneuver reconstruction (designed vs estimated station keeping, Table 4.4; estimated
   vs the executed truth), the truth comparison of every arc (actual errors against
   the reported covariance), and all of it beside the thesis' figures
   (:mod:`odpipe.simulate.thesis`), in one HTML report.

``odpipe demo --twin`` runs ``runs/artemis_p2_twin.toml`` instead: the ARTEMIS-P2 twin with the
thesis' error budget (issue #25), 1-3 min on 2 cores against the fast case's ~15 s.

The a priori state of each arc is the truth at its start displaced by 1 km and
1 cm/s (in operations, the previous arc's prediction); the filter's a priori
sigma (100 km, 1 m/s, Table 4.1) makes the result independent of it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.analysis import maneuvers as maneuver_report
from odpipe.analysis import overlap
from odpipe.constants import J2000, SECONDS_PER_DAY
from odpipe.dynamics.compile_timer import compile_timer
from odpipe.numerics.precision import plus_minus, significant
from odpipe.pipeline.run import run_config
from parsers.atomic import write_text
from odpipe.products.spk import SpkTrajectory
from odpipe.operations.nightly import night_summary, run_batch
from odpipe.operations.report import Section, utc_iso, write_report
from odpipe.simulate import thesis
from odpipe.simulate.case import load as load_case
from odpipe.simulate.run import run_case
from odpipe.time import tdb_to_utc, utc_to_tdb
from parsers import oem
from parsers.maneuvers import read_plan

CASE = Path(__file__).resolve().parents[2] / "runs" / "artemis_p2_like.toml"
TWIN = CASE.with_name("artemis_p2_twin.toml")   # the ARTEMIS error budget (issue #25); slower
HOUR = 3600.0
OFFSET = np.array([1000.0, -800.0, 600.0, 0.01, -0.01, 0.005])  # a priori displacement, m and m/s


def arcs(start: float, end: float, sk: list[float]) -> list[tuple[str, str, float, float]]:
    """(name, 'short'|'long', start, end TDB s) of the arcs around the station-keeping epochs ``sk`` (TDB s)."""
    sk = sorted(sk)
    out = []
    for k, (a, b) in enumerate(zip(sk[:-1], sk[1:])):  # short arcs: both ends of each maneuver interval
        span = min(5 * SECONDS_PER_DAY, (b - a) - 2 * HOUR)
        out += [(f"short{k}a", "short", a + HOUR, a + HOUR + span), (f"short{k}b", "short", b - HOUR - span, b - HOUR)]
    edges = [start] + sk + [end]
    for k in range(len(edges) - 2):  # long arcs: from after one maneuver to before the one after next
        a = edges[k] + (HOUR if k else 0.0)
        b = edges[k + 2] - (HOUR if k + 2 < len(edges) - 1 else 0.0)
        out.append((f"long{k}", "long", a, b))
    return out


SPIN_DOPPLER = 2e-4  # m/s: the spin signature left in 60-s Doppler (~3 mHz at S-band), not modelled


def fitted_networks(case) -> list:
    """The networks whose data the fits use (USN is simulated but, as in the thesis §4.2.2, not fitted)."""
    return [n for n in case.networks if n.fitted]


def data_sigmas(case) -> dict:
    """Per-station data sigmas at the fitted 60-s count time (LOS m, m/s), as an analyst sets them from the
    pre-fit scatter: the noise and the unmodelled spin signature together."""
    sig = {"doppler_2way": 1e-4, "range": 2.0}
    for net in fitted_networks(case):
        name = f"PAD-{net.pad}" if net.format == "utdf" else net.station
        noise = net.sigma_doppler * np.sqrt(min(net.doppler_count_s, 60.0) / 60.0)
        sig[f"doppler_2way:{name}"] = float(np.hypot(noise, SPIN_DOPPLER))
        if net.range_step_s:
            sig[f"range:{name}"] = net.sigma_range
    return sig


def arc_config(case, files: dict, name: str, a: float, b: float, x0: np.ndarray, sigmas: dict,
               plots: bool = True) -> str:
    """Run configuration (TOML text) of arc ``name`` over [a, b] (TDB s) of the simulated case in ``files``
    (``plots``: the arc's residual plots)."""
    fitted = {f"utdf:{n.station}" for n in fitted_networks(case)}
    data = [Path(p).name for k, p in files.items() if k == "trk234" or k in fitted]
    body = case.body
    sig = ", ".join(f'"{k}" = {v:.6g}' for k, v in sigmas.items())
    return f"""# Arc {name} of the embedded ARTEMIS-like case (written by odpipe demo)
[run]
name = "{name}"
output = "../runs"
[arc]
spacecraft = "{case.spacecraft}"
start = "{utc_iso(a)}"
end = "{utc_iso(b)}"
[data]
files = {json.dumps(['../case/' + f for f in data])}
stations = ["../case/stations.csv"]
observables = ["doppler_2way", "range"]
[calibration]
tro = ["../case/{Path(files['tro']).name}"]
ion = ["../case/{Path(files['ion']).name}"]
[dynamics]
center = "earth"
ephemeris = "de421"
third_bodies = ["moon", "sun"]
mass = {body.mass_kg}
[dynamics.srp.cylinder]
radius = {body.radius_m}
length = {body.length_m}
rho_s = {body.rho_s}
rho_d = {body.rho_d}
axis = {body.spin_axis}
[initial_state]
epoch = "{utc_iso(a)}"
state = {list(map(float, x0))}
[estimation]
stochastic = {{ sigma = {case.stochastic.sigma}, tau = {case.stochastic.tau_s}, batch = {case.stochastic.batch_s} }}
data_sigma = {{ {sig} }}
maneuver_plan = "../case/{Path(files['maneuvers']).name}"
edit_against_reference = true   # arcs across burns: the plume after one must not lock the filter out
[products]
naif_id = {case.naif_id}
step = 600.0
""" + ("" if plots else "plots = false\n")


def _run_arc(path: Path) -> dict:
    with compile_timer() as ct:
        detail = run_config(path, progress=None)
    return {**detail, "numba_compile_s": ct.seconds, "numba_functions": ct.functions}


def compile_note(main, outcomes) -> str:
    """One line: numba compilation in the main process (``main``, a CompileTimer) and in the workers' arcs."""
    w_s = sum(o.detail.get("numba_compile_s", 0.0) for o in outcomes)
    w_n = sum(o.detail.get("numba_functions", 0) for o in outcomes)
    if main.functions + w_n == 0:
        return "numba: no compilation, every kernel loaded from the on-disk cache"
    return (f"numba: compiled {main.functions} functions in {main.seconds:.1f} s in the main process and "
            f"{w_n} in {w_s:.1f} s in the workers (once per checkout; later runs load them from the cache)")


def run_demo(out: Path = Path("out/demo"), workers: int = 2, progress=print, days: float | None = None,
             case=None, plots: bool = True) -> dict:
    """Run the whole demo into ``out`` (``days``: only the case's first days; ``case``: a loaded case instead
    of ``runs/artemis_p2_like.toml``; ``plots=False``: no per-arc residual plots, the figures unchanged);
    returns the headline figures."""
    out = Path(out).resolve()
    case = load_case(CASE) if case is None else case
    case = case if days is None else case.shortened(days)
    case_dir = out / "case"
    stem = case.name
    files = {"trk234": case_dir / f"{stem}.tnf", "tro": case_dir / f"{stem}.TRO", "ion": case_dir / f"{stem}.ION",
             "maneuvers": case_dir / "maneuvers_designed.csv", "spk": case_dir / f"{stem}_truth.bsp",
             "executed": case_dir / "maneuvers_executed_truth.csv"}
    files.update({f"utdf:{n.station}": case_dir / f"{stem}_{n.station}.utdf" for n in case.networks
                  if n.format == "utdf"})
    with compile_timer() as main_compile:
        if not all(p.exists() for p in files.values()):
            progress(f"simulating the case {case.name} into {case_dir} ...")
            run_case(case, case_dir)
        truth = SpkTrajectory(files["spk"], case.naif_id)
        sigmas = data_sigmas(case)
        arc_dir = out / "arcs"
        arc_dir.mkdir(parents=True, exist_ok=True)
        plan = arcs(float(utc_to_tdb(case.start)), float(utc_to_tdb(case.end)),
                    list(np.asarray(utc_to_tdb(case.station_keeping_epochs()), float)))
        configs = []
        for name, _, a, b in plan:
            path = arc_dir / f"{name}.toml"
            text = arc_config(case, files, name, a, b, truth.state(a)[0] + OFFSET, sigmas, plots)
            if not path.exists() or path.read_text() != text:
                write_text(path, text)
            configs.append(path)
        progress(f"fitting {len(configs)} arcs on {workers} workers ...")
        outcomes = run_batch(configs, _run_arc, workers=workers, progress=progress, imports=("odpipe.pipeline.demo",))
    progress(night_summary(outcomes))
    progress(compile_note(main_compile, outcomes))
    return _report(out, case, plan, files, truth)


TRUTH_FORMATS = {"position error RMS (m)": significant, "velocity error RMS (mm/s)": significant,   # RMS: 3 figures
                 "max |error| (sigma)": "{:.2f}", "RMS error (sigma)": significant, "within 3 sigma (%)": "{:.1f}",
                 "fit time (s)": "{:.1f}"}


def _report(out: Path, case, plan, files, truth) -> dict:
    runs = out / "runs"
    done = [(n, k, a, b) for n, k, a, b in plan if (runs / n / "current" / "trajectory.oem").exists()]
    traj = {n: overlap.oem_trajectory(runs / n / "current" / "trajectory.oem") for n, *_ in done}
    sections, headline = [], {"case": case.name, "arcs fitted": f"{len(done)} of {len(plan)}"}
    summaries = {}
    for kind in ("short", "long"):
        table, pngs = overlap.consecutive_overlaps(traj, [n for n, k, *_ in done if k == kind], out, kind,
                                           f"{kind.capitalize()}-arc")
        if table is None:
            continue
        sec = Section(f"{kind.capitalize()}-arc overlaps (RIC differences over each overlap)").tables(
            overlap.report_tables(table))
        for png, caption in pngs:
            sec.figure(png, caption)
        sections.append(sec)
        summaries[kind] = table
        mean, std = table.iloc[-2], table.iloc[-1]
        headline[f"{kind}-arc overlap RIC RMS"] = " / ".join(   # 3 significant figures, as the tables
            significant(mean[f'pos_{c}_rms']) for c in thesis.COMPONENTS) + " m"
        headline[f"{kind}-arc overlap 3D RMS"] = (f"{plus_minus(mean.pos_3d_rms, std.pos_3d_rms)} m, "
                                                 f"{plus_minus(mean.vel_3d_rms * 1e3, std.vel_3d_rms * 1e3)} mm/s")
    truth_rows = []
    for n, kind, a, b in done:
        cur = runs / n / "current"
        err, z = truth_errors(cur / "trajectory.oem", truth, a, b)
        summary = json.loads((cur / "summary.json").read_text())
        truth_rows.append({"arc": n, "kind": kind, "start (UTC)": utc_iso(a), "end (UTC)": utc_iso(b),
                           "converged": summary["converged"],
                           "position error RMS (m)": float(np.sqrt(np.mean(np.sum(err[:, :3] ** 2, 1)))),
                           "velocity error RMS (mm/s)": float(np.sqrt(np.mean(np.sum(err[:, 3:] ** 2, 1)))) * 1e3,
                           "max |error| (sigma)": float(np.max(np.abs(z))) if z.size else np.nan,
                           "RMS error (sigma)": float(np.sqrt(np.mean(z ** 2))) if z.size else np.nan,
                           "within 3 sigma (%)": 100 * float(np.mean(np.abs(z) < 3)) if z.size else np.nan,
                           "fit time (s)": summary["fit_seconds"]})
    truth_table = pd.DataFrame(truth_rows)
    write_text(out / "truth_comparison.csv", truth_table.to_csv(index=False))
    sections.append(Section("Truth comparison (smoothed solution minus simulated truth)").text(
        "Errors every 30 min; error/sigma at the filter grid epochs with the reported smoothed covariance "
        "(one hour clear of the arc ends), in units of that sigma.").table(truth_table, TRUTH_FORMATS))
    headline["share of state errors within 3σ"] = f"{truth_table['within 3 sigma (%)'].mean():.1f} %"
    headline["RMS of state error/σ (1 if the covariance is realistic)"] = f"{truth_table['RMS error (sigma)'].mean():.2f}"
    mans = _maneuvers(out, done, files, {m["name"] for m in case.maneuvers})
    stats = None
    if mans is not None:
        rows, stats, vs_truth, epochs = mans
        sections.append(Section("Maneuvers: designed − estimated (thesis Table 4.4)").tables(
            maneuver_report.report_tables(rows, stats, tdb_to_utc(epochs))))
        sections.append(Section("Maneuvers: estimated − executed truth").table(
            vs_truth, {"|executed| (mm/s)": "{:.3f}", "|error| (mm/s)": "{:.3f}", "max |error| (sigma)": "{:.2f}"}))
        headline["maneuver magnitude error vs truth (median)"] = f"{vs_truth['|error| (mm/s)'].median():.2f} mm/s"
        within = int((vs_truth['max |error| (sigma)'] < 3).sum())
        headline["maneuver errors within 3σ"] = f"{within} of {len(vs_truth)}"
        headline["station-keeping |designed| (median)"] = f"{rows['designed (mm/s)'].median():.1f} mm/s"
        headline["Table 4.4 median Mag. (%)"] = f"{stats.loc['Median', 'Mag. (%)']:.2f} (thesis 0.58)"
    if summaries:
        versus = thesis.comparison(summaries, stats)
        write_text(out / "thesis_comparison.csv", versus.to_csv(index=False))
        sections.insert(0, Section("ARTEMIS-P2 (thesis ch. 4) beside this twin").text(
            "Overlap means ± standard deviations of the per-overlap RMS differences (§4.5, §4.6) and Table 4.4's "
            "median and average designed − estimated station-keeping differences; ratio = odpipe / thesis. "
            "The thesis' maneuver components are true of date, odpipe's ICRF.").table(versus, {"ratio": "{:.2f}"}))
    report = write_report(out / "report.html", f"odpipe demo: {case.name}", headline, sections)
    headline["report"] = str(report)
    return headline


def truth_errors(oem_path: Path, truth, a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """(errors every 30 min over [a, b], (N,6) m and m/s; errors over the reported sigmas (M,6) at the
    covariance epochs one hour clear of the arc ends and of maneuver epochs) of a fitted OEM against the truth."""
    traj = overlap.oem_trajectory(oem_path)
    t = np.arange(a, b, 1800.0)
    err = traj.state(t) - truth.state(t)
    z = []
    for seg in oem.read(oem_path):
        tc = (seg.cov_epochs - J2000) / np.timedelta64(1, "s")
        ends = (seg.epochs[[0, -1]] - J2000) / np.timedelta64(1, "s")
        # away from the arc ends, and from maneuver epochs (pre- and post-burn states meet there)
        inside = (tc > a + HOUR) & (tc < b - HOUR) & (tc > ends[0] + 1.0) & (tc < ends[1] - 1.0)
        if inside.any():
            e = traj.state(tc[inside]) - truth.state(tc[inside])
            z.append(e / np.sqrt(np.einsum("kii->ki", seg.covariances[inside])))
    return err, (np.concatenate(z) if z else np.zeros((0, 6)))


def _maneuvers(out: Path, done, files, unplanned: set):
    """(Table 4.4 rows and summary of the station-keeping burns, estimated - executed truth of every burn,
    epochs) from the long arcs; ``unplanned``: burns known only by their time (attitude), not in Table 4.4."""
    rows = []
    for n, kind, *_ in done:
        path = out / "runs" / n / "current" / "maneuvers.csv"
        if kind == "long" and path.exists():
            rows.append(pd.read_csv(path).assign(arc=n))
    if not rows:
        return None
    table = pd.concat(rows, ignore_index=True)
    table["maneuver"] = table["maneuver"].astype(str).str.split(".").str[-1]
    table = table.drop_duplicates("maneuver", keep="first")  # each maneuver from the long arc that spans it first
    evaluated, stats = maneuver_report.evaluate(table[~table["maneuver"].isin(unplanned)])
    executed = read_plan(files["executed"]).set_index("name")
    ex = executed.loc[table["maneuver"], ["dv1", "dv2", "dv3"]].to_numpy(float)
    est = table[[f"estimated_{a}" for a in "xyz"]].to_numpy(float)
    sig = table[[f"sigma_{a}" for a in "xyz"]].to_numpy(float)
    vs_truth = pd.DataFrame({"maneuver": table["maneuver"].to_numpy(), "arc": table["arc"].to_numpy(),
                             "|executed| (mm/s)": np.linalg.norm(ex, axis=1) * 1e3,
                             "|error| (mm/s)": np.linalg.norm(est - ex, axis=1) * 1e3,
                             "max |error| (sigma)": np.max(np.abs(est - ex) / sig, axis=1)})
    write_text(out / "maneuvers_vs_truth.csv", vs_truth.to_csv(index=False))
    return evaluated, stats, vs_truth, table.loc[~table["maneuver"].isin(unplanned), "epoch"].to_numpy(float)
