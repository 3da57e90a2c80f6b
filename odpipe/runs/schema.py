"""Strict loading of TOML configuration into dataclasses.

A configuration section is a dataclass; its fields' type hints say what the
TOML may hold. Unknown keys, wrong types and missing required keys are errors
that name the key path and the file. Fields typed ``Path`` (or lists of
them) resolve relative to the configuration file's folder; strings with glob
characters in a ``list[Path]`` field are expanded there too.
"""

from __future__ import annotations

import dataclasses
import glob
import types
import typing
from pathlib import Path


class ConfigError(ValueError):
    """A configuration file is wrong: names the file and the key."""

    def __init__(self, path, key: str, reason: str):
        self.path, self.key, self.reason = str(path), key, reason
        super().__init__(f"{path}: [{key}] {reason}" if key else f"{path}: {reason}")


def load(cls, data: dict, path: Path, key: str = ""):
    """Build dataclass ``cls`` from the TOML table ``data`` read from ``path``."""
    if not isinstance(data, dict):
        raise ConfigError(path, key, f"expected a table, got {type(data).__name__}")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise ConfigError(path, _join(key, unknown[0]), f"unknown key (allowed: {', '.join(sorted(fields))})")
    values = {}
    for name, f in fields.items():
        sub = _join(key, name)
        if name in data:
            values[name] = _convert(hints[name], data[name], path, sub)
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise ConfigError(path, sub, "required key is missing")
    return cls(**values)


def _join(key, name):
    return f"{key}.{name}" if key else name


def _convert(hint, value, path: Path, key: str):
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        options = [a for a in args if a is not type(None)]
        errors = []
        for opt in options:
            try:
                return _convert(opt, value, path, key)
            except ConfigError as err:
                errors.append(err.reason)
        raise ConfigError(path, key, " or ".join(errors))
    if dataclasses.is_dataclass(hint):
        return load(hint, value, path, key)
    if origin is list:
        if not isinstance(value, list):
            raise ConfigError(path, key, f"expected a list, got {type(value).__name__}")
        if args and args[0] is Path:
            return [p for i, v in enumerate(value) for p in _expand(v, path, f"{key}[{i}]")]
        return [_convert(args[0], v, path, f"{key}[{i}]") for i, v in enumerate(value)] if args else value
    if origin is dict:
        if not isinstance(value, dict):
            raise ConfigError(path, key, f"expected a table, got {type(value).__name__}")
        return {k: _convert(args[1], v, path, f"{key}.{k}") for k, v in value.items()} if args else value
    if hint is Path:
        if not isinstance(value, str):
            raise ConfigError(path, key, f"expected a path string, got {type(value).__name__}")
        return (path.parent / value).resolve()
    if hint is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(path, key, f"expected a number, got {value!r}")
        return float(value)
    if hint is typing.Any:
        return value
    if hint in (int, str, bool):
        if type(value) is not hint:
            raise ConfigError(path, key, f"expected {hint.__name__}, got {value!r}")
        return value
    if origin is typing.Literal:
        if value not in args:
            raise ConfigError(path, key, f"expected one of {list(args)}, got {value!r}")
        return value
    raise TypeError(f"schema type {hint!r} of {key} is not supported")


def _expand(value, path: Path, key: str) -> list[Path]:
    if not isinstance(value, str):
        raise ConfigError(path, key, f"expected a path string, got {type(value).__name__}")
    full = path.parent / value
    if glob.has_magic(value):
        found = sorted(Path(p).resolve() for p in glob.glob(str(full)))
        if not found:
            raise ConfigError(path, key, f"no file matches {value!r}")
        return found
    return [full.resolve()]
