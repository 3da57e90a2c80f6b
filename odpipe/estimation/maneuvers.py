"""Maneuver products: designed-minus-estimated table and detection of unlogged maneuvers.

Logged impulsive maneuvers are registry parameters (kind ``maneuver``, a priori
= designed dV, 10 mm/s per axis as Table 4.1 of the ARTEMIS set-up). An unlogged
maneuver shows as a run of large normalized innovations: the filter's predicted
residuals ``nu / s`` (``s`` = predicted sigma) are N(0, 1) while the model holds,
so the sum of ``(nu/s)^2`` over a sliding window of ``w`` rows is chi-square(w).
A window beyond the ``p_false`` quantile raises a finding; its epoch is the split
of that window maximizing the generalized likelihood ratio of a suffix whose
variance is scaled by ``mu`` (estimated): ``n/2 (mu - 1 - ln mu)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.special import chdtri  # chi-square inverse survival function (scipy.stats costs ~1 s to import)

from .registry import ParameterRegistry


def maneuver_table(registry: ParameterRegistry, x: np.ndarray, P: np.ndarray) -> pd.DataFrame:
    """Per maneuver: designed and estimated dV (m/s), sigma, the Mahalanobis distance of
    estimated-minus-designed, and the epoch offset (s) with sigma when estimated
    (NaN otherwise). ``x``, ``P``: estimate and covariance in registry order."""
    rows = []
    owners = dict.fromkeys(p.owner for p in registry.parameters if p.kind == "maneuver")
    for owner in owners:
        idx = registry.indices("maneuver", owner)
        par = registry.parameters[idx[0]]
        designed = registry.apriori[idx]
        d = x[idx] - designed
        Pm = P[np.ix_(idx, idx)]
        it = registry.indices("maneuver_epoch", owner)
        dt, sdt = (float(x[it[0]]), float(np.sqrt(P[it[0], it[0]]))) if it.size else (np.nan, np.nan)
        rows.append({"maneuver": owner, "epoch": par.epoch,
                     "epoch_offset": dt, "epoch_offset_sigma": sdt,
                     "designed": designed, "estimated": x[idx], "sigma": np.sqrt(np.diag(Pm)),
                     "estimated_minus_designed": d,
                     "dv_change_norm": float(np.linalg.norm(d)),
                     "mahalanobis": float(np.sqrt(d @ np.linalg.solve(Pm, d)))})
    return pd.DataFrame(rows)


@dataclass(frozen=True)
class ManeuverFinding:
    """A suspected unlogged maneuver between ``after`` and ``epoch`` (TDB s)."""

    epoch: float        # time of the first row showing the excess
    after: float        # time of the last quiet row before it
    statistic: float    # window chi-square that raised the alarm
    threshold: float


def detect_maneuvers(time, z, window=20, p_false=1e-6) -> list[ManeuverFinding]:
    """Findings from normalized innovations ``z`` (time ordered; NaN rows ignored)."""
    ok = np.isfinite(z)
    t, s = np.asarray(time)[ok], np.asarray(z)[ok] ** 2
    if s.size < window:
        return []
    W = np.convolve(s, np.ones(window), "valid")           # W[j] = sum s[j:j+window]
    thr = chdtri(window, p_false)
    alarm = W > thr
    findings, j = [], 0
    while j < alarm.size:
        if not alarm[j]:
            j += 1
            continue
        seg = s[j:j + window]
        n_suf = np.arange(window, 0, -1)
        mu = np.cumsum(seg[::-1])[::-1] / n_suf
        glr = 0.5 * n_suf * (mu - 1.0 - np.log(mu))
        glr[mu <= 1.0] = 0.0
        i = j + int(np.argmax(glr))
        before = np.searchsorted(t, t[i]) - 1            # last row strictly earlier
        findings.append(ManeuverFinding(float(t[i]), float(t[max(before, 0)]),
                                        float(W[j]), float(thr)))
        end = j
        while end < alarm.size and alarm[end]:
            end += 1
        j = end + window
    return findings
