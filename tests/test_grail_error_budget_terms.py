"""benchmarks/grail_error_budget.py swaps the run's media model for each media term: the swapped models must
take the arguments ``odpipe run`` gives its own (its ionosphere term failed with a TypeError once the run
passed calibration.standard_troposphere)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import grail_error_budget as budget  # noqa: E402
from odpipe.analysis.klobuchar import KlobucharIonosphere  # noqa: E402
from odpipe.media.model import MediaModel  # noqa: E402


def test_each_media_term_builds_as_the_run_builds_its_model():
    for name, (_, model) in budget.TERMS.items():
        if model is None:
            continue
        built = model(None, None, "modified-saastamoinen")   # as odpipe/pipeline/run.py: calibrations, IONEX, troposphere
        assert isinstance(built, MediaModel) and built.standard_troposphere == "modified-saastamoinen", name
    assert isinstance(budget.TERMS["ionosphere"][1](None, None, "saastamoinen-niell").ionex, KlobucharIonosphere)
