"""Process start-up and the nightly's fixed costs: wall and CPU seconds of fresh processes (figures printed,
never asserted).

    python benchmarks/bench_startup.py [--repeat 5] [--nightly N] [--batch runs/grail_b_nightly.toml]

Fresh processes (each ``--repeat`` times, the median and the range): ``odpipe --help``, ``odpipe batch --help``,
the import of what a batch's client needs to load its arcs (``odpipe.commands.batch``), the import of a run
(``odpipe.pipeline.run``), what a batch worker pays before its first arc (:func:`odpipe.pipeline.warmup.warm_worker`
on the nightly's arcs: the run's imports, the gravity fields, numba's cached kernels of each force model).
CPU seconds (user + system) are the process's and those of every process under it, so they mean the same on a
loaded machine.

``--nightly N`` also runs the batch (``odpipe batch CONFIG --force``, its products in the config's folders) N
times and splits each run's wall time into: before the first arc starts (command start to the earliest arc
attempt's ``started``, stamped once the worker has loaded that arc's configuration and hashed its inputs), the
arcs (to the latest arc's ``finished``), the night's report (to the printed ``report:`` line) and the exit after
it (the process's end). Run it on two checkouts in turn (interleaved) on a shared machine, and state the load
(printed); another checkout's code runs with this venv as
``PYTHONPATH=OTHER python benchmarks/bench_startup.py --batch OTHER/runs/grail_b_nightly.toml``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import threading
import time
from datetime import datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
NIGHTLY = ROOT / "runs" / "grail_b_nightly.toml"


TICK = os.sysconf("SC_CLK_TCK")


def _reaped_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _tree_cpu(root: int, seen: dict) -> None:
    """Record in ``seen`` (pid -> CPU s) the user + system seconds of ``root`` and of every process under it
    (a Dask worker forked from a server process is not reaped by the command, so its CPU never reaches
    RUSAGE_CHILDREN)."""
    parent, cpu = {}, {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                fields = Path(f"/proc/{d}/stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            parent[int(d)] = int(fields[1])
            cpu[int(d)] = (int(fields[11]) + int(fields[12])) / TICK
    tree, grown = {root}, True
    while grown:
        more = {p for p, pp in parent.items() if pp in tree} - tree
        tree |= more
        grown = bool(more)
    for p in tree & cpu.keys():
        seen[p] = max(seen.get(p, 0.0), cpu[p])


def timed(cmd: list[str], cwd: Path = ROOT) -> dict:
    """Wall and CPU s of one process and of every process under it (the larger of the reaped children's
    rusage and the sum sampled every 0.1 s from /proc, which misses each process's last tenth of a second
    but counts the processes the command does not reap), and every line it writes to stdout or stderr with its arrival time
    (s after the start; the child's output is unbuffered)."""
    cpu0, t0 = _reaped_cpu(), time.perf_counter()
    p = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env=os.environ | {"PYTHONUNBUFFERED": "1"})
    lines: list[tuple[float, str]] = []
    seen: dict[int, float] = {}

    def sample():
        while p.poll() is None:
            _tree_cpu(p.pid, seen)
            time.sleep(0.1)

    def read(stream):
        for line in stream:
            lines.append((time.perf_counter() - t0, line.rstrip("\n")))

    readers = [threading.Thread(target=read, args=(s,)) for s in (p.stdout, p.stderr)]
    readers.append(threading.Thread(target=sample))
    for r in readers:
        r.start()
    rc = p.wait()
    wall = time.perf_counter() - t0
    for r in readers:
        r.join()
    reaped, sampled = _reaped_cpu() - cpu0, sum(seen.values())
    cpu = max(reaped, sampled)
    if rc != 0:
        raise SystemExit(f"{' '.join(map(str, cmd))}: exit status {rc}\n" + "\n".join(s for _, s in lines[-20:]))
    return {"wall": wall, "cpu": cpu, "reaped": reaped, "sampled": sampled, "lines": sorted(lines),
            "start_epoch": time.time() - wall}


def fresh_processes(batch: Path, repeat: int) -> None:
    """Wall and CPU seconds of each fresh process, median and range over ``repeat``."""
    python, odpipe = str(BIN / "python"), str(BIN / "odpipe")
    arcs = [str(p) for p in _arcs(batch)]
    cases = {
        "odpipe --help": [odpipe, "--help"],
        "odpipe batch --help": [odpipe, "batch", "--help"],
        "import odpipe.commands.batch (client)": [python, "-c", "import odpipe.commands.batch"],
        "import odpipe.pipeline.run": [python, "-c", "import odpipe.pipeline.run"],
        "import + warm_worker(nightly arcs)": [python, "-c", "import sys; from odpipe.pipeline.warmup import warm_worker;"
                                               " warm_worker(sys.argv[1:])", *arcs],
    }
    print(f"fresh processes, {repeat} each (load {os.getloadavg()[0]:.1f}); median [min, max]")
    for name, cmd in cases.items():   # from the batch's folder: no package there shadows the one to measure
        runs = [timed(cmd, cwd=batch.parent) for _ in range(repeat)]
        w, c = [r["wall"] for r in runs], [r["cpu"] for r in runs]
        print(f"  {name:42s} wall {statistics.median(w):5.2f} s [{min(w):.2f}, {max(w):.2f}]   "
              f"CPU {statistics.median(c):5.2f} s [{min(c):.2f}, {max(c):.2f}]")


def _arcs(batch: Path) -> list[Path]:
    from odpipe.operations.nightly import load_batch
    return sorted(set(load_batch(batch).arcs))


def _attempt(arc: Path, after: float) -> dict:
    """The manifest of ``arc``'s newest attempt started after the epoch ``after`` (s)."""
    from odpipe.pipeline.config import load_config
    cfg = load_config(arc)
    folders = sorted((cfg.run.output / cfg.run.name / "attempts").glob("*"))
    for folder in reversed(folders):
        manifest = folder / "manifest.json"
        if manifest.is_file():
            m = json.loads(manifest.read_text())
            if datetime.fromisoformat(m["started"]).timestamp() >= after:
                return m
    raise SystemExit(f"{arc}: no complete attempt of this run")


def nightly(batch: Path) -> None:
    """One ``odpipe batch --force`` run of ``batch``, its wall time split at the first arc's start, the last arc's
    end and the printed report line."""
    load = os.getloadavg()[0]
    r = timed([str(BIN / "odpipe"), "batch", batch.name, "--force"], cwd=batch.parent)
    t0 = r["start_epoch"]
    manifests = [_attempt(a, t0) for a in _arcs(batch)]
    first = min(datetime.fromisoformat(m["started"]).timestamp() for m in manifests) - t0
    last = max(datetime.fromisoformat(m["finished"]).timestamp() for m in manifests) - t0
    report = next((t for t, line in r["lines"] if line.startswith("report:")), float("nan"))
    print(f"  nightly: wall {r['wall']:5.1f} s, CPU {r['cpu']:5.1f} s (reaped {r['reaped']:.1f}, sampled "
          f"{r['sampled']:.1f}; load {load:.1f} before): before the first arc "
          f"{first:4.2f} s, arcs {last - first:5.2f} s, report {report - last:4.2f} s, exit after the report "
          f"{r['wall'] - report:4.2f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="fresh processes of each kind")
    ap.add_argument("--nightly", type=int, default=0, help="runs of the batch (default none)")
    ap.add_argument("--batch", type=Path, default=NIGHTLY, help="the batch configuration")
    ap.add_argument("--no-fresh", action="store_true", help="only the batch runs")
    args = ap.parse_args()
    batch = args.batch.resolve()
    if not args.no_fresh:
        fresh_processes(batch, args.repeat)
    for _ in range(args.nightly):
        nightly(batch)


if __name__ == "__main__":
    main()
