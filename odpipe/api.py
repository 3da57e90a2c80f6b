"""The Python entry point for notebooks: fit an arc as ``odpipe run`` does, and read its products.

    >>> from odpipe.api import fit_arc
    >>> arc = fit_arc("runs/grail_b_2012_04_09_start.toml")   # skipped when unchanged
    >>> arc.statistics                      # post-fit RMS per station and observable
    >>> arc.residuals.plot(x="epoch", y="postfit_los", kind="scatter")
    >>> arc.parameters                      # a priori, estimate and sigma of every parameter

:class:`ArcProducts` opens a run folder written before (``OUTPUT/NAME/current``) the same way.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import pandas as pd


@dataclass(frozen=True)
class ArcProducts:
    """The products of one fitted arc in ``folder`` (a run's ``current`` or one of its attempts)."""

    folder: Path

    @cached_property
    def summary(self) -> dict:
        """The run's summary.json: convergence, RMS, edits, parameter count."""
        return json.loads((self.folder / "summary.json").read_text())

    @cached_property
    def residuals(self) -> pd.DataFrame:
        """Every fitted row with its pre- and post-fit residuals and flags (residuals.parquet)."""
        return pd.read_parquet(self.folder / "residuals.parquet")

    @cached_property
    def statistics(self) -> pd.DataFrame:
        """Post-fit residual statistics per station and observable (residual_statistics.csv)."""
        return pd.read_csv(self.folder / "residual_statistics.csv")

    @cached_property
    def parameters(self) -> pd.DataFrame:
        """Estimated parameters with a priori, estimate and formal sigma (parameters.csv)."""
        return pd.read_csv(self.folder / "parameters.csv")

    @cached_property
    def trajectory(self):
        """The smoothed trajectory (trajectory.oem) as an object with ``state(t_tdb)`` -> (n, 6) m, m/s."""
        from odpipe.analysis.overlap import oem_trajectory

        return oem_trajectory(self.folder / "trajectory.oem")

    @property
    def report(self) -> Path:
        """The run's HTML report."""
        return self.folder / "report.html"


def fit_arc(config, *, force: bool = False) -> ArcProducts:
    """Run the arc of run configuration ``config`` (``odpipe run``) and open its products."""
    from odpipe.pipeline.run import run_config

    out = run_config(Path(config), force=force, progress=None)
    return ArcProducts(Path(out["run"]))
