"""ReferenceChain.state: each epoch from the segment whose span holds it (before the first start: the
first segment's look-back), epochs in any order; against the straightforward per-epoch choice."""

import numpy as np

from odpipe.od.arc import ReferenceChain


class Line:
    """A segment 'trajectory' whose state is (t, k, 0, 0, 0, 0): it names the segment that gave it."""

    center = "moon"
    n_eval = 1

    def __init__(self, k):
        self.k = k

    def state(self, t):
        t = np.atleast_1d(t)
        return np.column_stack([t, np.full(t.size, self.k), np.zeros((t.size, 4))])


def test_each_epoch_from_its_segment_in_any_order():
    starts = [0.0, 100.0, 250.0, 400.0]
    chain = ReferenceChain(starts, [Line(k) for k in range(4)], -120.0, 600.0)
    t = np.random.default_rng(3).permutation(np.r_[np.linspace(-120.0, 600.0, 97), starts])
    out = chain.state(t)
    expected = np.array([max([k for k, s in enumerate(starts) if s <= x] or [0]) for x in t])
    np.testing.assert_array_equal(out[:, 0], t)
    np.testing.assert_array_equal(out[:, 1], expected)
    assert chain.state(150.0).shape == (1, 6) and chain.state(np.array([]).reshape(0)).shape == (0, 6)
