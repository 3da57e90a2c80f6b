"""The ``odpipe`` command. Each subcommand is a module in :mod:`odpipe.commands`.

A command module defines ``NAME`` (str), ``HELP`` (one line),
``add_arguments(parser)`` and ``run(args) -> int`` (exit status, :class:`odpipe.errors.Exit`).
Its product (a summary table, the path of a report) goes to stdout; progress and
diagnostics go through :mod:`logging` to stderr (:mod:`odpipe.log`). An expected error
raised by a command becomes one line on stderr and its exit status (:mod:`odpipe.errors`).
"""

from __future__ import annotations

import argparse
import importlib
import logging
import pkgutil
import sys

import odpipe.commands
from odpipe import log
from odpipe.errors import MEANING, Exit, describe

_log = logging.getLogger("odpipe")


def _command_modules():
    for info in sorted(pkgutil.iter_modules(odpipe.commands.__path__), key=lambda i: i.name):
        if not info.name.startswith("_"):
            yield importlib.import_module(f"odpipe.commands.{info.name}")


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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="odpipe",
                                     description="Orbit-determination post-processing of radiometric tracking data.",
                                     epilog=exit_status_table(),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"odpipe {odpipe.__version__}")
    _global_options(parser, top=True)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for mod in _command_modules():
        p = sub.add_parser(mod.NAME, help=mod.HELP.replace("%", "%%"), description=mod.HELP)  # help is %-formatted
        mod.add_arguments(p)
        _global_options(p, top=False)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``odpipe`` with ``argv`` (default: the process's); returns the exit status."""
    parser = build_parser()
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
