"""``odpipe reference``: the run configuration reference (every key, type, default, meaning) as Markdown."""

from __future__ import annotations

NAME = "reference"
HELP = "print the run configuration reference (every key, type, unit, default) as Markdown"


def add_arguments(parser) -> None:
    parser.add_argument("-o", "--output", help="write to this file instead of standard output")


def run(args) -> int:
    from odpipe.pipeline.config import reference
    from parsers.atomic import write_text

    text = reference()
    if args.output:
        write_text(args.output, text)
    else:
        print(text, end="")
    return 0
