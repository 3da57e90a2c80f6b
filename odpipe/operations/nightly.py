"""Nightly batches: many arcs in parallel on Dask, resumable, one failure never stopping the rest.

Each arc is a run configuration; ``run_one(config_path) -> dict`` runs it and
returns at least ``{"status": "complete" | "skipped", ...}``. An arc whose
products are complete and whose config and inputs are unchanged is skipped
by ``run_one`` itself (see :func:`odpipe.operations.rundir.up_to_date`), so a
batch killed at any point is simply started again. An arc that starts from another
arc's products (a nightly chain) runs after it, and is reported failed without being
run when that arc failed. An arc whose configuration cannot be loaded is reported
failed (``failed=``) and the rest run.

The batch configuration (``[batch]`` table) is :class:`BatchSection`.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from odpipe.errors import describe
from odpipe.operations.schema import checked, load_file, positive

_log = logging.getLogger(__name__)


@dataclass
class BatchSection:
    """``[batch]`` of a nightly batch configuration; globs and paths relative to its folder, or absolute."""

    arcs: list[Path]  # run configurations (globs allowed); a listed file that is absent fails as its arc
    workers: int = checked(positive, default=2)  # local Dask cluster size
    report: Path | None = None  # folder of the night's report (residual statistics, overlaps)
    overlaps: list[Path] | None = None  # arcs whose consecutive overlaps are reported (default: all)

    def problems(self):
        if not self.arcs:
            yield "arcs", "lists no run configuration"


@dataclass
class BatchConfig:
    batch: BatchSection


def load_batch(path) -> BatchSection:
    """The ``[batch]`` table of the batch configuration file ``path``, checked (ConfigError)."""
    return load_file(BatchConfig, path).batch


@dataclass
class ArcOutcome:
    config: str
    status: str  # complete | skipped | failed
    seconds: float
    detail: dict = field(default_factory=dict)
    error: str = ""


def _guarded(run_one: Callable[[Path], dict], config: str, *after: ArcOutcome) -> ArcOutcome:
    failed = [Path(o.config).name for o in after if o.status == "failed"]
    if failed:
        return ArcOutcome(config, "failed", 0.0, error=f"not run: it starts from {', '.join(failed)}, which failed")
    t0 = time.perf_counter()
    try:
        detail = run_one(Path(config)) or {}
        return ArcOutcome(config, detail.get("status", "complete"), time.perf_counter() - t0, detail)
    except Exception as exc:  # one arc's failure is reported, never fatal to the batch
        return ArcOutcome(config, "failed", time.perf_counter() - t0,
                          error=describe(exc, hint=f"`odpipe --debug run {config}` shows the traceback")[1])


def dependency_order(configs: list[str], after: dict) -> list[str]:
    """``configs`` ordered so that every arc comes after those it starts from (``after[c]``)."""
    order, state = [], {}

    def visit(c, chain):
        if state.get(c) == "done":
            return
        if state.get(c) == "open":
            raise ValueError(f"arcs start from each other in a cycle: {' -> '.join(map(str, chain + [c]))}")
        state[c] = "open"
        for d in after.get(c, ()):
            visit(d, chain + [c])
        state[c] = "done"
        order.append(c)

    for c in configs:
        visit(c, [])
    return order


def chain_lengths(configs: list[str], sources: dict) -> dict[str, int]:
    """Per arc, the number of arcs in the longest chain that starts with it (itself and those that start from
    it, directly or not): the arc that leads the longest chain runs first when workers are scarce."""
    length: dict[str, int] = {}
    for c in reversed(configs):   # dependency order reversed: every arc after those that start from it
        length[c] = 1 + max((length[d] for d in configs if c in sources.get(d, ())), default=0)
    return length


def _local_cluster(workers: int, imports: tuple[str, ...] = ()):
    """``workers`` single-threaded worker processes on any free port (never clashing with a running cluster),
    with glibc's own heap trimming: Dask's default ``MALLOC_TRIM_THRESHOLD_`` of 64 kB also fixes glibc's mmap
    threshold, so every array above 128 kB is mapped and unmapped again (a GRAIL arc: 5x the page faults,
    3x the system time and 26 % more CPU in all than the same arc in a plain process). The workers are forked
    from one server process (multiprocessing's forkserver, started here) that has imported Dask and ``imports``
    (module names, e.g. the run's 2 CPU-s of imports): each worker starts with them, paid once for all."""
    import dask
    from distributed import LocalCluster

    _forkserver(imports)
    with dask.config.set(_CLUSTER):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0")


_CLUSTER = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
            "distributed.worker.multiprocessing-method": "forkserver"}


def _forkserver(imports: tuple[str, ...]) -> None:
    """Start the server the workers are forked from, in the environment Dask gives the workers it spawns (its
    ``pre-spawn-environ`` without ``MALLOC_TRIM_THRESHOLD_``: one BLAS and OpenMP thread; ``PYTHONHASHSEED``
    as Dask's nanny sets it), so the libraries it imports start as they would in a spawned worker. Its imports
    begin at once, before this process has imported Distributed (a server already running keeps its own)."""
    import multiprocessing
    from multiprocessing import forkserver

    import dask

    with dask.config.set(_CLUSTER):
        env = {k: os.environ.get(k, str(v)) for k, v in dask.config.get("distributed.nanny.pre-spawn-environ").items()
               if v is not None}
    if env.get("PYTHONHASHSEED") in (None, "0"):
        env["PYTHONHASHSEED"] = "6640"   # Dask's nanny's choice for its workers
    saved = {k: os.environ.get(k) for k in env}
    multiprocessing.get_context("forkserver").set_forkserver_preload(["distributed", *imports])
    os.environ.update(env)
    try:
        forkserver.ensure_running()
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def start_local_cluster(workers: int, imports: tuple[str, ...] = ()) -> Future:
    """:func:`_local_cluster` started in a background thread (the future's result: the cluster), so the caller
    goes on (e.g. loading its configurations) while the workers' processes import ``imports``."""
    _forkserver(tuple(imports))
    pool = ThreadPoolExecutor(1, thread_name_prefix="start the local Dask cluster")
    try:
        return pool.submit(_local_cluster, workers, tuple(imports))
    finally:
        pool.shutdown(wait=False)


def _warmed(warm: Callable[[list], None], configs: list) -> None:
    try:
        warm([Path(c) for c in configs])
    except Exception as exc:  # a worker that could not be warmed still runs its arcs (then paying the start-up)
        _log.warning("warming a worker failed: %s", describe(exc)[1])


def _in_background(work: Callable[[], None]) -> threading.Thread:
    """A thread running ``work`` at the lowest CPU priority (Linux: a thread's own nice value), so the arcs'
    processes keep the cores; its failure is logged, never fatal (the caller does the same work later)."""
    def run():
        try:
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), 19)
        except (AttributeError, OSError):   # not Linux: the thread runs at the process's priority
            pass
        try:
            work()
        except Exception as exc:
            _log.warning("preparing what follows the arcs failed: %s", describe(exc)[1])

    thread = threading.Thread(target=run, name="prepare what follows the arcs", daemon=True)
    thread.start()
    return thread


def run_batch(configs, run_one: Callable[[Path], dict], *, after: dict | None = None, scheduler: str | None = None,
              workers: int = 2, progress: Callable[[str], None] = _log.info,
              failed: dict | None = None, warm: Callable[[list], None] | None = None,
              meanwhile: Callable[[], None] | None = None, cluster: Future | None = None,
              imports: tuple[str, ...] = ()) -> list[ArcOutcome]:
    """Run every arc config; returns one outcome per arc in completion order.

    ``after``: config -> configs whose products it starts from (run first: an arc is sent to the cluster once
    they are done, so it goes to whichever worker is free, the arc leading the longest chain first). ``scheduler``
    is the address of a running Dask scheduler; without it a local cluster of ``workers``
    single-threaded processes is started (and closed in the background once every arc is
    done, while the caller goes on: its workers take seconds to exit). ``failed``: config ->
    why it cannot run (e.g. its configuration does not load): reported failed first, with the
    arcs that start from it. ``warm(configs)``: run once in every worker at a lower priority than
    the arcs, so a worker that waits for a chain's first arc pays its imports and loads then
    (:func:`odpipe.pipeline.warmup.warm_worker`); its failure is logged, never fatal. ``meanwhile()``: run in
    this process once the first arcs are sent, in a background thread at the lowest CPU priority (e.g. the
    imports of the night's report, which would otherwise follow the last arc); its failure is logged.
    ``cluster``: the local cluster already starting (:func:`start_local_cluster`), else one is started here,
    its workers importing ``imports`` (module names) before their first arc.
    """
    from distributed import Client, as_completed

    after = {str(c): [str(d) for d in ds] for c, ds in (after or {}).items()}
    broken = {str(c): ArcOutcome(str(c), "failed", 0.0, error=why) for c, why in (failed or {}).items()}
    total = len({str(c) for c in configs} | set(broken))
    outcomes: list[ArcOutcome] = []
    for out in broken.values():
        outcomes.append(out)
        progress(f"[{len(outcomes)}/{total}] {Path(out.config).name}: failed: {out.error}")
    configs = [c for c in dependency_order([str(c) for c in configs], after) if c not in broken]
    starting, cluster = cluster, None
    if not configs:
        if starting is not None:
            _close_in_background(starting.result())
        return outcomes
    if not scheduler:
        cluster = starting.result() if starting is not None else _local_cluster(workers, imports)
    inside = set(configs)
    sources = {c: [d for d in after.get(c, ()) if d in broken or d in inside] for c in configs}
    rank = chain_lengths(configs, sources)
    done = dict(broken)
    waiting = list(configs)
    with Client(scheduler or cluster) as client:
        running = as_completed()

        def submit_ready():   # an arc is sent once its sources are done, to whichever worker is free
            for c in [c for c in waiting if all(d in done for d in sources[c])]:
                waiting.remove(c)
                running.add(client.submit(_guarded, run_one, c, *[done[d] for d in sources[c]],
                                          key=f"arc-{configs.index(c)}", priority=rank[c], pure=False))

        submit_ready()
        preparing = None if meanwhile is None else _in_background(meanwhile)
        if warm is not None:   # after the arcs: a worker given the first arc runs this only when idle
            for k, address in enumerate(client.scheduler_info()["workers"]):
                client.submit(_warmed, warm, configs, key=f"warm-{k}", workers=[address],
                              allow_other_workers=False, priority=-1, pure=False)
        for fut in running:
            out = fut.result()
            done[out.config] = out
            outcomes.append(out)
            note = f": {out.error}" if out.error else ""
            progress(f"[{len(outcomes)}/{total}] {Path(out.config).name}: {out.status} in {out.seconds:.1f} s{note}")
            submit_ready()
    if preparing is not None:
        preparing.join()
    if cluster is not None:   # the caller's summary and report need no worker
        _close_in_background(cluster)
    return outcomes


def _close_in_background(cluster) -> None:
    """Close a local cluster while the caller goes on (its workers take a fraction of a second to exit)."""
    threading.Thread(target=cluster.close, name="close the local Dask cluster").start()


def night_summary(outcomes: list[ArcOutcome]) -> str:
    """A few lines that say how the night went."""
    counts = {s: sum(o.status == s for o in outcomes) for s in ("complete", "skipped", "failed")}
    lines = [f"{len(outcomes)} arcs: {counts['complete']} run, {counts['skipped']} unchanged (skipped), "
             f"{counts['failed']} failed"]
    lines += [f"  FAILED {o.config}: {o.error}" for o in outcomes if o.status == "failed"]
    return "\n".join(lines)
