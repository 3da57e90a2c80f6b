"""The configuration reference, generated from the schema dataclasses so it cannot drift.

Each section is a dataclass (:mod:`odpipe.operations.schema` loads them); a key's description is the
comment on its line in the class source, or the comment lines just above it; a section's description is
its class docstring. ``odpipe reference`` prints the Markdown; ``docs/config.md`` is its output.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import re
import types
import typing
from pathlib import Path

_FIELD = re.compile(r"^\s+(\w+)\s*:")


@functools.cache
def field_comments(cls) -> dict[str, str]:
    """Key -> the source comment describing it (same line, else the lines just above); inherited keys
    described in their base classes."""
    out, above = {}, []
    for base in reversed(cls.__mro__[1:]):
        if dataclasses.is_dataclass(base):
            out.update(field_comments(base))
    for line in inspect.getsource(cls).splitlines()[1:]:
        stripped = line.strip()
        if stripped.startswith("#"):
            above.append(stripped.lstrip("# ").strip())
            continue
        m = _FIELD.match(line)
        if m and not stripped.startswith(("def ", "@")):
            code, _, comment = line.partition("  #")
            text = " ".join(above + ([comment.strip()] if comment.strip() else []))
            out[m.group(1)] = text
        above = []
    return out


def type_name(hint) -> str:
    """A reader's name for a schema type hint."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        names = [type_name(a) for a in args if a is not type(None)]
        return " or ".join(names) + (" (optional)" if type(None) in args else "")
    if origin is list:
        return f"list of {type_name(args[0])}" if args else "list"
    if origin is dict:
        return f"table of {type_name(args[1])}" if args else "table"
    if origin is typing.Literal:
        return " \\| ".join(f'`"{a}"`' if isinstance(a, str) else f"`{a}`" for a in args)
    if dataclasses.is_dataclass(hint):
        return "table (its keys below)"
    return {Path: "path", float: "number", int: "integer", str: "string", bool: "boolean",
            typing.Any: "any"}.get(hint, getattr(hint, "__name__", str(hint)))


def default_text(f: dataclasses.Field) -> str:
    """The field's default as TOML would write it; 'required' when there is none."""
    if f.default is not dataclasses.MISSING:
        value = f.default
    elif f.default_factory is not dataclasses.MISSING:
        value = f.default_factory()
    else:
        return "required"
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, Path):
        return f'"{value}"'
    if isinstance(value, str):
        return f'"{value}"'
    if dataclasses.is_dataclass(value):
        return "(its defaults)"
    return repr(value).replace("'", '"')


def sections(cls, prefix: str = "") -> list[tuple[str, type]]:
    """The dataclass tables reachable from ``cls``, as (TOML key path, class), depth first."""
    out = [(prefix, cls)]
    hints = typing.get_type_hints(cls)
    for f in dataclasses.fields(cls):
        for inner in _dataclasses_in(hints[f.name]):
            key = f"{prefix}.{f.name}" if prefix else f.name
            out += sections(inner, key)
    return out


def _dataclasses_in(hint):
    if dataclasses.is_dataclass(hint):
        return [hint]
    return [t for a in typing.get_args(hint) for t in _dataclasses_in(a)]


def markdown(cls, title: str, skip: tuple[str, ...] = ()) -> str:
    """The reference of configuration class ``cls`` as Markdown: one table per section."""
    lines = [f"# {title}", ""]
    for key, sec in sections(cls):
        hints, comments = typing.get_type_hints(sec), field_comments(sec)
        rows = [f for f in dataclasses.fields(sec) if f.name not in skip and not dataclasses.is_dataclass(
            hints[f.name]) and not (key == "" and _dataclasses_in(hints[f.name]))]
        if not rows:
            continue
        lines += [f"## `[{key}]`" if key else "## top level", ""]
        doc = inspect.getdoc(sec) or ""
        if doc and not doc.startswith(sec.__name__ + "("):  # dataclass's generated signature is no doc
            lines += [doc, ""]
        lines += ["| key | type | default | meaning |", "|---|---|---|---|"]
        for f in rows:
            meaning = comments.get(f.name, "").replace("|", "\\|")
            lines.append(f"| `{f.name}` | {type_name(hints[f.name])} | `{default_text(f)}` | {meaning} |")
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"
