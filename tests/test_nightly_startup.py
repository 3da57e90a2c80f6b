"""The nightly's start-up and exit: workers forked from a server holding the run's imports, the caller's
preparation while the arcs run, a process exiting without the final garbage collections, and `odpipe batch
--help` without the pipeline's imports."""

import subprocess
import sys
import textwrap
import threading

from odpipe.operations.nightly import run_batch


def _fresh(code: str) -> subprocess.CompletedProcess:
    """``code`` in a fresh interpreter (the fork server and the at-exit handlers are per process)."""
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return out


def test_workers_start_with_the_imports_asked_for_and_spawned_workers_hash_seed():
    """Asked for odpipe.operations.report, each worker has it before its arc imports anything; a module nobody
    asked for (odpipe.operations.reference) is not there. Both workers hash strings as a fresh interpreter
    with Dask's PYTHONHASHSEED for spawned workers (6640) does."""
    out = _fresh("""
        import sys
        from odpipe.operations.nightly import run_batch, start_local_cluster

        def arc(path):
            return {"status": "complete", "asked": "odpipe.operations.report" in sys.modules,
                    "not asked": "odpipe.operations.reference" in sys.modules, "hash": hash("odpipe")}

        if __name__ == "__main__":
            cluster = start_local_cluster(2, ("odpipe.operations.report",))
            out = run_batch(["a.toml", "b.toml"], arc, cluster=cluster, progress=lambda s: None)
            for o in out:
                print(o.detail["asked"], o.detail["not asked"], o.detail["hash"])
    """)
    seeded = subprocess.run([sys.executable, "-c", "print(hash('odpipe'))"], capture_output=True, text=True,
                            env={"PYTHONHASHSEED": "6640"}).stdout.strip()
    assert out.stdout.splitlines() == [f"True False {seeded}"] * 2


def _complete(path):
    return {"status": "complete"}


def test_the_callers_preparation_runs_in_a_background_thread_and_its_failure_is_not_the_batchs(caplog):
    threads = []

    def prepare():
        threads.append(threading.current_thread().name)
        raise OSError("cannot prepare the report")

    out = run_batch(["a.toml"], _complete, workers=1, meanwhile=prepare, progress=lambda s: None)
    assert [o.status for o in out] == ["complete"]
    assert threads == ["prepare what follows the arcs"] and "cannot prepare the report" in caplog.text


def test_a_process_exits_with_its_objects_frozen():
    """An at-exit handler registered before runs after the freeze (last in, first out): it sees the objects
    frozen, which they are not before the exit."""
    out = _fresh("""
        import atexit, gc
        atexit.register(lambda: print("at exit", gc.get_freeze_count() > 0))
        from odpipe.operations.quick_exit import skip_final_collection
        skip_final_collection()
        print("before exit", gc.get_freeze_count() > 0)
    """)
    assert out.stdout.splitlines() == ["before exit False", "at exit True"]


def test_batch_help_does_not_import_the_pipeline():
    out = _fresh("""
        import sys
        from odpipe.cli import build_parser
        build_parser("batch").parse_args(["batch", "nightly.toml"])
        print(sorted(m for m in ("odpipe.pipeline.config", "pandas", "numba", "distributed") if m in sys.modules))
    """)
    assert out.stdout.strip() == "[]"
