"""Square-root information smoother (Bierman's SRIS, Dyer-McReynolds form).

Runs backwards over an :class:`~odpipe.estimation.srif.SRIF` log, starting from
the final filtered information array. A deterministic map ``dx+ = Phi dx`` is
undone as ``R* <- R* Phi`` (a compiled run of them for :meth:`~.srif.SRIF.intervals`);
a colored-noise step combines the smoothed array of ``dx+`` with the rows the filter
eliminated (which tie ``p_old`` to ``dx+``) and marginalizes ``p_new``. Measurement updates need no backward work: between
process-noise steps the smoothed estimate is the mapped final one.
"""

from __future__ import annotations

import numpy as np

from .srif import SRIF, solve_information, triangularize
from .srif_kernels import backward_maps


def smooth(srif: SRIF) -> dict:
    """Smoothed :class:`~.srif.Gaussian` at every ``mark`` label in the filter's log."""
    return {k: solve_information(R, z, srif.n_est, srif.c_bar, srif.c_sigma)
            for k, (R, z) in smooth_arrays(srif).items()}


def smooth_arrays(srif: SRIF) -> dict:
    """Smoothed information arrays ``(R, z)`` (rows in any order) at every ``mark`` label."""
    R, z = srif.R.copy(), srif.z.copy()
    n = srif.n
    out = {}
    for event in reversed(srif.log):
        kind = event[0]
        if kind == "mark":
            out[event[1]] = (R, z)
        elif kind == "map":
            R = R @ event[1]
        elif kind == "intervals":   # marks first.. each followed by its map, undone at once
            _, first, Phi = event
            Rs = backward_maps(np.ascontiguousarray(R), Phi)
            out.update({first + k: (Rs[k], z) for k in range(Phi.shape[0])})
            R = Rs[0]
        else:
            _, idx, Rpp, Rpx, zp = event
            k = idx.size
            rest = np.ones(n, bool)
            rest[idx] = False
            # variables: [p_new (k) | dx_old (n) with p_old in slots idx]
            A = np.zeros((n + k, k + n + 1))
            A[:n, :k] = R[:, idx]
            A[:n, k:k + n][:, rest] = R[:, rest]
            A[:n, -1] = z
            A[n:, :k] = Rpx[:, idx]
            A[n:, k + idx] = Rpp
            A[n:, k:k + n][:, rest] = Rpx[:, rest]
            A[n:, -1] = zp
            T = triangularize(A)
            R, z = T[k:, k:k + n], T[k:, -1]
    return out

