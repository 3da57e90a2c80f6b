"""Imports follow the pipeline: a module of odpipe imports only its own layer and the layers below.

``LAYERS`` is the one statement of the order, bottom first. ``parsers`` sits beside the
bottom: every layer may import it and it imports no odpipe but ``BENEATH``, the constants under
everything (odpipe.constants), which import nothing of the project. Every ``import`` counts, also
those inside functions and under ``TYPE_CHECKING``; imports by name through ``importlib``
(the CLI finding its commands, ``commands.study`` its scenario) are not seen. Each
package of odpipe must be placed, so a new package cannot slip in without a layer.

The studies (``odpipe.studies``, the seed papers' scenarios) sit above the library: only the
commands may import them, so nothing the library does can depend on a reproduction.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

LAYERS = (
    # numerical kernels with no model knowledge; the odpipe package itself (version, BLAS threads)
    ("foundation", ("odpipe", "odpipe.errors", "odpipe.log", "odpipe.numerics")),
    ("time", ("odpipe.time",)),
    # the TrackingTable's own structure: count intervals from time tags, ramp segments, passes
    ("tracking", ("odpipe.tracking",)),
    # one layer: Earth rotation (frames.earth) needs EOP (environment.eop), the Moon's
    # orientation (frames.moon) the ephemeris's libration angles, solid tides
    # (environment.solid_tides) Earth rotation, and station coordinates (environment.stations)
    # the epoch conversions of frames.epochs
    ("frames and environment", ("odpipe.frames", "odpipe.environment")),
    ("dynamics and measurement models", ("odpipe.dynamics", "odpipe.measurements")),
    ("media calibration", ("odpipe.media",)),
    ("preprocess", ("odpipe.preprocess",)),
    ("estimation", ("odpipe.estimation",)),
    ("orbit determination and analysis", ("odpipe.od", "odpipe.analysis")),
    ("products and run bookkeeping", ("odpipe.products", "odpipe.operations")),
    ("pipeline and simulator", ("odpipe.pipeline", "odpipe.simulate")),
    ("studies", ("odpipe.studies",)),
    ("commands", ("odpipe.commands", "odpipe.cli", "odpipe.api")),
)

# below parsers and every layer: what all of them may import (layer index -2)
BENEATH = ("odpipe.constants",)

# (importing module, imported module): imports that run up the layers on purpose, each with its reason.
ALLOWED: dict[tuple[str, str], str] = {}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def source_files() -> list[Path]:
    return sorted(p for pkg in ("odpipe", "parsers") for p in (ROOT / pkg).rglob("*.py"))


MODULES = {module_name(p) for p in source_files()}


def imports(source: str, module: str, is_package: bool, known=MODULES):
    """(line, imported module) of every import in ``source``; ``from a import b`` names ``a.b`` when
    that is a module in ``known``, relative imports are resolved against ``module``."""
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = module.split(".")[: len(module.split(".")) - (0 if is_package else 1)]
                parts = parts[: len(parts) - (node.level - 1)]
                base = ".".join(parts + ([node.module] if node.module else []))
            targets = {f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names}
            for target in sorted(targets):
                yield node.lineno, target


def layer_of(module: str) -> int | None:
    """Index in LAYERS (-1 for parsers, -2 for BENEATH); None for a module of neither odpipe nor parsers."""
    if module in BENEATH:
        return -2
    top = module.split(".")[0]
    if top == "parsers":
        return -1
    if top != "odpipe":
        return None
    best, index = "", None
    for i, (_, packages) in enumerate(LAYERS):
        for pkg in packages:
            # "odpipe" places the package's own __init__ only, never its subpackages
            inside = module == pkg or (pkg != "odpipe" and module.startswith(pkg + "."))
            if inside and len(pkg) > len(best):
                best, index = pkg, i
    if index is None:
        raise LookupError(f"{module} is in no layer: add its package to LAYERS in tests/test_layers.py")
    return index


def violations(module: str, path: str, source: str, is_package: bool, known=MODULES) -> list[str]:
    """One line per import of ``source`` that runs up the layers (or from parsers into odpipe)."""
    own = layer_of(module)
    out = []
    for line, target in imports(source, module, is_package, known):
        theirs = layer_of(target)
        if theirs is None or (module, target) in ALLOWED:
            continue
        if theirs > own:
            out.append(f"{path}:{line}: {module} ({layer_name(own)}) imports {target} ({layer_name(theirs)})")
    return out


def layer_name(index: int) -> str:
    return {-2: "constants", -1: "parsers"}.get(index) or LAYERS[index][0]


def test_every_import_runs_down_the_layers():
    found = []
    for p in source_files():
        found += violations(module_name(p), str(p.relative_to(ROOT)), p.read_text(), p.name == "__init__.py")
    assert not found, "imports against the pipeline's flow:\n" + "\n".join(found)


def test_the_library_never_imports_the_studies():
    """Only the commands import ``odpipe.studies``: ``odpipe study`` (and its former name) and ``odpipe reference``."""
    found = [f"{p.relative_to(ROOT)}:{line}: imports {target}"
             for p in source_files() if not module_name(p).startswith(("odpipe.studies", "odpipe.commands."))
             for line, target in imports(p.read_text(), module_name(p), p.name == "__init__.py")
             if target == "odpipe.studies" or target.startswith("odpipe.studies.")]
    assert found == []
    users = {module_name(p) for p in source_files() if module_name(p).startswith("odpipe.commands.")
             and any(t.startswith("odpipe.studies") for _, t in imports(p.read_text(), module_name(p), False))}
    assert users == {"odpipe.commands.study", "odpipe.commands.reference"}


def test_every_package_has_a_layer():
    for module in MODULES:
        layer_of(module)


def test_allowed_exceptions_are_still_needed():
    for (module, target), reason in ALLOWED.items():
        path = ROOT / (module.replace(".", "/") + ".py")
        if not path.exists():
            path = ROOT / module.replace(".", "/") / "__init__.py"
        found = {t for _, t in imports(path.read_text(), module, path.name == "__init__.py")}
        assert target in found, f"ALLOWED {module} -> {target} ({reason}) no longer imported: remove it"
        assert layer_of(target) > layer_of(module), f"ALLOWED {module} -> {target} runs down: remove it"


def test_checker_finds_upward_imports():
    """The checker itself, on a made-up module of the time layer: a top-level, a function-level and a
    relative import up the layers are each reported with their line; imports down and sideways are not."""
    known = MODULES | {"odpipe.time.fake"}
    source = ("import numpy\n"
              "from odpipe.numerics import chebyshev\n"
              "from odpipe.dynamics.propagator import propagate, propagate_many\n"
              "def f():\n"
              "    from odpipe.estimation import fit\n"
              "    from ..media import apply\n"
              "    from . import scales\n"
              "from parsers import table\n")
    found = violations("odpipe.time.fake", "odpipe/time/fake.py", source, False, known)
    assert found == [
        "odpipe/time/fake.py:3: odpipe.time.fake (time) imports odpipe.dynamics.propagator "
        "(dynamics and measurement models)",
        "odpipe/time/fake.py:5: odpipe.time.fake (time) imports odpipe.estimation.fit (estimation)",
        "odpipe/time/fake.py:6: odpipe.time.fake (time) imports odpipe.media.apply (media calibration)",
    ]
    found = violations("parsers.fake", "parsers/fake.py", "from odpipe.time import scales\n", False, known)
    assert found == ["parsers/fake.py:1: parsers.fake (parsers) imports odpipe.time.scales (time)"]
    assert violations("parsers.fake", "parsers/fake.py", "from odpipe.constants import C_LIGHT\n", False, known) == []
    found = violations("odpipe.constants", "odpipe/constants.py", "import numpy\nfrom parsers import table\n"
                       "from odpipe import log\n", False, known)
    assert found == ["odpipe/constants.py:2: odpipe.constants (constants) imports parsers.table (parsers)",
                     "odpipe/constants.py:3: odpipe.constants (constants) imports odpipe.log (foundation)"]
    with pytest.raises(LookupError, match="odpipe.nowhere is in no layer"):
        layer_of("odpipe.nowhere")
