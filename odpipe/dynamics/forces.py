"""Force-model components and their compilation into arrays for the numba kernel.

A :class:`ForceModel` is a centre (NAIF name: 'earth', 'moon', 'sun', 'emb',
'ssb', ...) and a list of components:

* :class:`PointMasses` - third bodies from the ephemeris (indirect terms included);
* :class:`SphericalHarmonics` - a body's field in its body-fixed frame (ITRS for
  Earth, DE421 PA for the Moon by default), optionally with partials from a
  lower degree; it replaces that body's point mass (a third body keeps the
  point-mass indirect term);
* :class:`SolarRadiationPressure` - cannonball Cr*A and/or :class:`Plate` and
  :class:`Cylinder` surfaces, conical shadow of the occulting bodies;
* :class:`AtmosphericDrag` - Harris-Priester drag, atmosphere co-rotating with the Earth
  (Earth-centred models only, :mod:`odpipe.dynamics.drag`);
* :class:`EmpiricalRTN` - constant or piecewise-constant RTN accelerations;
* :class:`Relativity` - Schwarzschild term of the central body;
* :class:`FiniteBurn` - constant thrust in ICRF or RTN over an interval, with mass flow;
* :class:`ImpulsiveManeuver` - ICRF delta-v at an epoch (handled by the propagator).

Estimable dynamic parameters (names used by ``Trajectory.param_names``):
``srp_scale``, ``rho_s[k]``/``rho_d[k]`` (surface k), ``cd`` (drag), ``emp[b].R|T|N`` (batch b),
``dv[k].x|y|z`` and ``dv[k].t`` (impulsive maneuver k).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from odpipe.constants import EGM96_RADIUS, MOON_RADIUS
from odpipe.numerics.chebyshev import fit_channel, stack_channels
from odpipe.dynamics.harmonics import by_order, recursion_factors
from odpipe.dynamics.srp import CYLINDER, P_SUN_1AU, PLATE, SUN_CYLINDER, SUN_PLATE
from odpipe.environment.gravity import GravityField

BODY_RADIUS = {"earth": EGM96_RADIUS, "moon": MOON_RADIUS}  # m, for shadows
ROTATION_GRID = {"earth": (3600.0, 12), "moon": (86400.0, 12)}  # s per segment, degree


@dataclass
class PointMasses:
    bodies: Sequence[str]


@dataclass
class SphericalHarmonics:
    """``rotation(t_tdb) -> (N,3,3)`` ICRF-to-body-fixed; default ITRS (Earth) / DE421 PA (Moon)."""

    body: str
    field: GravityField
    degree: int
    partial_degree: int | None = None
    rotation: Callable | None = None


@dataclass
class Plate:
    """Flat plate: ``normal`` ICRF unit vector or 'sun'; area m^2; reflectivities."""

    normal: object
    area: float
    rho_s: float = 0.0
    rho_d: float = 0.0


@dataclass
class Cylinder:
    """Cylinder (spin axis ``axis``: ICRF unit vector or 'sun'); radius, length m."""

    axis: object
    radius: float
    length: float
    rho_s: float = 0.0
    rho_d: float = 0.0


@dataclass
class SolarRadiationPressure:
    cr_area: float = 0.0  # Cr * A, m^2 (cannonball)
    surfaces: Sequence = ()
    occulters: Sequence[str] = ("earth", "moon")
    p_1au: float = P_SUN_1AU
    scale: float = 1.0


@dataclass
class AtmosphericDrag:
    """Drag coefficient Cd, cross-section area (m^2); Harris-Priester bulge exponent n (2 low, 6 polar orbits)."""

    cd: float
    area: float
    n_bulge: float = 6.0


@dataclass
class EmpiricalRTN:
    """Rows (t_start, t_end, aR, aT, aN): TDB s, m/s^2; active for t_start <= t < t_end."""

    batches: np.ndarray


@dataclass
class Relativity:
    pass


@dataclass
class FiniteBurn:
    t_start: float
    t_end: float
    thrust: float  # N
    direction: Sequence[float]  # unit vector in ``frame``
    mass_flow: float = 0.0  # kg/s
    frame: str = "icrf"  # or 'rtn'


@dataclass
class ImpulsiveManeuver:
    epoch: float  # TDB s
    dv: Sequence[float]  # ICRF, m/s


@dataclass
class ForceModel:
    """Centre, components, spacecraft mass (kg), the ephemeris (``Ephemeris``) and
    optionally the centre's GM (m^3/s^2; default from the ephemeris)."""

    center: str
    components: list = field(default_factory=list)
    mass: float = 1000.0
    ephemeris: object = None
    central_gm: float | None = None

    def of_type(self, kind):
        return [c for c in self.components if isinstance(c, kind)]

    def maneuvers(self) -> list[ImpulsiveManeuver]:
        return sorted(self.of_type(ImpulsiveManeuver), key=lambda m: m.epoch)

    def parameter_names(self) -> list[str]:
        """All estimable dynamic parameters of this model, in canonical order."""
        names = []
        for srp in self.of_type(SolarRadiationPressure):
            names.append("srp_scale")
            for k in range(len(srp.surfaces)):
                names += [f"rho_s[{k}]", f"rho_d[{k}]"]
        if self.of_type(AtmosphericDrag):
            names.append("cd")
        for emp in self.of_type(EmpiricalRTN):
            for b in range(len(np.atleast_2d(emp.batches))):
                names += [f"emp[{b}].{c}" for c in "RTN"]
        for k, _ in enumerate(self.maneuvers()):
            names += [f"dv[{k}].{c}" for c in "xyz"] + [f"dv[{k}].t"]
        return names

    def breakpoints(self) -> list[float]:
        """Epochs where the dynamics are discontinuous (segments restart there)."""
        pts = [m.epoch for m in self.maneuvers()]
        for emp in self.of_type(EmpiricalRTN):
            pts += list(np.atleast_2d(emp.batches)[:, :2].ravel())
        for b in self.of_type(FiniteBurn):
            pts += [b.t_start, b.t_end]
        return sorted(set(pts))


PARAM_SCALE, PARAM_RHO_S, PARAM_RHO_D, PARAM_EMP, PARAM_DV, PARAM_DT, PARAM_CD = range(7)


def _param_code(name: str) -> tuple[int, int]:
    if name == "srp_scale":
        return PARAM_SCALE, 0
    if name == "cd":
        return PARAM_CD, 0
    head, _, tail = name.partition("]")
    kind, _, idx = head.partition("[")
    idx = int(idx)
    if kind == "rho_s":
        return PARAM_RHO_S, idx
    if kind == "rho_d":
        return PARAM_RHO_D, idx
    if kind == "emp":
        return PARAM_EMP, 3 * idx + "RTN".index(tail[1:])
    if kind == "dv":
        return (PARAM_DT, idx) if tail == ".t" else (PARAM_DV, 3 * idx + "xyz".index(tail[1:]))
    raise ValueError(f"unknown dynamic parameter {name!r}")


def _default_rotation(body: str) -> Callable:
    if body == "earth":
        from odpipe.frames.earth import gcrs_to_itrs

        return gcrs_to_itrs
    if body == "moon":
        from odpipe.frames.moon import moon_pa_to_icrf

        return lambda t: np.swapaxes(moon_pa_to_icrf(t), -1, -2)
    raise ValueError(f"no default body-fixed frame for {body!r}; give SphericalHarmonics.rotation")


def compile_model(fm: ForceModel, t0: float, t1: float, params: Sequence[str], with_stm: bool):
    """Arrays the numba right-hand side reads (see :mod:`odpipe.dynamics.rhs`).

    ``model[1][5]`` is the mid-epoch of the segment being integrated; the propagator
    sets it so empirical batches and burns switch exactly at segment boundaries.
    ``model[16]`` is the drag row [on, Cd, area (m^2), bulge exponent, Sun slot].
    """
    lo, hi = min(t0, t1) - 3600.0, max(t0, t1) + 3600.0
    eph = fm.ephemeris
    center = fm.center.lower()
    sh_list = fm.of_type(SphericalHarmonics)
    sh_bodies = {s.body.lower() for s in sh_list}
    srp = fm.of_type(SolarRadiationPressure)
    srp = srp[0] if srp else None
    third = [b.lower() for pm in fm.of_type(PointMasses) for b in pm.bodies]
    drag = fm.of_type(AtmosphericDrag)
    drag = drag[0] if drag else None
    if drag is not None and center != "earth":
        raise ValueError("atmospheric drag needs an Earth-centred force model")
    # every body whose position the kernel needs, relative to the centre
    needed = list(dict.fromkeys(
        third + [s.body.lower() for s in sh_list if s.body.lower() != center]
        + ([b.lower() for b in srp.occulters if b.lower() != center] if srp else [])
        + (["sun"] if (srp or drag) and center != "sun" else [])))
    if needed:
        interp = eph.interpolant(needed, center, lo, hi)
        coeffs, t_start, t_step = interp.coeffs, interp.t_start, interp.t_step
    else:
        coeffs, t_start, t_step = np.zeros((1, 1, 3, 1)), lo, hi - lo
    slot = {b: i for i, b in enumerate(needed)}

    def gm(body):
        return float(eph.gm(body))

    barycentre = center in ("ssb", "emb")
    gm_body = 0.0 if barycentre else (fm.central_gm if fm.central_gm is not None else gm(center))
    gm_center = 0.0 if center in sh_bodies else gm_body
    pm = np.array([[gm(b), slot[b], 1.0] for b in third if b not in sh_bodies]
                  + [[gm(b), slot[b], 0.0] for b in third if b in sh_bodies]).reshape(-1, 3)
    # SH fields: rows [gm, radius, nmax, ngrad, slot (-1 centre), rotation channel]
    nmax_all = max([s.degree for s in sh_list] + [2])
    C = np.zeros((max(1, len(sh_list)), nmax_all + 1, nmax_all + 1))
    S = np.zeros_like(C)
    sh_meta = np.zeros((len(sh_list), 6))
    channels = []
    for k, s in enumerate(sh_list):
        g = s.field.truncated(s.degree)
        C[k, : s.degree + 1, : s.degree + 1] = by_order(g.C)
        S[k, : s.degree + 1, : s.degree + 1] = by_order(g.S)
        ngrad = (s.degree if s.partial_degree is None else s.partial_degree) if with_stm else -1
        body = s.body.lower()
        rot = s.rotation or _default_rotation(body)
        seg, deg = ROTATION_GRID.get(body, (3600.0, 12))
        channels.append(fit_channel(lambda t, rot=rot: np.asarray(rot(t)).reshape(-1, 9), lo, hi, seg, deg))
        sh_meta[k] = [g.gm, g.radius, s.degree, ngrad, slot.get(body, -1) if body != center else -1, k]
    rot_coefs, rot_meta = stack_channels(channels)
    fac = recursion_factors(max(nmax_all, 2))
    # SRP
    surf_rows = []
    occ = np.zeros((0, 2))
    sun_slot = -1
    srp_row = np.zeros(4)  # [on, cr_area, p_1au, scale]
    if srp is not None:
        for sf in srp.surfaces:
            sun = isinstance(getattr(sf, "normal", getattr(sf, "axis", None)), str)
            vec = np.zeros(3) if sun else np.asarray(getattr(sf, "normal", getattr(sf, "axis", None)), float)
            if isinstance(sf, Plate):
                surf_rows.append([SUN_PLATE if sun else PLATE, *vec, sf.area, 0.0, sf.rho_s, sf.rho_d])
            else:
                surf_rows.append([SUN_CYLINDER if sun else CYLINDER, *vec, sf.radius, sf.length,
                                  sf.rho_s, sf.rho_d])
        occ = np.array([[BODY_RADIUS[b.lower()], slot.get(b.lower(), -1)] for b in srp.occulters]).reshape(-1, 2)
        sun_slot = slot.get("sun", -1)
        srp_row = np.array([1.0, srp.cr_area, srp.p_1au, srp.scale])
    surfaces = np.array(surf_rows, dtype=float).reshape(-1, 8)
    emp = np.concatenate([np.atleast_2d(np.asarray(e.batches, float)) for e in fm.of_type(EmpiricalRTN)]
                         or [np.zeros((0, 5))]).reshape(-1, 5)
    burns = np.array([[b.t_start, b.t_end, b.thrust, b.mass_flow, *np.asarray(b.direction, float),
                       1.0 if b.frame == "rtn" else 0.0] for b in fm.of_type(FiniteBurn)]).reshape(-1, 8)
    pmap = np.array([_param_code(p) for p in params], dtype=np.int64).reshape(-1, 2)
    flags = np.array([1 if fm.of_type(Relativity) else 0, 1 if with_stm else 0, sun_slot], dtype=np.int64)
    scal = np.array([gm_center, fm.mass, t_start, t_step, gm_body, 0.5 * (t0 + t1)])
    drag_row = (np.array([1.0, drag.cd, drag.area, drag.n_bulge, slot["sun"]]) if drag is not None
                else np.zeros(5))
    return (flags, scal, coeffs, pm, C, S, fac, sh_meta, rot_coefs, rot_meta, srp_row, surfaces, occ,
            emp, burns, pmap, drag_row)
