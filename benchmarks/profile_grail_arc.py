"""Where a GRAIL-B daily arc spends its time: wall and CPU seconds by pipeline stage and by fit iteration.

    python benchmarks/profile_grail_arc.py [runs/grail_b_2012_04_10.toml] [--interval 0.002] [--cprofile N] [--warm N]

Runs the arc's configuration like ``odpipe run`` (``force``: always fitted again) while a
sampling thread reads the main thread's Python stack every ``interval`` seconds. Each
interval's wall time goes to the innermost frame that belongs to a stage:

    ingest          parsers/ (but parsers/atomic.py), odpipe/pipeline/ingest.py
    geometry        odpipe/pipeline/geometry.py (elevation, azimuth, light time of every row; the media's
                    spacecraft directions)
    media           odpipe/media/
    compression     odpipe/preprocess/compress.py
    editing         the rest of odpipe/preprocess/
    integration     odpipe/dynamics/ (DOP853 with the variational equations, the field kernel)
    light time      odpipe/measurements/ (light-time solution, observables and their partials)
    filter          odpipe/estimation/ and odpipe/od/ outside the two above
    smoother        odpipe/estimation/smoother.py
    products        odpipe/products/, odpipe/operations/, odpipe/pipeline/fitted_trajectory.py, run.py:_products,
                    parsers/atomic.py (file writes)
    set-up          the rest of odpipe/pipeline (force model, gravity file, a priori state)

Frames of odpipe/frames, odpipe/time, odpipe/environment, numpy, scipy and pandas are
passed over (they count for the stage that called them). numba kernels hold the GIL, so
a sample lands just after the kernel returns, in the frame that called it: stages are
right to the length of one kernel call. Each interval is counted twice: wall seconds and the
main thread's CPU seconds (its own clock, ``time.pthread_getcpuclockid``), the steadier figure
on a loaded machine. The process's own fixed costs are printed first, measured before the run: importing the
pipeline and numba's first call (its runtime's start), CPU s. Time inside ``odpipe.estimation.fit.fit`` is
also split by (fit call, iteration, weight stage). numba compilation (none when its
cache is warm: run twice) is reported apart. Integrations and force-model evaluations
(``Trajectory.n_eval``, independent of the machine's load) are counted by where
``propagate`` was called from. BLAS runs one thread unless the environment says otherwise, as
in the nightly's Dask workers (two BLAS threads on a loaded 2-core machine cost the media's
per-pass polynomial fits ten times the CPU). ``--cprofile N`` also runs cProfile on the CPU clock
(``time.process_time``) and prints its N functions of most cumulative CPU time (the sampler's
figures then include cProfile's own overhead). ``--warm N`` first runs the arc N times unmeasured, as a
nightly's Dask worker has run an arc before its next one: the gravity file, the EOP table, numba's cached
kernels and matplotlib are then loaded, and the figures are those of the arc inside the nightly. Figures
are printed, never asserted.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import sys
import threading
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):   # as in a nightly's Dask workers
    os.environ.setdefault(_var, "1")

_IMPORT_CPU = time.process_time()
from odpipe.dynamics.compile_timer import compile_timer  # noqa: E402
from odpipe.pipeline.run import run_config  # noqa: E402
from odpipe.operations.schema import ConfigError  # noqa: E402
_IMPORT_CPU = time.process_time() - _IMPORT_CPU


def numba_start() -> float:
    """CPU s of the process's first numba call (its runtime's start and one small cached kernel), made
    before the run so that no stage is charged with it."""
    import numpy as np

    from odpipe.numerics.interpolation import lagrange4_uniform

    t = time.process_time()
    lagrange4_uniform(0.0, 1.0, np.zeros(4), np.array([1.5]))
    return time.process_time() - t


STAGES = [  # (path fragment, stage): the first fragment found in a frame's file name wins
    ("/parsers/atomic.py", "products"),   # the products' atomic file writes
    ("/parsers/", "ingest"), ("/odpipe/pipeline/ingest.py", "ingest"),
    ("/odpipe/media/", "media"),
    ("/odpipe/preprocess/compress.py", "compression"), ("/odpipe/preprocess/", "editing"),
    ("/odpipe/dynamics/", "integration"),
    ("/odpipe/measurements/", "light time and partials"),
    ("/odpipe/estimation/smoother.py", "smoother"),
    ("/odpipe/estimation/", "filter"), ("/odpipe/od/", "filter"),
    ("/odpipe/products/", "products"), ("/odpipe/operations/", "products"),
    ("/odpipe/pipeline/fitted_trajectory.py", "products"),
    ("/odpipe/pipeline/geometry.py", "geometry"),
    ("/odpipe/pipeline/", "set-up"),
]
ORDER = ["ingest", "set-up", "geometry", "media", "compression", "editing", "integration", "light time and partials",
         "filter", "smoother", "products", "other"]


def stage_of(frame) -> str:
    """Stage of the innermost frame on ``frame``'s stack that belongs to one."""
    while frame is not None:
        name = frame.f_code.co_filename.replace("\\", "/")
        if name.endswith("/odpipe/pipeline/run.py") and frame.f_code.co_name == "_products":
            return "products"
        for frag, stage in STAGES:
            if frag in name:
                return stage
        frame = frame.f_back
    return "other"


def fit_position(frame, calls: dict) -> tuple | None:
    """(fit call, iteration, weight stage) if ``frame`` runs inside odpipe.estimation.fit.fit."""
    while frame is not None:
        if frame.f_code.co_name == "fit" and frame.f_code.co_filename.endswith("/odpipe/estimation/fit.py"):
            loc = frame.f_locals
            call = calls.setdefault(id(frame), len(calls) + 1)
            return call, loc.get("it"), loc.get("stage")
        frame = frame.f_back
    return None


class Sampler(threading.Thread):
    """Samples the stack of thread ``ident`` every ``interval`` s; wall and CPU seconds of that thread by
    stage, CPU seconds by fit step."""

    def __init__(self, ident: int, interval: float):
        super().__init__(daemon=True)
        self.target, self.interval = ident, interval
        self.clock = time.pthread_getcpuclockid(ident)
        self.by_stage = defaultdict(float)
        self.cpu_by_stage = defaultdict(float)
        self.by_fit = defaultdict(lambda: defaultdict(float))
        self.calls: dict = {}
        self.stop = threading.Event()

    def run(self):
        last, last_cpu = time.perf_counter(), time.clock_gettime(self.clock)
        while not self.stop.wait(self.interval):
            frame = sys._current_frames().get(self.target)
            now, cpu = time.perf_counter(), time.clock_gettime(self.clock)
            dt, last = now - last, now
            dc, last_cpu = cpu - last_cpu, cpu
            if frame is None:
                continue
            stage = stage_of(frame)
            self.by_stage[stage] += dt
            self.cpu_by_stage[stage] += dc
            pos = fit_position(frame, self.calls)
            if pos is not None:
                self.by_fit[pos][stage] += dc


class Integrations:
    """Wraps ``propagate`` where the pipeline calls it: (integrations, force evaluations) by caller."""

    MODULES = ("odpipe.od.segment", "odpipe.pipeline.setup")

    def __init__(self):
        self.count = defaultdict(lambda: [0, 0])
        self.fit_calls: dict = {}

    def __enter__(self):
        import importlib
        self.saved = [(importlib.import_module(m), importlib.import_module(m).propagate) for m in self.MODULES]
        for mod, original in self.saved:
            mod.propagate = self._wrap(original)
        return self

    def __exit__(self, *exc):
        for mod, original in self.saved:
            mod.propagate = original

    def _wrap(self, original):
        def counted(*args, **kw):
            traj = original(*args, **kw)
            frame = sys._getframe(1)
            pos = fit_position(frame, self.fit_calls)
            key = f"fit {pos[0]} iteration {pos[1]}" if pos else stage_of(frame)
            while frame is not None and pos is None:
                if frame.f_code.co_name in ("fitted_segments", "reference", "a_priori_reference"):
                    key = frame.f_code.co_name
                    break
                frame = frame.f_back
            self.count[key][0] += 1
            self.count[key][1] += traj.n_eval
            return traj
        return counted


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config", nargs="?", type=Path, default=ROOT / "runs" / "grail_b_2012_04_10.toml")
    ap.add_argument("--interval", type=float, default=0.002, help="sampling interval, s")
    ap.add_argument("--cprofile", type=int, default=0, metavar="N",
                    help="also profile with cProfile on the CPU clock and print its top N functions")
    ap.add_argument("--warm", type=int, default=0, metavar="N",
                    help="run the arc N times first, unmeasured (a nightly worker's state before its next arc)")
    args = ap.parse_args(argv)
    print(f"import of the pipeline: {_IMPORT_CPU:.2f} CPU s; numba's first call: {numba_start():.2f} CPU s "
          "(both before the run)")
    if args.warm:
        import matplotlib
        matplotlib.use("Agg")
        c = time.process_time()
        try:
            for _ in range(args.warm):
                run_config(args.config, force=True, progress=None)
        except ConfigError as exc:
            print(exc)
            return 1
        print(f"{args.warm} unmeasured run(s) first: {time.process_time() - c:.1f} CPU s")
    profiler = cProfile.Profile(time.process_time) if args.cprofile else None
    sampler = Sampler(threading.get_ident(), args.interval)
    sampler.start()
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        with compile_timer() as ct, Integrations() as integ:
            if profiler is not None:
                profiler.enable()
            summary = run_config(args.config, force=True, progress=None)
    except ConfigError as exc:
        print(exc)
        return 1
    finally:
        if profiler is not None:
            profiler.disable()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    sampler.stop.set()
    sampler.join()
    print(f"{args.config.name}: {wall:.1f} s wall ({cpu:.1f} s CPU of this process), of which numba compiled {ct.functions} functions in "
          f"{ct.seconds:.1f} s; fit {summary.get('fit_seconds', float('nan')):.1f} s")
    total = sum(sampler.cpu_by_stage.values())
    print(f"\n{'stage':26s} {'wall s':>7s} {'CPU s':>7s} {'CPU share':>9s}")
    for stage in ORDER:
        s, c = sampler.by_stage.get(stage, 0.0), sampler.cpu_by_stage.get(stage, 0.0)
        if s:
            print(f"{stage:26s} {s:7.2f} {c:7.2f} {c / total:9.1%}")
    cols = [s for s in ("integration", "light time and partials", "filter", "smoother", "other")
            if any(v.get(s) for v in sampler.by_fit.values())]
    print(f"\nCPU s by fit step\n{'fit call':>8s} {'iter':>4s} {'w.stage':>7s} {'total':>7s} " + " ".join(f"{c[:12]:>12s}" for c in cols))
    for (call, it, st), v in sorted(sampler.by_fit.items(), key=lambda kv: tuple(-1 if x is None else x
                                                                                 for x in kv[0])):
        print(f"{call:8d} {it if it is not None else '-':>4} {st if st is not None else '-':>7} "
              f"{sum(v.values()):7.2f} " + " ".join(f"{v.get(c, 0.0):12.2f}" for c in cols))
    print(f"\n{'integrations called from':30s} {'calls':>6s} {'force evaluations':>18s}")
    for key, (calls, evals) in integ.count.items():
        print(f"{key:30s} {calls:6d} {evals:18d}")
    print(f"{'total':30s} {sum(c for c, _ in integ.count.values()):6d} "
          f"{sum(e for _, e in integ.count.values()):18d}")
    if profiler is not None:
        print("\ncProfile, CPU seconds")
        pstats.Stats(profiler).sort_stats("cumulative").print_stats(args.cprofile)
    return 0


if __name__ == "__main__":
    sys.exit(main())
