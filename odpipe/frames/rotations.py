"""Elementary frame rotations R1, R2, R3 (vectorized), the IERS/SOFA sign convention."""

from __future__ import annotations

import numpy as np


def frame_rotation(axis: int, angle) -> np.ndarray:
    """Matrices (…,3,3) rotating the frame by ``angle`` rad about ``axis`` 1, 2 or 3.

    R3(a) = [[cos a, sin a, 0], [-sin a, cos a, 0], [0, 0, 1]] (as SOFA ``iauRz``).
    """
    a = np.asarray(angle, dtype=float)
    c, s = np.cos(a), np.sin(a)
    m = np.zeros(a.shape + (3, 3))
    i, j = {1: (1, 2), 2: (2, 0), 3: (0, 1)}[axis]
    m[..., axis - 1, axis - 1] = 1.0
    m[..., i, i] = c
    m[..., j, j] = c
    m[..., i, j] = s
    m[..., j, i] = -s
    return m
