"""Strict loading of TOML configuration into dataclasses, every problem reported at once.

A configuration section is a dataclass; its fields' type hints say what the
TOML may hold. Unknown keys, wrong types and missing required keys are errors
that name the key path and the file. Fields typed ``Path`` (or lists of
them) resolve relative to the configuration file's folder; strings with glob
characters in a ``list[Path]`` field are expanded there too.

Values are checked too: a field made with :func:`checked` runs its check on
the converted value, and a section with a ``problems()`` method reports what
is wrong across its fields (e.g. an end before the start). Loading goes on
past a problem, so one :class:`ConfigError` lists all of them, each with its
key and, when the TOML text is given, its line.
"""

from __future__ import annotations

import dataclasses
import glob
import math
import os
import re
import tomllib
import types
import typing
from pathlib import Path
from typing import Any, Callable, Iterable


@dataclasses.dataclass(frozen=True)
class Problem:
    """One thing wrong in a configuration: key path (e.g. ``arc.start``), reason, 1-based line if known."""

    key: str
    reason: str
    line: int | None = None

    def __str__(self) -> str:
        where = f"line {self.line} " if self.line else ""
        return f"{where}[{self.key}] {self.reason}" if self.key else f"{where}{self.reason}"


class ConfigError(ValueError):
    """A configuration file is wrong: names the file and, for each problem, the key (and line).

    ``key`` and ``reason`` are the first problem's; ``problems`` holds them all.
    """

    def __init__(self, path, key: str = "", reason: str = "", *, line: int | None = None,
                 problems: Iterable[Problem] | None = None):
        self.path = str(path)
        self.problems = list(problems) if problems else [Problem(key, reason, line)]
        self.key, self.reason = self.problems[0].key, self.problems[0].reason
        if len(self.problems) == 1:
            p = self.problems[0]
            head = f"{path}:{p.line}" if p.line else f"{path}"
            text = f"{head}: [{p.key}] {p.reason}" if p.key else f"{head}: {p.reason}"
        else:
            text = f"{path}: {len(self.problems)} problems: " + "; ".join(map(str, self.problems))
        super().__init__(text)

    def located(self, text: str) -> "ConfigError":
        """The same error with each problem's line found in the TOML ``text``."""
        found = [p if p.line else Problem(p.key, p.reason, key_line(text, p.key)) for p in self.problems]
        return ConfigError(self.path, problems=sorted(found, key=lambda p: p.line or math.inf))


Check = Callable[[Any], Iterable[tuple[str, str]]]


def checked(check: Check, **kwargs) -> dataclasses.Field:
    """A dataclass field whose converted value is checked by ``check(value) -> [(key suffix, reason)]``
    (suffix "" for the field itself, e.g. "[2]" or ".range" for an entry)."""
    return dataclasses.field(metadata={"check": check}, **kwargs)


def internal(default) -> dataclasses.Field:
    """A dataclass field the program sets, never the TOML (an unknown key there)."""
    return dataclasses.field(default=default, metadata={"internal": True})


def read_toml(path) -> tuple[dict, str]:
    """The TOML table and text of the file ``path``; ConfigError when it is not UTF-8 TOML
    (OSError when it cannot be read)."""
    path = Path(path)
    raw = path.read_bytes()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(path, "", f"not UTF-8 text (byte offset {exc.start})") from None
    try:
        return tomllib.loads(text), text
    except tomllib.TOMLDecodeError as exc:
        line = re.search(r"line (\d+)", str(exc))
        raise ConfigError(path, "", f"not valid TOML: {exc}", line=int(line.group(1)) if line else None) from None


def load_file(cls, path):
    """Build dataclass ``cls`` from the TOML file ``path`` (resolved): one ConfigError naming the file and
    every wrong key with its line."""
    path = Path(path).resolve()
    data, text = read_toml(path)
    return load(cls, data, path, text=text)


def load(cls, data: dict, path: Path, key: str = "", text: str | None = None):
    """Build dataclass ``cls`` from the TOML table ``data`` read from ``path`` (its ``text`` locates
    problems by line). Raises one ConfigError listing every problem."""
    try:
        return _load(cls, data, path, key)
    except ConfigError as err:
        raise (err.located(text) if text is not None else err) from None


def _load(cls, data: dict, path: Path, key: str):
    if not isinstance(data, dict):
        raise ConfigError(path, key, f"expected a table, got {type(data).__name__}")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if not f.metadata.get("internal")}
    problems = [Problem(_join(key, name), f"unknown key (allowed: {', '.join(sorted(fields))})")
                for name in sorted(set(data) - set(fields))]
    values = {}
    for name, f in fields.items():
        sub = _join(key, name)
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                problems.append(Problem(sub, "required key is missing"))
            continue
        try:
            values[name] = _convert(hints[name], data[name], path, sub)
        except ConfigError as err:
            problems += err.problems
            continue
        if "check" in f.metadata and values[name] is not None:
            problems += [Problem(sub + suffix, reason) for suffix, reason in f.metadata["check"](values[name])]
    if problems:
        raise ConfigError(path, problems=problems)
    obj = cls(**values)
    if hasattr(obj, "problems"):
        problems = [Problem(_join(key, sub), reason) for sub, reason in obj.problems()]
        if problems:
            raise ConfigError(path, problems=problems)
    return obj


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
                if len(options) == 1 or len(err.problems) > 1 or err.key != key:  # the table itself is wrong
                    raise
                errors.append(err.reason)
        raise ConfigError(path, key, " or ".join(errors))
    if dataclasses.is_dataclass(hint):
        return _load(hint, value, path, key)
    if origin is list:
        if not isinstance(value, list):
            raise ConfigError(path, key, f"expected a list, got {type(value).__name__}")
        if args and args[0] is Path:
            return [p for i, v in enumerate(value) for p in _expand(v, path, f"{key}[{i}]")]
        return _collect([(f"{key}[{i}]", args[0], v) for i, v in enumerate(value)], path, list) if args else value
    if origin is dict:
        if not isinstance(value, dict):
            raise ConfigError(path, key, f"expected a table, got {type(value).__name__}")
        if not args:
            return value
        return dict(zip(value, _collect([(f"{key}.{k}", args[1], v) for k, v in value.items()], path, list)))
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


def _collect(items, path: Path, kind):
    """Convert each (key, hint, value); one ConfigError with every entry's problems."""
    out, problems = [], []
    for key, hint, value in items:
        try:
            out.append(_convert(hint, value, path, key))
        except ConfigError as err:
            problems += err.problems
    if problems:
        raise ConfigError(path, problems=problems)
    return kind(out)


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


def key_line(text: str, key: str) -> int | None:
    """1-based line of ``key`` (e.g. ``dynamics.gravity[1].file``) in the TOML ``text``: the line that
    sets it, else the one setting its nearest parent (an inline table, a table header); None if absent.
    An index counts the ``[[array]]`` headers of that array; on a plain array it is ignored."""
    want = [(m.group(1), int(m.group(2)) if m.group(2) else None)
            for m in (re.fullmatch(r"(.*?)(?:\[(\d+)\])?", part) for part in _parts(key))]
    seen: dict[tuple, int] = {}
    table: list[tuple] = []
    best, best_len = None, 0
    for no, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        header = re.match(r"^(\[\[?)\s*([^\]]+?)\s*\]", line)
        if header:
            names = _parts(header.group(2))
            index = None
            if header.group(1) == "[[":
                index = seen[tuple(names)] = seen.get(tuple(names), -1) + 1
            table = [(n, None) for n in names[:-1]] + [(names[-1], index)]
            here = table
        else:
            m = re.match(r"^([A-Za-z0-9_\-\"'. ]+?)\s*=", line)
            if not m:
                continue
            here = table + [(n, None) for n in _parts(m.group(1))]
        n = len(here)
        if n > best_len and n <= len(want) and all(
                a == w and (i is None or j is None or i == j) for (a, i), (w, j) in zip(here, want)):
            best, best_len = no, n
            if n == len(want):
                break
    return best


def _parts(dotted: str) -> list[str]:
    return [p.strip().strip("\"'") for p in dotted.split(".")]


# --- checks shared by configurations ------------------------------------------------------------------------


def positive(value, *, allow_inf: bool = False) -> list[tuple[str, str]]:
    """A number > 0 (finite unless ``allow_inf``); each entry of a list or table."""
    def bad(v):
        return not (v > 0 and (allow_inf or math.isfinite(v)))  # NaN fails every comparison
    return _each(value, bad, "must be positive" + ("" if allow_inf else " and finite"))


def at_least(low):
    """Check: a number (or each entry) >= ``low``."""
    return lambda value: _each(value, lambda v: not v >= low, f"must be at least {low}")


def between(low, high):
    """Check: a number (or each entry) in [``low``, ``high``]."""
    return lambda value: _each(value, lambda v: not low <= v <= high, f"must be between {low} and {high}")


def finite(value) -> list[tuple[str, str]]:
    """Every number finite (not NaN or inf)."""
    return _each(value, lambda v: not math.isfinite(v), "must be finite")


def _each(value, bad, reason) -> list[tuple[str, str]]:
    if isinstance(value, dict):
        return [(f".{k}", f"{v!r} {reason}") for k, v in value.items() if bad(v)]
    if isinstance(value, (list, tuple)):
        return [(f"[{i}]", f"{v!r} {reason}") for i, v in enumerate(value) if bad(v)]
    return [("", f"{value!r} {reason}")] if bad(value) else []


def file_name(value: str) -> list[tuple[str, str]]:
    """A single file or folder name: no separators, not '.' or '..', so it cannot leave its folder."""
    if not value or value in (".", "..") or "/" in value or "\\" in value or "\0" in value:
        return [("", f"{value!r} is not a plain name (no '/', '\\', '.' or '..'): "
                     "it must stay inside the output folder")]
    return []


def readable(path: Path) -> str | None:
    """Why the file ``path`` cannot be read, or None."""
    if not path.exists():
        return f"{path} does not exist"
    if not path.is_file():
        return f"{path} is not a file"
    if not os.access(path, os.R_OK):
        return f"{path} is not readable (permission denied)"
    return None


def readable_files(value) -> list[tuple[str, str]]:
    """Check: a path (or each of a list) names a readable file (the reason names the file)."""
    return [("", why) for p in (value if isinstance(value, list) else [value]) if (why := readable(p))]
