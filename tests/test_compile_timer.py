"""compile_timer counts numba compilations and not calls that reuse a compiled kernel."""

import numpy as np
from numba import njit

from odpipe.dynamics.compile_timer import compile_timer


def test_counts_a_compilation_once():
    @njit  # defined here: never in any cache, so the first call compiles
    def twice(x):
        return 2.0 * x

    with compile_timer() as first:
        assert twice(np.float64(1.5)) == 3.0
    assert first.functions >= 1 and first.seconds > 0.0
    with compile_timer() as again:
        twice(np.float64(2.0))
    assert again.functions == 0 and again.seconds == 0.0
