"""Whole study runs for the paper regression tests, once per test session.

A whole run takes minutes to tens of minutes (``runs/study_*.toml`` as shipped), so the tests
that need one are opt-in: ``ODPIPE_STUDY_RUNS=1 pytest tests/test_study_*.py -k whole``. The
default suite checks the same tables on the parts that are cheap (CRLB, Gramians, two schedules).
"""

from __future__ import annotations

import functools
import importlib
import os
import tempfile
from pathlib import Path

import pandas as pd
import pytest

from odpipe.studies.scenarios import load_config

RUNS = Path(__file__).resolve().parents[1] / "runs"
STORED = Path(__file__).resolve().parents[1] / "fixtures" / "studies"

whole_run = pytest.mark.skipif(os.environ.get("ODPIPE_STUDY_RUNS", "") in ("", "0"),
                               reason="a whole study run (minutes): set ODPIPE_STUDY_RUNS=1")


@functools.cache
def run_study(config: str) -> dict:
    """The result of ``run`` of the study ``runs/<config>.toml`` as shipped (its report in a temporary folder)."""
    cfg = load_config(RUNS / f"{config}.toml")
    out = Path(tempfile.mkdtemp(prefix=f"{config}_"))
    return importlib.import_module(f"odpipe.studies.{cfg['scenario']}").run(cfg, out, log=lambda m: None)


def as_recorded(text: str):
    """A figure as docs/validation.md records it (e.g. "7.85"): equal to within half a unit of its last digit."""
    decimals = len(text.split(".")[1]) if "." in text else 0
    return pytest.approx(float(text), abs=0.5 * 10.0 ** -decimals)


def stored_figures(name: str) -> pd.DataFrame:
    """odpipe's figures of a whole study run as recorded in fixtures/studies/<name>.csv (the figure columns as
    text, to the digits recorded: compare with :func:`as_recorded`)."""
    return pd.read_csv(STORED / f"{name}.csv", comment="#", dtype=str, keep_default_na=False)
