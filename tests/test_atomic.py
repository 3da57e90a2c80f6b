"""The one atomic writer (parsers.atomic) and the clean-up of killed runs' attempt folders (odpipe.operations.rundir)."""

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from parsers import atomic
from odpipe.operations import rundir

ROOT = Path(__file__).resolve().parents[1]


def _parts(folder: Path) -> list[Path]:
    return sorted(folder.rglob("*.part"))


def test_helpers_write_what_their_readers_read_back(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    df = pd.DataFrame({"a": [1.5, -2.0], "b": ["x", "y"]})
    atomic.write_text(tmp_path / "t.txt", "héllo\n")
    atomic.write_bytes(tmp_path / "b.bin", b"\x00\xff")
    atomic.write_parquet(tmp_path / "d.parquet", df, index=False)
    atomic.write_csv(tmp_path / "sub" / "d.csv", df, index=False)
    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    atomic.save_figure(tmp_path / "f.png", fig, dpi=50)
    plt.close(fig)
    assert (tmp_path / "t.txt").read_bytes() == "héllo\n".encode()
    assert (tmp_path / "b.bin").read_bytes() == b"\x00\xff"
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "d.parquet"), df)
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "sub" / "d.csv"), df)
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert oct((tmp_path / "t.txt").stat().st_mode & 0o777) == "0o644"
    assert not _parts(tmp_path)


def test_file_and_folder_are_fsynced_around_the_rename(tmp_path, monkeypatch):
    synced = []
    real = os.fsync

    def spy(fd):
        synced.append((os.readlink(f"/proc/self/fd/{fd}"), (tmp_path / "x.txt").exists()))
        real(fd)

    monkeypatch.setattr(os, "fsync", spy)
    atomic.write_text(tmp_path / "x.txt", "data")
    (tmp_file, renamed_before), (folder, renamed_after) = synced
    assert re.fullmatch(r"\.x\.txt\..+\.part", Path(tmp_file).name) and not renamed_before
    assert folder == str(tmp_path) and renamed_after


def test_a_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    atomic.write_text(tmp_path / "x.txt", "old")
    with pytest.raises(ZeroDivisionError):
        with atomic.atomic_path(tmp_path / "x.txt") as tmp:
            tmp.write_text("half")
            1 / 0
    assert (tmp_path / "x.txt").read_text() == "old" and not _parts(tmp_path)


_SLOW_WRITER = """
import sys, time
from parsers.atomic import atomic_path
with atomic_path(sys.argv[1]) as tmp:
    with open(tmp, "w") as f:
        f.write("partial"); f.flush()
        print("writing", flush=True)
        time.sleep(60)
"""


def test_a_killed_writer_leaves_the_old_file_and_its_temporary_is_removed_next_time(tmp_path):
    dest = tmp_path / "x.txt"
    atomic.write_text(dest, "old")
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_WRITER, str(dest)], stdout=subprocess.PIPE,
                            env=dict(os.environ, PYTHONPATH=str(ROOT)), text=True)
    assert proc.stdout.readline() == "writing\n"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert dest.read_text() == "old"
    (stale,) = _parts(tmp_path)
    assert stale.read_text() == "partial" and f"-{proc.pid}." in stale.name
    atomic.write_text(dest, "new")
    assert dest.read_text() == "new" and not _parts(tmp_path)


def test_a_live_writers_temporary_is_not_touched(tmp_path):
    with atomic.atomic_path(tmp_path / "x.txt") as mine:
        mine.write_text("in progress")
        atomic.write_text(tmp_path / "x.txt", "other")   # another writer of the same file, same process
        assert mine.read_text() == "in progress"
    assert (tmp_path / "x.txt").read_text() == "in progress"


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_a_killed_attempt_is_emptied_and_marked_abandoned_by_the_next_run(tmp_path):
    cfg = tmp_path / "arc.toml"
    cfg.write_text("x = 1\n")
    fp = rundir.fingerprint(cfg.read_text(), [cfg])
    good = rundir.start(tmp_path / "out")
    atomic.write_text(good.product("a.txt"), "good")
    good.finish(fp)
    # a run killed mid-way: an attempt folder with a partial product whose owner process is gone
    pid = _dead_pid()
    stale = tmp_path / "out" / "attempts" / f"20000101T000000000000Z-{pid}"
    stale.mkdir()
    (stale / "attempt.json").write_text(json.dumps({"host": os.uname().nodename, "pid": pid, "started": 0.0}))
    (stale / "a.txt").write_text("parti")
    (stale / ".b.csv.x-1.abc.part").write_text("tmp")
    # a running attempt (this process) and a failed one are left alone
    running = rundir.start(tmp_path / "out")
    atomic.write_text(running.product("a.txt"), "in progress")
    failed = rundir.start(tmp_path / "out")
    failed.fail(RuntimeError("diverged"))
    assert rundir.up_to_date(tmp_path / "out", fp)         # the next run settles the folder first
    assert sorted(p.name for p in stale.iterdir()) == ["ABANDONED.txt"]
    note = json.loads((stale / "ABANDONED.txt").read_text())
    assert note["owner"]["pid"] == pid and note["removed"] == [".b.csv.x-1.abc.part", "a.txt", "attempt.json"]
    assert (running.path / "a.txt").read_text() == "in progress"
    assert (failed.path / "FAILED.txt").exists() and not (failed.path / "ABANDONED.txt").exists()
    assert (tmp_path / "out" / "current" / "a.txt").read_text() == "good"
    assert rundir.settle(tmp_path / "out") == []          # marked once


def test_an_attempt_of_a_reused_process_id_is_abandoned(tmp_path):
    """The owner's id now belongs to a process that started after the attempt (this one)."""
    stale = tmp_path / "out" / "attempts" / f"20000101T000000000000Z-{os.getpid()}"
    stale.mkdir(parents=True)
    (stale / "attempt.json").write_text(json.dumps({"host": os.uname().nodename, "pid": os.getpid(),
                                                    "started": time.time() - 86400.0}))
    assert rundir.settle(tmp_path / "out") == [stale]


def test_a_run_killed_between_its_manifest_and_the_switch_becomes_current(tmp_path):
    cfg = tmp_path / "arc.toml"
    cfg.write_text("x = 1\n")
    fp = rundir.fingerprint(cfg.read_text(), [cfg])
    first = rundir.start(tmp_path / "out")
    atomic.write_text(first.product("a.txt"), "first")
    first.finish(fp)
    second = rundir.start(tmp_path / "out")
    atomic.write_text(second.product("a.txt"), "second")
    link = tmp_path / "out" / "current"
    target = os.readlink(link)
    second.finish({**fp, "config_sha256": "new"})
    link.unlink()                                          # as if killed before the switch
    link.symlink_to(target)
    assert (link / "a.txt").read_text() == "first"
    assert not rundir.up_to_date(tmp_path / "out", fp)     # the newest complete attempt is current again
    assert (link / "a.txt").read_text() == "second"
    assert rundir.up_to_date(tmp_path / "out", {**fp, "config_sha256": "new"})


_IN_PLACE = [re.compile(p) for p in (
    r"\.to_parquet\(", r"\.savefig\(", r"os\.replace\(", r"\.write_text\(", r"\.write_bytes\(", r"np\.save\w*\((?!buf\b)",
    r"tempfile\.mkstemp", r"shutil\.copy", r"\bopen\([^)]*[\"'][wax]b?[\"']", r"\.to_csv\(\s*(?!\)|\w+\s*=)")]


def test_every_product_table_plot_and_report_goes_through_the_atomic_writer():
    """No module of odpipe, parsers or runs writes a file in place or has its own atomic write."""
    allowed = {"parsers/atomic.py", "odpipe/operations/rundir.py"}   # the writer itself; the ``current`` link switch
    found = []
    for folder in ("odpipe", "parsers", "runs"):
        for f in sorted((ROOT / folder).rglob("*.py")):
            rel = str(f.relative_to(ROOT))
            if rel in allowed:
                continue
            for n, line in enumerate(f.read_text().splitlines(), 1):
                code = line.split("#", 1)[0]
                if any(p.search(code) for p in _IN_PLACE):
                    found.append(f"{rel}:{n}: {line.strip()}")
    assert not found, "\n".join(found)
