"""Scenario configurations: TOML whose file entries are relative to the configuration.

Entries named ``*_file`` or ``*_gravity`` (at any depth) hold paths; a relative one is taken
from the configuration's folder, so ``runs/liaison_*.toml`` point at ``../../shared/data``
and run from any working directory.
"""

from __future__ import annotations

import tomllib
from pathlib import Path


def _resolve(node, base: Path):
    if isinstance(node, dict):
        return {k: (str(base / v) if isinstance(v, str) and k.endswith(("_file", "_gravity"))
                    and not Path(v).is_absolute() else _resolve(v, base)) for k, v in node.items()}
    return node


def load_config(path) -> dict:
    """The scenario configuration at ``path`` with its file entries resolved."""
    path = Path(path)
    return _resolve(tomllib.loads(path.read_text()), path.resolve().parent)
