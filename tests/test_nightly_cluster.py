"""The nightly's local Dask cluster: its workers' environment and warm-up."""

import os

from odpipe.operations.nightly import _local_cluster, run_batch


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
