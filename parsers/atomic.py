"""Atomic, durable file writes: a file appears whole or not at all, and stays after a crash.

The one home of atomic writing for the whole project (the format writers of
``parsers`` and every product, table, plot and report of ``odpipe``); it lives
here because ``parsers`` imports no ``odpipe`` module (but ``odpipe.constants``),
while ``odpipe`` imports ``parsers``.

A write goes to a temporary file in the destination folder
(``.NAME.HOST-PID.RANDOM.part``), which is flushed and fsynced, renamed over the
destination, and the folder is fsynced so the rename itself survives a power
loss. A writer that fails removes its temporary file; one that is killed
leaves it behind, and the next write of the same destination on the same host
removes temporaries whose process is gone.
"""

from __future__ import annotations

import glob
import os
import socket
import tempfile
from contextlib import contextmanager
from pathlib import Path

_SUFFIX = ".part"


def fsync_dir(folder) -> None:
    """fsync a folder, so that entries renamed or created in it are on disk."""
    fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_file(path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def pid_alive(pid: int, started: float | None = None) -> bool:
    """True when process ``pid`` runs on this host (a zombie counts as gone) and, when ``started``
    (Unix s) is given, it started before then (a later process with the same id is another one)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
        if fields[0] == b"Z":
            return False
        if started is not None:
            with open("/proc/stat", "rb") as f:
                boot = next(float(line.split()[1]) for line in f if line.startswith(b"btime"))
            return boot + int(fields[19]) / os.sysconf("SC_CLK_TCK") <= started + 1.0
    except (OSError, StopIteration, IndexError, ValueError):
        pass
    return True


def _owner() -> str:
    return f"{socket.gethostname()}-{os.getpid()}"


def _remove_stale(path: Path) -> None:
    """Remove temporaries of ``path`` left by killed writers of this host."""
    host = socket.gethostname()
    for tmp in path.parent.glob(f".{glob.escape(path.name)}.{glob.escape(host)}-*{_SUFFIX}"):
        pid = tmp.name[len(path.name) + len(host) + 3:].split(".", 1)[0]
        if pid.isdigit() and not pid_alive(int(pid)):
            tmp.unlink(missing_ok=True)


@contextmanager
def atomic_path(path):
    """Yield a temporary path (not yet created) beside ``path``; when the block succeeds the
    file written there is fsynced and renamed to ``path`` and the folder fsynced."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _remove_stale(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{_owner()}.", suffix=_SUFFIX, dir=path.parent)
    os.close(fd)
    os.unlink(tmp)  # writers such as SPICE refuse to open an existing file
    tmp = Path(tmp)
    try:
        yield tmp
        os.chmod(tmp, 0o644)
        _fsync_file(tmp)
        os.replace(tmp, path)
        fsync_dir(path.parent)
    finally:
        tmp.unlink(missing_ok=True)


def write_bytes(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; returns the path."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_text(path, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically; returns the path."""
    return write_bytes(path, text.encode(encoding))


def write_parquet(path, df, **kwargs) -> Path:
    """Write a DataFrame as Parquet atomically (``kwargs`` to ``DataFrame.to_parquet``)."""
    with atomic_path(path) as tmp:
        df.to_parquet(tmp, **kwargs)
    return Path(path)


def write_csv(path, df, **kwargs) -> Path:
    """Write a DataFrame as CSV atomically (``kwargs`` to ``DataFrame.to_csv``)."""
    return write_text(path, df.to_csv(**kwargs))


def save_figure(path, fig, **kwargs) -> Path:
    """Save a matplotlib figure atomically, in the format of the file's suffix (``kwargs`` to ``savefig``)."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", **kwargs)
    return path
