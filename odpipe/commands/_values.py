"""The type of the commands' numeric options: the text converted, then checked by the run
configuration's own checks (:mod:`odpipe.operations.schema`), so that a bad value (a count time of 0,
a negative gap, NaN) is a usage error (exit 2) naming the option, as a bad key of a run configuration is."""

from __future__ import annotations

import argparse

from odpipe.operations.schema import Check, positive


def number(convert=float, check: Check = positive):
    """An argparse ``type``: ``convert`` (float or int) the option's text, then ``check`` the value."""
    def parse(text: str):
        try:
            value = convert(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {'an integer' if convert is int else 'a number'}") \
                from None
        for _, reason in check(value):
            raise argparse.ArgumentTypeError(reason)
        return value
    return parse
