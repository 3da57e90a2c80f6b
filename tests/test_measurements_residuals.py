"""Residual helper: modulus wrapping and line-of-sight scaling (checked against hand values)."""

from __future__ import annotations

import numpy as np

from odpipe.measurements.compute import Evaluation
from odpipe.measurements.residuals import residuals
from parsers.table import build


def test_range_residual_wraps_at_the_modulus_and_scales_to_metres():
    m = 2.0**20
    rows = build(3, observable=["range", "range", "doppler_2way"], value=[10.0, m - 5.0, 1.0],
                 range_modulus=[m, m, np.nan])
    ev = Evaluation(np.array([m - 2.0, 7.0, 0.5]), np.array([0.14, 0.14, 0.02]), np.array(["", "", ""]), {}, {})
    res, los = residuals(rows, ev)
    np.testing.assert_allclose(res, [12.0, -12.0, 0.5])
    np.testing.assert_allclose(los, [12.0 * 0.14, -12.0 * 0.14, 0.5 * 0.02])
