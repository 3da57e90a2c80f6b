"""Elementary rotations equal SOFA/ERFA's iauRx, iauRy, iauRz."""

from __future__ import annotations

import erfa
import numpy as np

from odpipe.frames.rotations import frame_rotation


def test_elementary_rotations_match_erfa():
    angles = np.linspace(-4.0, 4.0, 9)
    for axis, ref in ((1, erfa.rx), (2, erfa.ry), (3, erfa.rz)):
        ours = frame_rotation(axis, angles)
        expected = np.array([ref(a, np.eye(3)) for a in angles])
        np.testing.assert_allclose(ours, expected, rtol=0, atol=1e-16)
