"""``odpipe reference``: the configuration reference (every key, type, default, meaning) as Markdown.

One document for every kind of configuration file: run configurations, simulated cases, studies.
``docs/config.md`` is its output.
"""

from __future__ import annotations

NAME = "reference"
HELP = "print the configuration reference (run configurations, simulated cases, studies: every key, type, unit, default)"


def add_arguments(parser) -> None:
    parser.add_argument("-o", "--output", help="write to this file instead of standard output")


def document() -> str:
    """The reference of every configuration kind, one Markdown document."""
    from odpipe.pipeline.config import reference as run_reference
    from odpipe.simulate.case import reference as case_reference
    from odpipe.studies import scenarios

    return run_reference() + "\n" + case_reference() + "\n" + scenarios.reference()


def run(args) -> int:
    from parsers.atomic import write_text

    text = document()
    if args.output:
        write_text(args.output, text)
    else:
        print(text, end="")
    return 0
