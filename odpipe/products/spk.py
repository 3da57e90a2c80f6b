"""SPICE SPK (type 13, Hermite on unequal steps) trajectory writer through spiceypy.

SPK epochs are TDB seconds past J2000 (SPICE's ET), the models' own time, so
no time conversion is made; states go in km and km/s, frame 'J2000', which
SPICE's planetary ephemerides use as a label for the ICRF axes.
"""

from __future__ import annotations

import numpy as np
import spiceypy as sp

from parsers.atomic import atomic_path
from odpipe.products.segments import EphemerisSegment

# NAIF ids of the centres a segment may name.
NAIF_IDS = {"ssb": 0, "sun": 10, "mercury": 199, "venus": 299, "earth": 399, "moon": 301, "emb": 3, "mars": 4,
            "jupiter": 5, "saturn": 6, "uranus": 7, "neptune": 8, "pluto": 9}


def write_spk(path, segments: list[EphemerisSegment], body_id: int, *, degree: int = 7,
              segment_id: str = "odpipe", comments: list[str] = ()) -> None:
    """Write segments of body ``body_id`` (a NAIF id, e.g. -181) to a new SPK, atomically.

    Each segment covers exactly its first to its last epoch. ``degree`` is the
    Hermite polynomial degree (odd, 1..27); SPICE uses (degree+1)/2 states per
    interpolation window. ``comments`` (e.g. the run's provenance) go into the
    file's comment area (lines of at most 1000 characters; read with ``commnt``
    or ``spiceypy.dafec``).
    """
    if degree % 2 == 0:
        raise ValueError("SPK type 13 needs an odd Hermite degree")
    centers = [NAIF_IDS.get(seg.center.lower()) for seg in segments]
    unknown = [seg.center for seg, c in zip(segments, centers) if c is None]
    if unknown:
        raise ValueError(f"no NAIF id known for centre(s) {unknown}")
    comments = [str(c) for c in comments]
    if any(len(c) > 1000 for c in comments):
        raise ValueError("SPK comment lines are limited to 1000 characters")
    with atomic_path(path) as tmp:
        handle = sp.spkopn(str(tmp), "odpipe", sum(len(c) + 1 for c in comments))
        try:
            if comments:
                sp.dafac(handle, comments)
            for seg, center in zip(segments, centers):
                sp.spkw13(handle, body_id, center, "J2000", float(seg.t_tdb[0]), float(seg.t_tdb[-1]),
                          segment_id[:40], degree, len(seg.t_tdb), np.ascontiguousarray(seg.states / 1e3),
                          np.ascontiguousarray(seg.t_tdb))
        finally:
            sp.spkcls(handle)


class SpkTrajectory:
    """A body's trajectory from an SPK file through SPICE (e.g. a reference or truth ephemeris).

    ``state(t_tdb) -> (N,6)`` m, m/s in ICRF axes about ``center``; ``t0``, ``t1``
    bound the file's coverage of the body (s TDB). The file is loaded into SPICE only while
    ``state`` reads it, so the kernel pool never holds a file that may later be moved or removed.
    """

    def __init__(self, path, body_id: int, center: str = "earth"):
        self.path, self.body, self.center = str(path), int(body_id), center
        cover = sp.spkcov(self.path, self.body)
        windows = [sp.wnfetd(cover, i) for i in range(sp.wncard(cover))]
        if not windows:
            raise ValueError(f"{path}: no SPK data for body {body_id}")
        self.t0, self.t1 = windows[0][0], windows[-1][1]

    def state(self, t_tdb) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t_tdb, float))
        center = NAIF_IDS[self.center]
        sp.furnsh(self.path)
        try:
            return np.array([sp.spkgeo(self.body, float(x), "J2000", center)[0] for x in t]) * 1e3
        finally:
            sp.unload(self.path)
