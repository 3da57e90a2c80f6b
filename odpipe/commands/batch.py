"""odpipe batch: many arcs in parallel on Dask, resumable, with a summary of the night and, with
``[batch] report = "folder"``, the night's report: every arc's post-fit residual statistics per station
and the overlaps of consecutive arcs (RIC, 3D RMS) with their plots; ``overlaps = [globs]`` limits the
overlap sequence to those arcs (e.g. leaving out a start-up arc that spans the same day as another)."""

from pathlib import Path

from odpipe.errors import Exit, describe
from odpipe.operations.nightly import load_batch, night_summary, run_batch, start_local_cluster
from odpipe.operations.schema import load, read_toml

RUN_IMPORTS = ("odpipe.pipeline.run",)   # what every worker imports before its first arc

NAME = "batch"
HELP = ("run many arcs (a nightly batch config listing arc configs) in parallel; skips arcs whose config, "
        "inputs and software are unchanged; an arc that fails (or whose config does not load) never stops the rest")


def add_arguments(p):
    p.add_argument("config", type=Path, help="batch config: [batch] arcs = [run configs or globs, relative to "
                                             "the batch config or absolute], workers = N, report = folder")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    p.add_argument("--workers", type=int, help="local cluster size (default: the config's, else 2)")
    p.add_argument("--force", action="store_true", help="refit every arc, even unchanged ones")


def arc_configs(arcs: list[Path]) -> tuple[dict, dict]:
    """(arc -> RunConfig of the arcs whose configuration loads, arc -> one line saying why the others do not)."""
    from odpipe.pipeline.config import load_config  # the pipeline's imports: not for `odpipe batch --help`

    cfgs, broken = {}, {}
    for a in arcs:
        try:
            cfgs[a] = load_config(a)
        except (ValueError, OSError) as exc:  # ConfigError (every problem), unreadable or absent file
            broken[a] = describe(exc)[1]
    return cfgs, broken


def _root(arc: Path) -> Path | None:
    """The run folder of an arc whose configuration does not load, if its [run] table says it."""
    from odpipe.pipeline.config import RunSection

    try:
        data, _ = read_toml(arc)
        run = load(RunSection, data.get("run"), Path(arc).resolve(), "run")
    except (ValueError, OSError):
        return None
    return (run.output / run.name).resolve()


def starts_from(arcs: list[Path], cfgs: dict | None = None, broken=()) -> dict:
    """arc -> the arcs of the batch whose products its a priori state is read from (``cfgs``: the loaded
    configurations, default: load them; ``broken``: arcs whose configuration does not load)."""
    if cfgs is None:
        from odpipe.pipeline.config import load_config
        cfgs = {a: load_config(a) for a in arcs}
    roots = {a: (c.run.output / c.run.name).resolve() for a, c in cfgs.items()}
    roots.update({a: root for a in broken if (root := _root(a)) is not None})
    after = {}
    for a, c in cfgs.items():
        source = c.initial_state.from_oem
        if source is not None:
            after[a] = [b for b, root in roots.items() if b != a and root in source.parents]
    return after


def night_report(out: Path, arcs: list[Path], outcomes, overlap_arcs: list[Path] | None = None,
                 config: Path | None = None, cfgs: dict | None = None) -> Path:
    """The batch's report in ``out``: residual statistics per arc and station, overlaps of consecutive
    arcs among ``overlap_arcs`` (default all); titled by the batch configuration ``config`` (its name).
    ``cfgs``: arc -> its configuration as the batch loaded it (default: load them again)."""
    import pandas as pd

    from odpipe.analysis.overlap import consecutive_overlaps, oem_trajectory, report_tables
    from odpipe.numerics.precision import plus_minus
    from odpipe.pipeline.config import load_config
    from odpipe.pipeline.setup import tdb
    from odpipe.products import residuals
    from parsers.atomic import write_csv
    from odpipe.operations.report import Section, write_report

    out.mkdir(parents=True, exist_ok=True)
    status = {Path(o.config).resolve(): o for o in outcomes}
    done = []
    for a in arcs:
        if status[a.resolve()].status == "failed":
            continue
        cfg = cfgs[a] if cfgs is not None and a in cfgs else load_config(a)
        run = cfg.run.output / cfg.run.name / "current"
        if (run / "trajectory.oem").exists():
            done.append((tdb(cfg.arc.start), cfg.run.name, run, a))
    done.sort()
    stats = pd.concat([pd.read_csv(run / "residual_statistics.csv").assign(arc=name) for _, name, run, _ in done],
                      ignore_index=True) if done else pd.DataFrame()
    headline = {"arcs": night_summary(outcomes).splitlines()[0]}
    if config is not None:
        headline["batch configuration"] = str(Path(config).resolve())
    sections = []
    if not stats.empty:
        stats = stats[["arc"] + [c for c in stats.columns if c != "arc"]]
        write_csv(out / "residual_statistics.csv", stats, index=False)
        sections.append(Section("Post-fit residuals per arc and station").text(
            "Along the line of sight (Doppler mm/s, range m), and the post-fit RMS in the observable's unit; "
            "per pass in each run's residual_statistics_passes.csv. "
            f"{residuals.PREFIT_MEANING}, {residuals.ONE_WAY_PREFIT}.").tables(residuals.report_tables(stats)))
    seq = [(name, run) for _, name, run, a in done if overlap_arcs is None or a in overlap_arcs]
    table, pngs = consecutive_overlaps({name: oem_trajectory(run / "trajectory.oem") for name, run in seq},
                                       [name for name, _ in seq], out, "arcs", "Consecutive-arc", step=60.0)
    if table is not None:
        sec = Section("Overlaps of consecutive arcs (RIC differences, A - B over each overlap)").tables(
            report_tables(table))
        for png, caption in pngs:
            sec.figure(png, caption)
        sections.append(sec)
        mean, std = table.iloc[-2], table.iloc[-1]
        headline["overlap 3D RMS"] = f"{plus_minus(mean.pos_3d_rms, std.pos_3d_rms)} m"
    failed = [o for o in outcomes if o.status == "failed"]
    if failed:
        sections.append(Section("Failed arcs").table(pd.DataFrame(
            [{"arc": Path(o.config).name, "error": o.error} for o in failed])))
    title = "odpipe batch" + (f" {Path(config).stem}" if config is not None else "")
    return write_report(out / "report.html", title, headline, sections)


def prepare_report() -> None:
    """The imports of :func:`night_report` and of its plots (about 1 CPU-s), done while the arcs run."""
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.figure  # noqa: F401

    import odpipe.analysis.overlap  # noqa: F401
    import odpipe.operations.report  # noqa: F401
    import odpipe.pipeline.setup  # noqa: F401
    import odpipe.products.residuals  # noqa: F401


def _arc(path: Path) -> dict:
    from odpipe.pipeline.run import run_config
    return run_config(path, progress=None)


def _arc_forced(path: Path) -> dict:
    from odpipe.pipeline.run import run_config
    return run_config(path, force=True, progress=None)


def run(args) -> int:
    batch = load_batch(args.config)
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers {args.workers}: must be at least 1")
    arcs = sorted(set(batch.arcs))
    overlap_arcs = None if batch.overlaps is None else set(batch.overlaps)
    workers = args.workers or batch.workers
    # the workers start (and import the run) while this process loads the arcs' configurations
    cluster = None if args.scheduler else start_local_cluster(workers, RUN_IMPORTS)
    cfgs, broken = arc_configs(arcs)
    from odpipe.pipeline.warmup import warm_worker
    outcomes = run_batch(arcs, _arc_forced if args.force else _arc, after=starts_from(arcs, cfgs, broken),
                         scheduler=args.scheduler, workers=workers, failed=broken, warm=warm_worker,
                         meanwhile=prepare_report if batch.report is not None else None, cluster=cluster,
                         imports=RUN_IMPORTS)
    print(night_summary(outcomes))
    if batch.report is not None:
        print(f"report: {night_report(batch.report, arcs, outcomes, overlap_arcs, args.config, cfgs)}")
    return Exit.PARTIAL if any(o.status == "failed" for o in outcomes) else Exit.OK
