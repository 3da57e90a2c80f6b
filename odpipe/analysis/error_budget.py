"""Error budget of an overlap: what each model error does to the difference of two overlapping arcs.

Two measures, both in arc A's radial / in-track / cross-track axes over the overlap span:

* difference of solutions (:func:`term_contribution`): both arcs refitted with one model changed
  (another lunar field, an ionosphere added, ...); the term's contribution to the overlap is the
  change of A minus the change of B, (A' − A) − (B' − B), its RMS per component;
* formal (:func:`formal_sigma`): the arcs' own smoothed covariances (data noise and the stochastic
  accelerations' process noise), RMS over the overlap's covariance epochs of the sigma of A − B taken as
  independent, sqrt(P_A + P_B) (an upper bound: both arcs fit the overlap's data).
"""

from __future__ import annotations

import numpy as np

from odpipe.analysis.overlap import COMPONENTS, EDGE, oem_trajectory
from odpipe.frames.local import rtn_matrix
from odpipe.time import utc_to_tdb
from parsers import oem

_J2000 = np.datetime64("2000-01-01T12:00:00", "ns")


def overlap_grid(traj_a, traj_b, step: float = 60.0) -> np.ndarray:
    """TDB s every ``step`` over the common span of two trajectories."""
    t0, t1 = max(traj_a.t0, traj_b.t0), min(traj_a.t1, traj_b.t1)
    if t1 <= t0:
        raise ValueError("the arcs do not overlap")
    return np.linspace(t0, t1, max(int(np.ceil((t1 - t0) / step)), 1) + 1)


def _ric(axes_traj, t, d):
    x = axes_traj.state(t)
    return np.einsum("nij,nj->ni", rtn_matrix(x[:, :3], x[:, 3:]), d)


def rms(d: np.ndarray) -> dict:
    """{radial, intrack, crosstrack, 3d}: RMS (m) of (N,3) R/I/C differences."""
    r = np.sqrt(np.mean(d**2, axis=0))
    return dict(zip(COMPONENTS, r)) | {"3d": float(np.sqrt(np.sum(r**2)))}


def term_contribution(base_a, base_b, pert_a, pert_b, step: float = 60.0) -> dict:
    """RMS per R/I/C component and 3D (m) of (A' − A) − (B' − B) over the overlap of A and B, and the
    perturbed overlap's own 3D RMS (``overlap_3d``)."""
    t = overlap_grid(base_a, base_b, step)
    change = _ric(base_a, t, (pert_a.state(t) - base_a.state(t) - pert_b.state(t) + base_b.state(t))[:, :3])
    seen = _ric(pert_a, t, (pert_a.state(t) - pert_b.state(t))[:, :3])
    return rms(change) | {"overlap_3d": rms(seen)["3d"]}


def _covariances(path):
    """(TDB s, (M,6,6)) of every covariance block of an OEM."""
    t, P = [], []
    for seg in oem.read(path):
        if len(seg.cov_epochs):
            scale = seg.meta.get("COV_TIME_SYSTEM", seg.meta.get("TIME_SYSTEM", "UTC"))
            t.append((seg.cov_epochs - _J2000) / np.timedelta64(1, "s") if scale == "TDB"
                     else utc_to_tdb(seg.cov_epochs))
            P.append(seg.covariances)
    if not t:
        raise ValueError(f"{path}: no covariance blocks")
    return np.concatenate(t), np.concatenate(P)


def formal_sigma(oem_a, oem_b) -> dict:
    """RMS over A's covariance epochs inside the overlap of the R/I/C sigma (m) of A − B, from both
    OEMs' covariances (B's interpolated linearly to those epochs, element by element)."""
    traj_a, traj_b = oem_trajectory(oem_a), oem_trajectory(oem_b)
    ta, Pa = _covariances(oem_a)
    tb, Pb = _covariances(oem_b)
    t0, t1 = max(traj_a.t0, traj_b.t0, tb[0]) - EDGE, min(traj_a.t1, traj_b.t1, tb[-1]) + EDGE
    keep = (ta >= t0) & (ta <= t1)
    if not keep.any():
        raise ValueError(f"{oem_a}, {oem_b}: no covariance epoch inside the overlap")
    t = ta[keep]
    pb = np.stack([np.interp(t, tb, Pb[:, i, j]) for i in range(3) for j in range(3)], -1).reshape(-1, 3, 3)
    x = traj_a.state(t)
    rot = rtn_matrix(x[:, :3], x[:, 3:])
    S = rot @ (Pa[keep][:, :3, :3] + pb) @ np.transpose(rot, (0, 2, 1))
    sig = np.sqrt(np.mean(np.diagonal(S, axis1=1, axis2=2), axis=0))
    return dict(zip(COMPONENTS, sig)) | {"3d": float(np.sqrt(np.sum(sig**2)))}


def earth_elevation_deg(traj, ephemeris, t_tdb) -> np.ndarray:
    """Elevation (deg) of the Earth above the orbit plane of ``traj`` (about the Moon) at ``t_tdb``: near
    90 deg the line of sight is along the orbit normal (Doppler sees cross-track, not in-track); near 0 it
    lies in the plane (Doppler blind to cross-track)."""
    x = traj.state(t_tdb)
    h = np.cross(x[:, :3], x[:, 3:])
    e = ephemeris.position("earth", "moon", np.atleast_1d(t_tdb))
    s = np.sum(h * e, axis=1) / np.linalg.norm(h, axis=1) / np.linalg.norm(e, axis=1)
    return np.degrees(np.arcsin(s))
