"""odpipe liaison: the former name of ``odpipe study``, kept so existing scripts keep working."""

from __future__ import annotations

from odpipe.commands.study import add_arguments, run  # noqa: F401 (the command's interface)

NAME = "liaison"
HELP = "the same as `odpipe study` (its former name)"
