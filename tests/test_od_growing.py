"""The growing-arc start of long arcs: which shorter arcs are fitted first."""

from types import SimpleNamespace

import pytest

from odpipe.od.arc import growing_ends

DAY = 86400.0


@pytest.mark.parametrize("days, growing, expected", [
    (14.0, 2.0, [2.0, 4.0, 8.0]),     # the demo's long arcs: 2, 4, 8 days, then all 14
    (5.0, 2.0, [2.0]),                 # a short arc: one 2-day start
    (2.5, 2.0, []),                    # no shorter arc when it would be nearly the whole arc
    (14.0, None, []),                  # switched off
])
def test_growing_arc_ends(days, growing, expected):
    setup = SimpleNamespace(start=1000.0, end=1000.0 + days * DAY, growing_days=growing, maneuvers=())
    assert [(e - 1000.0) / DAY for e in growing_ends(setup)] == expected


def test_growing_arcs_restart_at_burns():
    """A burn 6.96 days in (the twin's long2 spans SK-3 there): 2 and 4 days, then 2 and 4 days past the burn,
    not an 8-day window ending a day after it and extrapolated 6 days."""
    burn = SimpleNamespace(epoch=1000.0 + 6.96 * DAY)
    setup = SimpleNamespace(start=1000.0, end=1000.0 + 13.92 * DAY, growing_days=2.0, maneuvers=(burn,))
    assert [(e - 1000.0) / DAY for e in growing_ends(setup)] == pytest.approx([2.0, 4.0, 8.96, 10.96])
