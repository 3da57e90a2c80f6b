"""The per-arc Chebyshev table of Earth orientation reproduces the full IAU 2006/2000A + EOP matrix."""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.frames.earth import gcrs_to_itrs
from odpipe.frames.tabulated import TabulatedRotation
from odpipe.time import utc_to_tdb


def test_table_matches_the_full_model_over_three_days():
    t0 = float(utc_to_tdb(np.datetime64("2003-06-01T00:00:00"))[()])
    tab = TabulatedRotation(gcrs_to_itrs, t0, t0 + 3 * 86400.0)
    t = t0 + np.random.default_rng(2).uniform(0.0, 3 * 86400.0, 5000)
    err = np.abs(tab(t) - gcrs_to_itrs(t)).max()
    assert err < 1e-12                                  # 6 micrometres at the Earth's surface
    with pytest.raises(ValueError, match="outside"):
        tab(np.array([tab.t0 - 1.0]))
    assert tab.t0 <= t0 and tab.t0 % 3600.0 == 0.0  # segments on whole hours of TDB


def test_rows_sparse_over_their_span_take_the_rotation_directly():
    """`compute`'s span set-up tabulates the Earth orientation only where its rows would ask for it at more
    epochs than the table has nodes (13 per hour): 6 rows a month apart compute it directly (a month's table
    costs 9,000 full evaluations), 1,000 rows over a day use the table."""
    from odpipe.frames.tabulated import node_count
    from odpipe.measurements.compute import MeasurementSetup, spanning

    setup = MeasurementSetup.default()
    t0 = float(utc_to_tdb(np.datetime64("2003-06-01T00:00:00"))[()])
    month, day = t0 + 30 * 86400.0, t0 + 86400.0
    hour = np.floor(t0 / 3600.0) * 3600.0        # pieces on whole hours of TDB: 30 days from t0 (64 s past) touch 721
    assert node_count(hour, hour + 30 * 86400.0) == 720 * 13 and node_count(hour + 1.0, hour + 3599.0) == 13
    assert node_count(t0, month) == 721 * 13
    assert spanning(setup, t0, month, n_rows=6).gcrs_to_itrs is setup.gcrs_to_itrs
    assert isinstance(spanning(setup, t0, day, n_rows=1000).gcrs_to_itrs, TabulatedRotation)
    assert isinstance(spanning(setup, t0, month).gcrs_to_itrs, TabulatedRotation)   # an arc's span: always
