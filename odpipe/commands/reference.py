"""``odpipe reference``: the configuration reference (every key, type, default, meaning) as Markdown: run
configurations, then study configurations."""

from __future__ import annotations

NAME = "reference"
HELP = "print the configuration reference (run and study configs: every key, type, unit, default) as Markdown"


def add_arguments(parser) -> None:
    parser.add_argument("-o", "--output", help="write to this file instead of standard output")


def document() -> str:
    """The whole reference: run configurations, then study configurations (docs/config.md)."""
    from odpipe.pipeline.config import reference
    from odpipe.studies import scenarios

    return reference() + "\n" + scenarios.reference()


def run(args) -> int:
    from odpipe.products.atomic import write_text

    text = document()
    if args.output:
        write_text(args.output, text)
    else:
        print(text, end="")
    return 0
