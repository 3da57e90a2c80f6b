"""odpipe batch: many arcs in parallel on Dask, resumable, with a summary of the night and, with
``[batch] report = "folder"``, the night's report: every arc's post-fit residual statistics per station
and the overlaps of consecutive arcs (RIC, 3D RMS) with their plots; ``overlaps = [globs]`` limits the
overlap sequence to those arcs (e.g. leaving out a start-up arc that spans the same day as another)."""

import tomllib
from pathlib import Path

import pandas as pd

from odpipe.analysis.overlap import consecutive_overlaps, oem_trajectory, report_tables
from odpipe.pipeline.config import load_config
from odpipe.pipeline.setup import tdb
from odpipe.pipeline.run import run_config
from odpipe.products import residuals
from odpipe.runs.batch import night_summary, run_batch
from odpipe.runs.report import Section, write_report
from odpipe.runs.schema import ConfigError

NAME = "batch"
HELP = ("run many arcs (a nightly batch config listing arc configs) in parallel; skips arcs whose config, "
        "inputs and software are unchanged")


def add_arguments(p):
    p.add_argument("config", type=Path, help="batch config: [batch] arcs = [run configs or globs], workers = N")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    p.add_argument("--workers", type=int, help="local cluster size (default: the config's, else 2)")
    p.add_argument("--force", action="store_true", help="refit every arc, even unchanged ones")


def starts_from(arcs: list[Path]) -> dict:
    """arc -> the arcs of the batch whose products its a priori state is read from."""
    cfgs = {a: load_config(a) for a in arcs}
    roots = {a: (c.run.output / c.run.name).resolve() for a, c in cfgs.items()}
    after = {}
    for a, c in cfgs.items():
        source = c.initial_state.from_oem
        if source is not None:
            after[a] = [b for b, root in roots.items() if b != a and root in source.parents]
    return after


def night_report(out: Path, arcs: list[Path], outcomes, overlap_arcs: list[Path] | None = None) -> Path:
    """The night's report in ``out``: residual statistics per arc and station, overlaps of consecutive
    arcs among ``overlap_arcs`` (default all)."""
    out.mkdir(parents=True, exist_ok=True)
    status = {Path(o.config).resolve(): o for o in outcomes}
    done = []
    for a in arcs:
        cfg = load_config(a)
        run = cfg.run.output / cfg.run.name / "current"
        if status[a.resolve()].status != "failed" and (run / "trajectory.oem").exists():
            done.append((tdb(cfg.arc.start), cfg.run.name, run, a))
    done.sort()
    stats = pd.concat([pd.read_csv(run / "residual_statistics.csv").assign(arc=name) for _, name, run, _ in done],
                      ignore_index=True) if done else pd.DataFrame()
    headline = {"arcs": night_summary(outcomes).splitlines()[0]}
    sections = []
    if not stats.empty:
        stats = stats[["arc"] + [c for c in stats.columns if c != "arc"]]
        stats.to_csv(out / "residual_statistics.csv", index=False)
        sections.append(Section("Post-fit residuals per arc and station").text(
            "Along the line of sight (Doppler mm/s, range m), and the post-fit RMS in the observable's unit; "
            "per pass in each run's residual_statistics_passes.csv").tables(residuals.report_tables(stats)))
    seq = [(name, run) for _, name, run, a in done if overlap_arcs is None or a in overlap_arcs]
    table, pngs = consecutive_overlaps({name: oem_trajectory(run / "trajectory.oem") for name, run in seq},
                                       [name for name, _ in seq], out, "arcs", "Consecutive-arc", step=60.0)
    if table is not None:
        sec = Section("Overlaps of consecutive arcs (RIC differences, A - B over each overlap)").tables(
            report_tables(table))
        for png in pngs:
            sec.figure(png, png.stem)
        sections.append(sec)
        mean, std = table.iloc[-2], table.iloc[-1]
        headline["overlap 3D RMS"] = f"{mean.pos_3d_rms:.1f} ± {std.pos_3d_rms:.1f} m"
    failed = [o for o in outcomes if o.status == "failed"]
    if failed:
        sections.append(Section("Failed arcs").table(pd.DataFrame(
            [{"arc": Path(o.config).name, "error": o.error} for o in failed])))
    return write_report(out / "report.html", "Nightly batch", headline, sections)


def _arc(path: Path) -> dict:
    return run_config(path, progress=None)


def _arc_forced(path: Path) -> dict:
    return run_config(path, force=True, progress=None)


def run(args) -> int:
    data = tomllib.loads(args.config.read_text())
    batch = data.get("batch")
    if not isinstance(batch, dict) or not isinstance(batch.get("arcs"), list):
        raise ConfigError(args.config, "batch.arcs", "a list of run configs is required")
    allowed = {"arcs", "workers", "report", "overlaps"}
    if set(batch) - allowed:
        raise ConfigError(args.config, f"batch.{sorted(set(batch) - allowed)[0]}",
                          f"unknown key (allowed: {', '.join(sorted(allowed))})")
    arcs = sorted({p for pattern in batch["arcs"] for p in args.config.parent.glob(pattern)})
    overlap_arcs = (None if "overlaps" not in batch
                    else {p for pattern in batch["overlaps"] for p in args.config.parent.glob(pattern)})
    if not arcs:
        raise ConfigError(args.config, "batch.arcs", "no run config matches")
    outcomes = run_batch(arcs, _arc_forced if args.force else _arc, after=starts_from(arcs), scheduler=args.scheduler,
                         workers=args.workers or batch.get("workers", 2))
    print(night_summary(outcomes))
    if "report" in batch:
        print(f"report: {night_report(args.config.parent / batch['report'], arcs, outcomes, overlap_arcs)}")
    return 1 if any(o.status == "failed" for o in outcomes) else 0
