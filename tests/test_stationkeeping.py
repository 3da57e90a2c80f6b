"""Station-keeping design (odpipe.simulate.stationkeeping): the gap rule and its delta-v bound.

The ARTEMIS twin designed on its true state met the case this guards: on 2010-12-17 the 7-day gap's Newton
converged on a 3.43 m/s root where the 7- and 6-day designs on the OD state fail and the 5-day one takes 0.39 m/s
(0.42 m/s on the truth); flown, it cost the 28-day ablation 8x its overlaps. The crossing itself is the design
force model's: these tests replace the Newton solve to check the rule alone."""

import numpy as np
import pytest

import odpipe.simulate.stationkeeping as sk

DAY = 86400.0


@pytest.fixture
def solutions(monkeypatch):
    """The twin's SK-3 on the truth, gap (d) -> design (m/s): 7 d a far root, 6 d no convergence, 5 d the burn."""
    found = {7: np.array([3.0, -1.5, 0.6]), 6: None, 5: np.array([0.3, -0.25, 0.15])}
    tried = []

    def crossing(fm, state, t, gap, horizon, **kw):
        tried.append(round(gap / DAY))
        assert horizon == gap + 8 * DAY
        return found[round(gap / DAY)]
    monkeypatch.setattr(sk, "_crossing_dv", crossing)
    return tried


def test_the_first_gap_that_converges_is_flown_without_a_bound(solutions):
    dv = sk.design_dv(None, np.zeros(6), 0.0, (7 * DAY, 6 * DAY, 5 * DAY), 8 * DAY)
    assert np.linalg.norm(dv) == pytest.approx(3.4073, abs=1e-4) and solutions == [7]


def test_a_design_above_the_bound_is_not_flown_the_next_gap_is(solutions):
    dv = sk.design_dv(None, np.zeros(6), 0.0, (7 * DAY, 6 * DAY, 5 * DAY), 8 * DAY, max_dv=2.0)
    np.testing.assert_array_equal(dv, [0.3, -0.25, 0.15])
    assert solutions == [7, 6, 5]


def test_no_gap_within_the_bound_names_it(solutions):
    with pytest.raises(ValueError, match=r"within 0\.1 m/s"):
        sk.design_dv(None, np.zeros(6), 0.0, (7 * DAY, 6 * DAY, 5 * DAY), 8 * DAY, max_dv=0.1)
