"""Scenario configurations: TOML whose file entries are relative to the configuration.

Entries named ``*_file`` or ``*_gravity`` (at any depth) hold paths; a relative one is taken
from the configuration's folder, so ``runs/liaison_*.toml`` point at ``../../shared/data``
and run from any working directory. ``base = "other.toml"`` starts from that configuration:
tables merge key by key, everything else (values, lists, arrays of tables) is replaced.
"""

from __future__ import annotations

import tomllib
from pathlib import Path


def _resolve(node, base: Path):
    if isinstance(node, dict):
        return {k: (str(base / v) if isinstance(v, str) and k.endswith(("_file", "_gravity"))
                    and not Path(v).is_absolute() else _resolve(v, base)) for k, v in node.items()}
    return node


def _merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def load_config(path, _seen=()) -> dict:
    """The scenario configuration at ``path`` on its ``base``, file entries resolved."""
    path = Path(path).resolve()
    if path in _seen:
        raise ValueError(f"{path}: configuration bases form a cycle")
    try:
        cfg = _resolve(tomllib.loads(path.read_text()), path.parent)
    except tomllib.TOMLDecodeError as err:
        raise ValueError(f"{path}: {err}") from err
    if "base" not in cfg:
        return cfg
    base = load_config(path.parent / cfg.pop("base"), (*_seen, path))
    return _merge(base, cfg)
