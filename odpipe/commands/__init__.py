"""Subcommands of the ``odpipe`` command, one module each (discovered by :mod:`odpipe.cli`)."""
