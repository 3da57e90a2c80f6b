"""EME2000 (mean equator and equinox of J2000.0, the dynamical J2000 frame) to GCRS/ICRF axes.

The two differ by the constant frame bias of IAU 2006 (IERS Conventions 2010 eq. 5.21; ERFA ``bp06``'s
``rb``, which turns GCRS vectors into the J2000 mean frame): a rotation of about 23 mas (the pole offset
by 16.6 and 6.8 mas, the equinox by 14.6 mas), 0.11 m on a vector 1,000 km long."""

from __future__ import annotations

import erfa
import numpy as np


def eme2000_to_gcrs(state) -> np.ndarray:
    """A state (m, m/s; shape (..., 6)) or position (..., 3) in EME2000 axes turned to GCRS axes."""
    rb = erfa.bp06(2451545.0, 0.0)[0]  # GCRS -> EME2000, constant
    x = np.asarray(state, float)
    return np.concatenate([x[..., i:i + 3] @ rb for i in range(0, x.shape[-1], 3)], axis=-1)
