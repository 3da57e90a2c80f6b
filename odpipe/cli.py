"""The ``odpipe`` command. Each subcommand is a module in :mod:`odpipe.commands`.

A command module defines ``NAME`` (str), ``HELP`` (one line),
``add_arguments(parser)`` and ``run(args) -> int`` (exit status).
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

import odpipe.commands


def _command_modules():
    for info in sorted(pkgutil.iter_modules(odpipe.commands.__path__), key=lambda i: i.name):
        if not info.name.startswith("_"):
            yield importlib.import_module(f"odpipe.commands.{info.name}")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="odpipe", description="Orbit-determination post-processing of radiometric tracking data.")
    parser.add_argument("--version", action="version", version=f"odpipe {odpipe.__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for mod in _command_modules():
        p = sub.add_parser(mod.NAME, help=mod.HELP, description=mod.HELP)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "_run"):
        parser.print_help()
        return 2
    return int(args._run(args) or 0)


if __name__ == "__main__":
    sys.exit(main())
