"""Station–spacecraft geometry of every row from a reference trajectory.

Adds ``elevation_rx`` and ``azimuth_rx`` (rad, at the receiving station, of the
spacecraft's apparent direction) and ``rtlt_s`` (round-trip light time, s),
which the media and editing stages use. Accuracy needed there is modest (mdeg,
ms): the light time is iterated twice in the geocentric frame, and the
direction is the spacecraft's geocentric position at emission (the Earth's
too), which for an Earth moving uniformly over the light time is the apparent
direction (light time and annual aberration; diurnal aberration, 1.5 µrad, is
left out). Rows whose signal left the spacecraft outside the trajectory's span,
or with a receiver the catalog does not know, get NaN. :func:`apparent_itrs`
gives the same direction at any ground time (the media legs' own instants), and
:func:`load_trajectory` the reference trajectory in a file a user names.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.constants import C_LIGHT
from odpipe.environment.stations import topocentric
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.time import tdb_to_utc, utc_to_tdb

RUN_TRAJECTORY = "trajectory.oem"


def add_geometry(table: pd.DataFrame, trajectory, ephemeris, catalog) -> pd.DataFrame:
    """A copy of ``table`` with ``elevation_rx``, ``azimuth_rx``, ``rtlt_s``."""
    out = table.copy()
    n = len(out)
    el, az, rtlt = np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    epochs = out["epoch"].to_numpy("datetime64[ns]")
    t = np.asarray(utc_to_tdb(epochs), float)
    lo, hi = _span(trajectory)
    for station, idx in out.groupby("station_rx", sort=False).indices.items():
        try:
            st = catalog[station]
        except KeyError:
            continue
        idx = idx[(t[idx] >= lo) & (t[idx] <= hi)]
        if idx.size == 0:
            continue
        e, first, back = np.unique(epochs[idx], return_index=True, return_inverse=True)  # rows sharing a time
        rot = gcrs_to_itrs(e)
        r_sta = np.einsum("nji,nj->ni", rot, st.position_itrs(e))  # GCRS
        r_sc = _light_time_corrected(trajectory, ephemeris, t[idx][first], r_sta)
        a, el_i, rng = topocentric(st, np.einsum("nij,nj->ni", rot, r_sc), e)
        el[idx], az[idx], rtlt[idx] = el_i[back], a[back], 2.0 * rng[back] / C_LIGHT
    out["elevation_rx"], out["azimuth_rx"], out["rtlt_s"] = el, az, rtlt
    return out


def apparent_itrs(trajectory, ephemeris):
    """``target_itrs(t_utc) -> (N, 3)`` m: the spacecraft's ITRS position at ground times ``t_utc``,
    light-time corrected from the geocentre (the station's own light time differs by < 22 ms: under
    0.1 µrad of direction at lunar or planetary distances); NaN where the signal left the spacecraft
    outside the trajectory's span."""
    lo, hi = _span(trajectory)

    def target(t_utc):
        e = np.atleast_1d(np.asarray(t_utc, "datetime64[ns]"))
        t = np.asarray(utc_to_tdb(e), float)
        out = np.full((e.size, 3), np.nan)
        ok = (t >= lo) & (t <= hi)
        if ok.any():
            r = _light_time_corrected(trajectory, ephemeris, t[ok], np.zeros((int(ok.sum()), 3)))
            out[ok] = np.einsum("nij,nj->ni", gcrs_to_itrs(e[ok]), r)
        return out
    return target


def median_round_trip(table: pd.DataFrame) -> float:
    """Median ``rtlt_s`` of the rows (s): the delay between a ramp change at the transmitter and its
    effect on the received data; 0 when the table carries no light time."""
    if "rtlt_s" not in table or not np.isfinite(table["rtlt_s"]).any():
        return 0.0
    return float(np.nanmedian(table["rtlt_s"]))


def span_utc(trajectory) -> tuple[np.datetime64, np.datetime64]:
    """(start, end) UTC of a trajectory's span (a row's signal must leave the spacecraft inside it)."""
    start, end = tdb_to_utc(np.array(_span(trajectory)))
    return np.datetime64(start, "s"), np.datetime64(end, "s")


def _span(trajectory) -> tuple[float, float]:
    return tuple(sorted((float(trajectory.t0), float(trajectory.t1))))


def load_trajectory(path, naif_id: int | None = None):
    """The reference trajectory in a file a user names: a CCSDS OEM (KVN), an SPK (body ``naif_id``,
    or the only body it holds), or an odpipe run directory (its ``trajectory.oem``, in the folder
    itself or in its ``current`` attempt). ValueError names the file and what is missing."""
    from odpipe.analysis.overlap import oem_trajectory
    from parsers import oem

    path = Path(path)
    if path.is_dir():
        found = [p for p in (path / RUN_TRAJECTORY, path / "current" / RUN_TRAJECTORY) if p.is_file()]
        if not found:
            raise ValueError(f"{path}: no {RUN_TRAJECTORY} in this run directory nor in its 'current' attempt")
        path = found[0]
    if not path.is_file():
        raise ValueError(f"{path}: trajectory file not found")
    with open(path, "rb") as f:
        head = f.read(64)
    if oem.sniff(head):
        return oem_trajectory(path)
    if head.startswith(b"DAF/SPK"):
        return _spk_trajectory(path, naif_id)
    raise ValueError(f"{path}: not a trajectory: expected a CCSDS OEM (KVN, 'CCSDS_OEM_VERS' header), "
                     "an SPK ('DAF/SPK') or an odpipe run directory")


def _spk_trajectory(path: Path, naif_id: int | None):
    """SpkTrajectory of one body about the centre its SPK segments give."""
    from odpipe.products.spk import NAIF_IDS, SpkTrajectory

    centers = _spk_segments(path)
    if naif_id is None:
        if len(centers) != 1:
            raise ValueError(f"{path}: holds bodies {sorted(centers)}: name one with --naif-id")
        naif_id = next(iter(centers))
    if naif_id not in centers:
        raise ValueError(f"{path}: no segment of body {naif_id} (it holds {sorted(centers)})")
    names = {v: k for k, v in NAIF_IDS.items()}
    center = names.get(centers[naif_id])
    if center is None:
        raise ValueError(f"{path}: body {naif_id} is given about NAIF id {centers[naif_id]}, which has no "
                         f"known name (known: {sorted(names)})")
    return SpkTrajectory(path, naif_id, center)


def _spk_segments(path: Path) -> dict[int, int]:
    """{body: centre} NAIF ids of an SPK's segments (the first segment's centre per body)."""
    import spiceypy as sp
    from spiceypy.utils.exceptions import SpiceyError

    try:
        handle = sp.dafopr(str(path))
    except SpiceyError as err:
        raise ValueError(f"{path}: not a readable SPK: {err.short} {' '.join(err.long.split())}") from None
    try:
        sp.dafbfs(handle)
        out = {}
        while sp.daffna():
            _, ic = sp.dafus(sp.dafgs(), 2, 6)
            out.setdefault(int(ic[0]), int(ic[1]))
        return out
    finally:
        sp.dafcls(handle)


def _light_time_corrected(trajectory, ephemeris, t_tdb, r_observer_gcrs):
    """Geocentric GCRS position (m) of the spacecraft seen at reception times ``t_tdb`` (inside the
    trajectory's span) from ``r_observer_gcrs`` (m): the light time iterated twice; NaN where the
    signal left before the span's start."""
    lo, hi = _span(trajectory)
    lt = np.zeros(t_tdb.size)
    for _ in range(2):
        t_emit = t_tdb - lt
        inside = (t_emit >= lo) & (t_emit <= hi)
        r_sc = np.full((t_tdb.size, 3), np.nan)
        r_sc[inside] = _geocentric(trajectory, ephemeris, t_emit[inside])
        lt = np.linalg.norm(r_sc - r_observer_gcrs, axis=1) / C_LIGHT
    return r_sc


def _geocentric(trajectory, ephemeris, t):
    r = trajectory.state(t)[:, :3]
    if trajectory.center != "earth":
        r = r + ephemeris.position(trajectory.center, "earth", t)
    return r
