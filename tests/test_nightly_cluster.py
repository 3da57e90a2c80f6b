"""The nightly's local Dask cluster: its workers' environment, warm-up and how chained arcs are placed."""

import os
import threading
import time

from odpipe.operations.nightly import _local_cluster, chain_lengths, run_batch


def _environment(path):
    return {"status": "complete", "trim": os.environ.get("MALLOC_TRIM_THRESHOLD_"),
            "blas": os.environ.get("OPENBLAS_NUM_THREADS")}


def _failing_warm(configs):
    raise OSError(f"cannot warm for {configs}")


def test_workers_keep_glibc_heap_trimming_and_one_blas_thread(monkeypatch):
    """Dask's default MALLOC_TRIM_THRESHOLD_ (64 kB) would fix glibc's mmap threshold: every large array
    mapped and unmapped again. The workers run without it, BLAS on one thread as before."""
    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    from distributed import Client

    cluster = _local_cluster(1)
    try:
        with Client(cluster) as client:
            env = client.submit(_environment, "x", pure=False).result()
    finally:
        cluster.close()
    assert env["trim"] is None and env["blas"] == "1"


def test_a_worker_warm_up_that_fails_is_not_the_arcs_failure():
    out = run_batch(["a.toml", "b.toml"], _environment, workers=2, warm=_failing_warm, progress=lambda s: None)
    assert sorted(o.status for o in out) == ["complete", "complete"]


def _timed(path):
    t0 = time.time()
    time.sleep(1.0)
    return {"status": "complete", "pid": os.getpid(), "start": t0, "end": time.time()}


def test_two_arcs_from_one_source_run_at_once_on_two_workers():
    """GRAIL's nightly: 04-08 and 04-10 both start from 04-09. Sent with 04-09's outcome as a Dask dependency
    they both went to 04-09's worker, and 04-10 waited 2 s for work stealing; each now goes to a free worker.
    Work stealing is off here, so only where an arc is sent decides where it runs."""
    import dask

    after = {"b.toml": ["a.toml"], "c.toml": ["a.toml"], "d.toml": ["c.toml"]}
    with dask.config.set({"distributed.scheduler.work-stealing": False}):
        out = {o.config: o.detail for o in run_batch(["a.toml", "b.toml", "c.toml", "d.toml"], _timed, after=after,
                                                     workers=2, progress=lambda s: None)}
        for closing in [t for t in threading.enumerate() if t.name == "close the local Dask cluster"]:
            closing.join()   # it reads the configuration set here
    b, c = out["b.toml"], out["c.toml"]
    assert b["pid"] != c["pid"] and b["start"] < c["end"] and c["start"] < b["end"]
    assert min(b["start"], c["start"]) >= out["a.toml"]["end"] and out["d.toml"]["start"] >= c["end"]


def test_the_arc_leading_the_longest_chain_ranks_first():
    sources = {"09": ["start"], "08": ["09"], "10": ["09"], "11": ["10"]}
    assert chain_lengths(["start", "09", "08", "10", "11"], sources) == {"start": 4, "09": 3, "10": 2, "08": 1,
                                                                           "11": 1}
