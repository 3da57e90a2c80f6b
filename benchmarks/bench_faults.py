"""Fault test of the nightly batch: SIGKILL at random moments, rerun, nothing lost, corrupted or fitted twice.

A night of ``--arcs`` simulated 6-h arcs (the cislunar HEO of ``tests/heo_case.py`` tracked by three DSN
sites, Doppler and range; consecutive arcs overlap by 2 h) runs as ``odpipe batch`` on a local Dask
cluster of two worker processes. Its whole process group (client, nanny and workers) is SIGKILLed after
a random delay (uniform in ``--min-delay``..``--max-delay`` s; by default up to the length of a first
night run whole, about 10 s on the idle 2-core machine in 2026-11) and the batch is run again, until ``--kills`` kills have hit a running batch. After every kill: each arc
finished before it is still current with the same manifest, and every ``current`` verifies against its
manifest's checksums. When a run ends before its kill, the night is complete and checked, and a new
night starts from the same inputs: every arc and the night's report are complete, every product parses,
each arc has exactly one complete attempt (no arc fitted twice), every other attempt folder is marked
abandoned, and no temporary file is left.

Run: ``.venv/bin/python benchmarks/bench_faults.py [--kills 20] [--arcs 6] [--min-delay 1] [--max-delay S] [--seed 1]
[--from-fit]`` (``--from-fit``: the delay counts from the first arc's start instead of the batch's).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

START = np.datetime64("2003-06-03T00:00:00", "s")
ARC_H, STEP_H = 6, 4   # arc length and start spacing (h)
NAIF_ID = -900         # of arc 0; arc k is NAIF_ID - k


def write_night(folder: Path, arcs: int = 6, seed: int = 7) -> Path:
    """Simulated tracking over the night and one run config per arc, a priori 700 m / 5 mm/s off; the batch config."""
    from heo_case import simulate, write_config, tdb

    folder.mkdir(parents=True, exist_ok=True)
    starts = [START + np.timedelta64(k * STEP_H, "h") for k in range(arcs)]
    end = starts[-1] + np.timedelta64(ARC_H, "h")
    truth, _ = simulate(folder, str(starts[0]), str(end), seed=seed)
    for k, s in enumerate(starts):
        x = truth.state(tdb(str(s)))[0] + np.r_[500.0, -400.0, 300.0, 0.004, -0.003, 0.002]
        write_config(folder, f"arc{k}", str(s), str(s + np.timedelta64(ARC_H, "h")), x,
                     naif_id=NAIF_ID - k).rename(folder / f"arc{k}.toml")
    batch = folder / "batch.toml"
    batch.write_text('[batch]\narcs = ["arc*.toml"]\nworkers = 2\nreport = "night"\n')
    return batch


def start_batch(batch: Path, log) -> subprocess.Popen:
    """``odpipe batch`` in its own process group (the Dask cluster's processes join it)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.Popen([sys.executable, "-c", "import sys; from odpipe.cli import main; sys.exit(main())",
                             "batch", str(batch)], cwd=batch.parent, env=env, start_new_session=True,
                            stdout=log, stderr=subprocess.STDOUT)


def kill_group(proc: subprocess.Popen) -> int:
    """SIGKILL every process of the batch's group; returns how many were alive."""
    pids = [p for p in os.listdir("/proc") if p.isdigit() and _pgid(int(p)) == proc.pid]
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    deadline = time.time() + 30
    while time.time() < deadline and any(_pgid(int(p)) == proc.pid for p in os.listdir("/proc") if p.isdigit()):
        time.sleep(0.05)
    return len(pids)


def _pgid(pid: int) -> int | None:
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
        return None if fields[0] == b"Z" else int(fields[2])
    except (OSError, IndexError, ValueError):
        return None


def attempts(out: Path) -> set:
    """Every attempt folder of every arc so far."""
    return set(out.glob("*/attempts/*"))


def wait_for_fitting(out: Path, proc: subprocess.Popen, timeout: float = 300.0) -> None:
    """Return once the batch ``proc`` has started an arc (a new attempt folder under ``out``) or has ended."""
    before, deadline = attempts(out), time.time() + timeout
    while proc.poll() is None and not attempts(out) - before and time.time() < deadline:
        time.sleep(0.05)


def finished(out: Path) -> dict:
    """arc -> its current manifest's finish time; asserts that every ``current`` verifies."""
    from odpipe.operations import rundir

    done = {}
    for root in sorted(p for p in out.iterdir() if p.is_dir()):
        if (root / "current").is_symlink() or (root / "current").exists():
            m = rundir.current_manifest(root)
            assert m is not None, f"{root / 'current'}: products do not match the manifest"
            done[root.name] = m["finished"]
    return done


def check_products(run: Path, naif_id: int) -> int:
    """Parse every product of one arc's current attempt; returns how many."""
    import matplotlib.image
    import pandas as pd

    from odpipe.estimation.solution import Solution
    from odpipe.products.spk import SpkTrajectory
    from parsers import oem

    n = 0
    for p in sorted(run.iterdir()):
        if p.suffix == ".oem":
            assert len(oem.read(p)[0].epochs) > 10, p
        elif p.suffix == ".bsp":
            traj = SpkTrajectory(p, naif_id)
            assert np.isfinite(traj.state(traj.t0 + 60.0)).all(), p
        elif p.suffix == ".parquet":
            assert len(pd.read_parquet(p)), p
        elif p.suffix == ".csv":
            pd.read_csv(p)
        elif p.suffix == ".json":
            json.loads(p.read_text())
        elif p.suffix == ".npz":
            assert Solution.load(p).converged, p
        elif p.suffix == ".png":
            assert matplotlib.image.imread(p).ndim == 3, p
        elif p.suffix == ".html":
            assert p.read_text().rstrip().endswith("</html>"), p
        elif p.suffix == ".log":
            assert "complete; products in" in p.read_text(), p
        else:
            raise AssertionError(f"unexpected product {p}")
        n += 1
    return n


def check_night(folder: Path, arcs: int) -> dict:
    """The end state: every arc once, every product parsing, the report complete, no temporaries."""
    import pandas as pd

    from odpipe.operations import rundir

    out = folder / "out"
    counts = {"products": 0, "abandoned": 0}
    for k in range(arcs):
        root = out / f"arc{k}"
        complete, abandoned, other = [], [], []
        for a in sorted((root / "attempts").iterdir()):
            (complete if (a / rundir.MANIFEST).exists() else abandoned if (a / rundir.ABANDONED).exists()
             else other).append(a)
        assert len(complete) == 1, f"arc{k} fitted {len(complete)} times: {complete}"
        assert not other, f"arc{k}: attempts neither complete nor abandoned: {other}"
        assert (root / "current").resolve() == complete[0].resolve()
        counts["products"] += check_products(root / "current", NAIF_ID - k)
        counts["abandoned"] += len(abandoned)
    night = folder / "night"
    stats = pd.read_csv(night / "residual_statistics.csv")
    assert sorted(set(stats["arc"])) == [f"arc{k}" for k in range(arcs)], stats["arc"].unique()
    overlaps = pd.read_csv(night / "overlap_arcs.csv")
    assert len(overlaps) == arcs - 1 + 2, overlaps["overlap"].tolist()   # consecutive pairs, mean, std
    html = (night / "report.html").read_text()
    assert html.rstrip().endswith("</html>") and f"{arcs} arcs:" in html and "Failed arcs" not in html
    left = sorted(str(p) for p in folder.rglob("*.part")) + sorted(str(p) for p in out.glob("*/.current.*"))
    assert not left, f"temporary files left: {left}"
    return counts


def fault_loop(folder: Path, kills: int, arcs: int = 6, min_delay: float = 1.0, max_delay: float | None = None,
               seed: int = 1, say=print, from_fit: bool = False) -> dict:
    """Run the batch and SIGKILL it after a random delay until ``kills`` kills have hit a running batch.

    The delay counts from the batch's start, or (``from_fit``) from its first arc starting, so that a kill
    lands among the fits whatever the machine's load makes of the start-up. Without ``max_delay`` a first
    night runs whole and the delays are drawn up to its length (measured the same way), so the kills land
    inside a night on a fast machine and a slow one alike. A run that ends before its kill is a finished
    night: it is checked (:func:`check_night`) and its outputs removed, and the next run starts a new night
    from the same inputs; after the last kill the batch runs to the end and that night is checked too."""
    rng = np.random.default_rng(seed)
    batch = write_night(folder, arcs)
    out, night = folder / "out", folder / "night"
    rows, nights, t_all = [], [], time.perf_counter()
    abandoned = products = 0

    def night_done(seconds: float) -> None:
        nonlocal abandoned, products
        counts = check_night(folder, arcs)
        abandoned, products = abandoned + counts["abandoned"], products + counts["products"]
        nights.append({"night": len(nights) + 1, "kills": sum(r["night"] == len(nights) + 1 for r in rows),
                       "abandoned_attempts": counts["abandoned"], "last_run_s": round(seconds, 1)})
        say(f"night {len(nights)} complete after {nights[-1]['kills']} kill(s): every check passed, "
            f"{counts['abandoned']} abandoned attempt(s) cleaned")
        shutil.rmtree(out)
        shutil.rmtree(night)

    with open(folder / "batch.log", "ab") as log:
        if max_delay is None:
            out.mkdir(exist_ok=True)
            proc, t0 = start_batch(batch, log), time.perf_counter()
            if from_fit:
                wait_for_fitting(out, proc)
            t1 = time.perf_counter()
            rc = proc.wait()
            assert rc == 0, f"a batch run failed (rc {rc}); see {folder / 'batch.log'}"
            max_delay = time.perf_counter() - (t1 if from_fit else t0)
            night_done(time.perf_counter() - t0)
            say(f"kills drawn {min_delay:.1f}-{max_delay:.1f} s after the "
                + ("first arc's start" if from_fit else "batch's start") + ": the first night's length")
        while len(rows) < kills:
            out.mkdir(exist_ok=True)
            before = finished(out)
            delay = float(rng.uniform(min_delay, max_delay))
            proc, t0 = start_batch(batch, log), time.perf_counter()
            if from_fit:
                wait_for_fitting(out, proc)
            fitting = time.perf_counter() - t0
            try:
                rc = proc.wait(timeout=delay)
                assert rc == 0, f"a batch run failed (rc {rc}); see {folder / 'batch.log'}"
                night_done(time.perf_counter() - t0)
                continue
            except subprocess.TimeoutExpired:
                n_proc = kill_group(proc)
            after = finished(out)
            lost = {a: f for a, f in before.items() if after.get(a) != f}
            assert not lost, f"kill {len(rows) + 1}: finished arcs lost or redone: {lost}"
            rows.append({"kill": len(rows) + 1, "night": len(nights) + 1, "delay_s": round(delay, 1),
                         "first_arc_s": round(fitting, 1) if from_fit else None,
                         "processes_killed": n_proc, "arcs_done_before": len(before), "arcs_done_after": len(after)})
            say(f"kill {len(rows)}/{kills} (night {len(nights) + 1}) after {delay:.1f} s"
                + (f" from the first arc's start ({fitting:.1f} s after the batch's)" if from_fit else "")
                + f": {n_proc} processes killed, {len(after)}/{arcs} arcs done "
                f"({len(after) - len(before)} in this run)")
        proc, t0 = start_batch(batch, log), time.perf_counter()
        rc = proc.wait()
    assert rc == 0, f"the last batch run failed (rc {rc}); see {folder / 'batch.log'}"
    night_done(time.perf_counter() - t0)
    summary = {"kills": len(rows), "arcs": arcs, "nights": len(nights),
               "processes_killed": sum(r["processes_killed"] for r in rows),
               "kills_with_arcs_finishing_before": sum(r["arcs_done_after"] > r["arcs_done_before"] for r in rows),
               "abandoned_attempts": abandoned, "products_parsed": products,
               "total_s": round(time.perf_counter() - t_all, 1), "per_kill": rows, "per_night": nights}
    say(json.dumps({k: v for k, v in summary.items() if k not in ("per_kill", "per_night")}))
    return summary


def main() -> None:
    import tempfile

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kills", type=int, default=20)
    ap.add_argument("--arcs", type=int, default=6)
    ap.add_argument("--min-delay", type=float, default=1.0,
                    help="s after the batch's start (--from-fit: its first arc's), at the earliest")
    ap.add_argument("--max-delay", type=float,
                    help="s after the batch's start (--from-fit: its first arc's), at the latest (default: the "
                         "length of a first, whole night)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--from-fit", action="store_true", help="count the delay from the first arc's start")
    ap.add_argument("--keep", type=Path, help="work in this folder (kept) instead of a temporary one")
    args = ap.parse_args()
    if args.keep:
        fault_loop(args.keep, args.kills, args.arcs, args.min_delay, args.max_delay, args.seed, from_fit=args.from_fit)
        return
    with tempfile.TemporaryDirectory() as tmp:
        fault_loop(Path(tmp), args.kills, args.arcs, args.min_delay, args.max_delay, args.seed, from_fit=args.from_fit)


if __name__ == "__main__":
    main()
