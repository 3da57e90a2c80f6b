"""The ``odpipe`` command. Each subcommand is a module in :mod:`odpipe.commands`.

A command module defines ``NAME`` (str), ``HELP`` (one line), both string literals,
``add_arguments(parser)`` and ``run(args) -> int`` (exit status, :class:`odpipe.errors.Exit`).
The list of commands is read from the modules' source; only the command being run is imported,
so ``odpipe --help`` does not wait for the whole pipeline to load.
Its product (a summary table, the path of a report) goes to stdout; progress and
diagnostics go through :mod:`logging` to stderr (:mod:`odpipe.log`). An expected error
raised by a command becomes one line on stderr and its exit status (:mod:`odpipe.errors`).
"""

from __future__ import annotations

import argparse
import ast
import importlib
import logging
import pkgutil
import sys
from pathlib import Path

import odpipe.commands
from odpipe import log
from odpipe.errors import MEANING, Exit, describe
from odpipe.operations.quick_exit import skip_final_collection

_log = logging.getLogger("odpipe")


def commands() -> dict[str, tuple[str, str]]:
    """Command name -> (module, one-line help), read from each command module's NAME and HELP literals."""
    out = {}
    for info in sorted(pkgutil.iter_modules(odpipe.commands.__path__), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        tree = ast.parse((Path(odpipe.commands.__path__[0]) / f"{info.name}.py").read_text())
        consts = {t.id: ast.literal_eval(node.value) for node in tree.body if isinstance(node, ast.Assign)
                  for t in node.targets if isinstance(t, ast.Name) and t.id in ("NAME", "HELP")}
        out[consts["NAME"]] = (f"odpipe.commands.{info.name}", consts["HELP"])
    return out


def _global_options(parser: argparse.ArgumentParser, top: bool) -> None:
    """-v/-q/--debug, accepted before the command and after it (there without overriding the first)."""
    unset = {} if top else {"default": argparse.SUPPRESS}
    parser.add_argument("-v", "--verbose", action="count", help="more detail on stderr (debug messages)",
                        **({"default": 0} if top else unset))
    parser.add_argument("-q", "--quiet", action="count", help="only warnings and errors on stderr",
                        **({"default": 0} if top else unset))
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error", **unset)


def exit_status_table() -> str:
    """The exit statuses, for the help text."""
    return "exit status:\n" + "\n".join(f"  {int(code):<4}{text}" for code, text in MEANING.items())


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of every command; only ``command``'s module is imported and its arguments added (all
    commands' when None)."""
    parser = argparse.ArgumentParser(prog="odpipe",
                                     description="Orbit-determination post-processing of radiometric tracking data.",
                                     epilog=exit_status_table(),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"odpipe {odpipe.__version__}")
    _global_options(parser, top=True)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module, text) in commands().items():
        p = sub.add_parser(name, help=text.replace("%", "%%"), description=text)  # help is %-formatted
        if command in (None, name):
            mod = importlib.import_module(module)
            mod.add_arguments(p)
            p.set_defaults(_run=mod.run)
        _global_options(p, top=False)
    return parser


def _command_in(argv: list[str]) -> str | None:
    """The command named in ``argv``: its first word that is not an option (global options take no value)."""
    return next((a for a in argv if not a.startswith("-")), None)


def main(argv: list[str] | None = None) -> int:
    """Run ``odpipe`` with ``argv`` (default: the process's); returns the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    skip_final_collection()
    parser = build_parser(_command_in(argv) or "")
    args = parser.parse_args(argv)
    log.configure(1 if args.debug else args.verbose - args.quiet)
    if not hasattr(args, "_run"):  # bare `odpipe`: what it can do
        parser.print_help()
        return Exit.OK
    try:
        return int(args._run(args) or 0)
    except KeyboardInterrupt:
        _log.error("interrupted")
        return Exit.INTERRUPTED
    except Exception as exc:
        code, line = describe(exc)
        _log.error(line, exc_info=exc if args.debug else None)
        return code


if __name__ == "__main__":
    sys.exit(main())
