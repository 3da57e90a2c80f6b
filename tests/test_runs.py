"""Run configuration, run directories, reports and the nightly batch."""

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from odpipe.operations import rundir
from odpipe.operations.nightly import dependency_order, night_summary, run_batch
from odpipe.operations.report import Section, write_report
from odpipe.operations.schema import ConfigError, load

ROOT = Path(__file__).resolve().parents[1]


@dataclasses.dataclass
class Models:
    degree: int = 8
    ephemeris: str = "de440"


@dataclasses.dataclass
class Example:
    name: str
    files: list[Path]
    span_days: float = 1.0
    models: Models = dataclasses.field(default_factory=Models)


def _load(tmp_path, text):
    path = tmp_path / "run.toml"
    path.write_text(text)
    import tomllib
    return load(Example, tomllib.loads(text), path)


def test_config_resolves_paths_and_globs_against_its_folder(tmp_path):
    (tmp_path / "data").mkdir()
    for n in ("b.odf", "a.odf"):
        (tmp_path / "data" / n).write_bytes(b"")
    cfg = _load(tmp_path, 'name = "x"\nfiles = ["data/*.odf"]\nspan_days = 2\n[models]\ndegree = 50\n')
    assert cfg.files == [tmp_path / "data" / "a.odf", tmp_path / "data" / "b.odf"]
    assert cfg.span_days == 2.0 and cfg.models == Models(50, "de440")


@pytest.mark.parametrize("text, key, reason", [
    ('name = "x"\nfiles = []\n[models]\ndegre = 5\n', "models.degre", "unknown key"),
    ('name = "x"\nfiles = []\n[models]\ndegree = "5"\n', "models.degree", "expected int"),
    ('files = []\n', "name", "required key is missing"),
    ('name = "x"\nfiles = ["nothing/*.odf"]\n', "files[0]", "no file matches"),
])
def test_config_errors_name_the_key_and_file(tmp_path, text, key, reason):
    with pytest.raises(ConfigError) as err:
        _load(tmp_path, text)
    assert err.value.key == key and reason in err.value.reason
    assert str(tmp_path / "run.toml") in str(err.value)


def test_failed_attempt_keeps_previous_products(tmp_path):
    cfg = tmp_path / "arc.toml"
    cfg.write_text("seconds = 0\n")
    fp = rundir.fingerprint(cfg.read_text(), [cfg])
    good = rundir.start(tmp_path / "out")
    good.product("a.txt").write_text("good")
    good.finish(fp)
    bad = rundir.start(tmp_path / "out")
    bad.product("a.txt").write_text("partial")
    bad.fail(RuntimeError("diverged"))
    assert (tmp_path / "out" / "current" / "a.txt").read_text() == "good"
    assert "diverged" in (bad.path / "FAILED.txt").read_text()
    assert rundir.up_to_date(tmp_path / "out", fp)
    # changed software (another odpipe or parsers source) makes the arc stale
    assert fp["software_sha256"] == rundir.software_sha256() and len(fp["software_sha256"]) == 64
    assert not rundir.up_to_date(tmp_path / "out", {**fp, "software_sha256": "0" * 64})
    cfg.write_text("seconds = 1\n")  # a changed config makes the arc stale
    assert not rundir.up_to_date(tmp_path / "out", rundir.fingerprint(cfg.read_text(), [cfg]))
    (tmp_path / "out" / "current" / "a.txt").write_text("tampered")  # so does an altered product
    assert rundir.current_manifest(tmp_path / "out") is None


def test_report_embeds_tables_and_figures(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    fig.savefig(tmp_path / "p.png")
    page = write_report(tmp_path / "r.html", "Arc <1>", {"post-fit RMS (mm/s)": 0.05},
                        [Section("Residuals").text("a & b").table(pd.DataFrame({"x": [1.5]})).figure(tmp_path / "p.png", "plot")])
    text = page.read_text()
    assert "Arc &lt;1&gt;" in text and "a &amp; b" in text and "data:image/png;base64,iVBOR" in text
    assert "<td>1.5</td>" in text


def _arcs(tmp_path, n, seconds, fail=()):
    paths = []
    for k in range(n):
        p = tmp_path / f"arc{k}.toml"
        p.write_text(f"seconds = {seconds}\nfail = {'true' if k in fail else 'false'}\n")
        paths.append(p)
    return paths


@pytest.fixture(scope="module")
def scheduler():
    """Address of a local Dask cluster of two single-threaded workers in this process, started once for this module's
    in-process batches (each run_batch of its own would start and stop a cluster of worker processes: seconds of
    CPU and wall each; threads run the same tasks, outcomes and run directories without those processes' start-up).
    The cluster of worker processes that run_batch starts itself is exercised by the killed batch's subprocess
    below, tests/test_batch_faults.py and tests/test_nightly_cluster.py."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster:
        yield cluster.scheduler_address


@pytest.mark.slow
def test_one_failing_arc_does_not_stop_the_batch(tmp_path, scheduler):
    from tests.batch_job import run_arc
    configs = _arcs(tmp_path, 3, 0, fail={1})
    out = {Path(o.config).stem: o for o in run_batch(configs, run_arc, scheduler=scheduler, progress=lambda s: None)}
    assert [out[f"arc{k}"].status for k in range(3)] == ["complete", "failed", "complete"]
    assert "told to fail" in out["arc1"].error
    assert "1 failed" in night_summary(list(out.values()))
    again = run_batch(configs, run_arc, scheduler=scheduler, progress=lambda s: None)
    assert sorted(o.status for o in again) == ["failed", "skipped", "skipped"]


def test_chained_arcs_run_after_their_source_and_not_after_a_failure(tmp_path, scheduler):
    from tests.batch_job import run_arc
    c = _arcs(tmp_path, 4, 0.5, fail={0})
    after = {c[1]: [c[0]], c[2]: [c[3]]}   # arc1 starts from the failing arc0, arc2 from arc3
    outcomes = run_batch([c[2], c[1], c[0], c[3]], run_arc, after=after, scheduler=scheduler,
                         progress=lambda s: None)
    order = [Path(o.config).stem for o in outcomes]
    out = {Path(o.config).stem: o for o in outcomes}
    assert out["arc0"].status == "failed" and out["arc1"].status == "failed"
    assert "not run: it starts from arc0.toml, which failed" in out["arc1"].error
    assert not (tmp_path / "out" / "arc1").exists()
    assert out["arc2"].status == "complete" and order.index("arc3") < order.index("arc2")
    with pytest.raises(ValueError, match="cycle"):
        dependency_order(["a", "b"], {"a": ["b"], "b": ["a"]})


def test_batch_killed_midway_resumes_without_redoing_arcs(tmp_path, scheduler):
    configs = _arcs(tmp_path, 5, 0.5)   # 0.5 s per arc: the poll below (0.1 s) sees two done well before a third
    script = ("import sys; from pathlib import Path; from odpipe.operations.nightly import run_batch;"
              "from tests.batch_job import run_arc;"
              "run_batch([Path(p) for p in sys.argv[1:]], run_arc, workers=1)")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen([sys.executable, "-c", script, *map(str, configs)], cwd=tmp_path, env=env,
                            start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    out = tmp_path / "out"
    deadline = time.time() + 120
    while time.time() < deadline and len(list(out.glob("*/current"))) < 2:
        time.sleep(0.1)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    done = {p.parent.name: json.loads((p / "manifest.json").read_text())["finished"] for p in out.glob("*/current")}
    assert 2 <= len(done) < 5, "the batch should have been killed midway"
    from tests.batch_job import run_arc
    outcomes = run_batch(configs, run_arc, scheduler=scheduler, progress=lambda s: None)
    status = {Path(o.config).stem: o.status for o in outcomes}
    assert all(status[name] == "skipped" for name in done)
    assert all(status[f"arc{k}"] == "complete" for k in range(5) if f"arc{k}" not in done)
    for name, finished in done.items():  # finished arcs untouched
        assert json.loads((out / name / "current" / "manifest.json").read_text())["finished"] == finished
    for k in range(5):  # every arc now has a whole, verified product set
        assert rundir.current_manifest(out / f"arc{k}") is not None
