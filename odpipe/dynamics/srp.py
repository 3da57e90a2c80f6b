"""Solar radiation pressure: cannonball, flat plates and cylinders, conical shadow.

Force per unit pressure (m^2) of a one-sided flat plate of area A and normal n
lit from the unit vector e towards the Sun, cos(theta) = n.e > 0, with
specular and diffuse reflectivities rho_s, rho_d (absorbed 1 - rho_s - rho_d),
Montenbruck & Gill (2000) eq. 3.72:
    F = -A cos(theta) [ (1 - rho_s) e + 2 (rho_s cos(theta) + rho_d / 3) n ].
A cylinder (radius R, length L, axis k; the surface of a spin-stabilized
spacecraft) integrates that law over its lit lateral surface in closed form,
with sin(phi) = |e x k| and u the unit part of e perpendicular to k:
    F_lat = -R L sin(phi) [ 2 (1 - rho_s) e + ((8/3) rho_s sin(phi) + (pi/3) rho_d) u ],
plus its lit end cap as a flat plate of area pi R^2.

Surface rows (n, 8): [kind, x, y, z, a, b, rho_s, rho_d]; kind 0 plate with
inertial normal (x, y, z), area a; 1 sun-pointing plate, area a; 2 cylinder
with inertial axis (x, y, z), radius a, length b; 3 cylinder with sun-pointing
axis. The shadow factor uses the conical model (Montenbruck & Gill 3.4.2)
with penumbra, multiplied over occulting bodies.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np
from numba import njit

from odpipe.constants import AU, EGM96_RADIUS, MOON_RADIUS
from odpipe.dynamics.force_registry import Force, kernel

P_SUN_1AU = 4.56e-6  # N/m^2 at 1 AU (Montenbruck & Gill 2000)
R_SUN = 6.96e8  # m, photospheric radius used for the shadow cones
BODY_RADIUS = {"earth": EGM96_RADIUS, "moon": MOON_RADIUS}  # m, for shadows
PLATE, SUN_PLATE, CYLINDER, SUN_CYLINDER = 0, 1, 2, 3


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
    """Cannonball ``cr_area`` (Cr * A, m^2) and/or ``surfaces``; shadows of ``occulters``;
    pressure ``p_1au`` (N/m^2); ``scale`` the estimable multiplier (parameter 'srp_scale',
    and 'rho_s[k]', 'rho_d[k]' for surface k)."""

    cr_area: float = 0.0
    surfaces: Sequence = ()
    occulters: Sequence[str] = ("earth", "moon")
    p_1au: float = P_SUN_1AU
    scale: float = 1.0


# surfaces (n, 8) rows as above; occulters' radius (m) and env.pos row (-1: the centre);
# sun_slot (-1: the Sun is the centre); d a/d p rows of srp_scale and of (rho_s, rho_d) per surface.
SrpData = namedtuple("SrpData", ["on", "cr_area", "p_1au", "scale", "surfaces", "occ_radius", "occ_slot",
                                 "sun_slot", "scale_row", "rho_rows"])


@njit(cache=True)
def shadow_factor(r, r_sun, r_body, radius_body):
    """Fraction of the solar disc seen from ``r`` past one body (0 umbra .. 1 sunlit)."""
    return _shadow((r_sun[0] - r[0], r_sun[1] - r[1], r_sun[2] - r[2]),
                   (r_body[0] - r[0], r_body[1] - r[1], r_body[2] - r[2]), radius_body)


@njit(cache=True)
def _shadow(s_sun, s_body, radius_body):
    """:func:`shadow_factor` from the Sun and the body as seen from the spacecraft (3-tuples, m)."""
    d_sun = np.sqrt(s_sun[0] * s_sun[0] + s_sun[1] * s_sun[1] + s_sun[2] * s_sun[2])
    d_body = np.sqrt(s_body[0] * s_body[0] + s_body[1] * s_body[1] + s_body[2] * s_body[2])
    if d_body <= radius_body:
        return 0.0
    a = np.arcsin(min(1.0, R_SUN / d_sun))
    b = np.arcsin(min(1.0, radius_body / d_body))
    cos_c = (s_sun[0] * s_body[0] + s_sun[1] * s_body[1] + s_sun[2] * s_body[2]) / (d_sun * d_body)
    c = np.arccos(max(-1.0, min(1.0, cos_c)))
    if c >= a + b:
        return 1.0
    if c <= b - a:
        return 0.0
    if c <= a - b:
        return 1.0 - (b * b) / (a * a)
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = np.sqrt(max(0.0, a * a - x * x))
    area = a * a * np.arccos(max(-1.0, min(1.0, x / a))) + b * b * np.arccos(
        max(-1.0, min(1.0, (c - x) / b))) - c * y
    return 1.0 - area / (np.pi * a * a)


@njit(cache=True)
def _plate(e, n, area, rho_s, rho_d, F, dF_ds, dF_dd, J):
    """Add one plate's force per pressure, its rho partials and d F / d e to F, dF_*, J."""
    c = np.sum(n * e)
    if c <= 0.0:
        return
    k = 2.0 * (rho_s * c + rho_d / 3.0)
    for i in range(3):
        F[i] -= area * c * ((1.0 - rho_s) * e[i] + k * n[i])
        dF_ds[i] -= area * c * (-e[i] + 2.0 * c * n[i])
        dF_dd[i] -= area * c * (2.0 / 3.0) * n[i]
        for j in range(3):
            J[i, j] -= area * ((1.0 - rho_s) * (e[i] * n[j] + (c if i == j else 0.0))
                               + 2.0 * (2.0 * rho_s * c + rho_d / 3.0) * n[i] * n[j])


@njit(cache=True)
def surfaces_force(e, surfaces, F, dF_ds, dF_dd, J):
    """Force per unit pressure (m^2) of all surfaces lit from ``e``.

    dF_ds, dF_dd: (n, 3) partials wrt each surface's rho_s, rho_d; J: d F / d e
    (plates only; the cylinder's is below 1e-19 s^-2 in acceleration and omitted).
    """
    for k in range(surfaces.shape[0]):
        kind = int(surfaces[k, 0])
        rho_s, rho_d = surfaces[k, 6], surfaces[k, 7]
        if kind == PLATE or kind == SUN_PLATE:
            n = surfaces[k, 1:4].copy() if kind == PLATE else e.copy()
            _plate(e, n, surfaces[k, 4], rho_s, rho_d, F, dF_ds[k], dF_dd[k], J)
            continue
        axis = surfaces[k, 1:4].copy() if kind == CYLINDER else e.copy()
        radius, length = surfaces[k, 4], surfaces[k, 5]
        cphi = np.sum(e * axis)
        cap = axis if cphi > 0.0 else -axis
        Jcap = np.zeros((3, 3))
        _plate(e, cap, np.pi * radius * radius, rho_s, rho_d, F, dF_ds[k], dF_dd[k], Jcap)
        if kind == CYLINDER:
            J[:, :] += Jcap
        sphi = np.sqrt(max(0.0, 1.0 - cphi * cphi))
        if sphi < 1e-12:
            continue
        u = (e - cphi * axis) / sphi
        rl = radius * length * sphi
        for i in range(3):
            F[i] -= rl * (2.0 * (1.0 - rho_s) * e[i]
                          + ((8.0 / 3.0) * rho_s * sphi + np.pi / 3.0 * rho_d) * u[i])
            dF_ds[k, i] -= rl * (-2.0 * e[i] + (8.0 / 3.0) * sphi * u[i])
            dF_dd[k, i] -= rl * (np.pi / 3.0) * u[i]


@njit(cache=True)
def srp_acceleration(r, r_sun, nu, scale, p_1au, mass, cr_area, surfaces,
                     acc, grad_r, d_scale, d_rho_s, d_rho_d):
    """Add SRP (m/s^2) for the cannonball term ``cr_area`` (Cr*A, m^2) plus ``surfaces``.

    ``nu`` shadow factor, ``scale`` the estimated multiplier, ``mass`` kg.
    Writes d a/d scale into d_scale (3,), d a/d rho into d_rho_s, d_rho_d (n, 3).
    """
    w = (r_sun[0] - r[0], r_sun[1] - r[1], r_sun[2] - r[2])
    d = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    p = p_1au * (AU / d) ** 2 * nu / mass
    ns = surfaces.shape[0]
    buf = np.zeros(15 + 6 * ns)   # one allocation: e, F, J = d F / d e, dF_ds, dF_dd
    e, F, J = buf[0:3], buf[3:6], buf[6:15].reshape((3, 3))
    dF_ds, dF_dd = buf[15:15 + 3 * ns].reshape((ns, 3)), buf[15 + 3 * ns:].reshape((ns, 3))
    for i in range(3):
        e[i] = w[i] / d
        F[i] = -cr_area * e[i]
        J[i, i] = -cr_area
    surfaces_force(e, surfaces, F, dF_ds, dF_dd, J)
    for i in range(3):
        acc[i] += scale * p * F[i]
        d_scale[i] += p * F[i]
        for k in range(ns):
            d_rho_s[k, i] += scale * p * dF_ds[k, i]
            d_rho_d[k, i] += scale * p * dF_dd[k, i]
    # p ~ 1/d^2 and d d/d r = -e^T; d e / d r = -(I - e e^T) / d
    for i in range(3):
        for j in range(3):
            j_de = 0.0
            for k in range(3):
                j_de += J[i, k] * (-((1.0 if k == j else 0.0) - e[k] * e[j]) / d)
            grad_r[i, j] += scale * p * (2.0 / d * F[i] * e[j] + j_de)


def _parameters(components) -> list[str]:
    names = []
    for srp in components:
        names.append("srp_scale")
        for k in range(len(srp.surfaces)):
            names += [f"rho_s[{k}]", f"rho_d[{k}]"]
    return names


def _surface_row(sf) -> list[float]:
    direction = sf.normal if isinstance(sf, Plate) else sf.axis
    sun = isinstance(direction, str)
    vec = np.zeros(3) if sun else np.asarray(direction, float)
    if isinstance(sf, Plate):
        return [SUN_PLATE if sun else PLATE, *vec, sf.area, 0.0, sf.rho_s, sf.rho_d]
    return [SUN_CYLINDER if sun else CYLINDER, *vec, sf.radius, sf.length, sf.rho_s, sf.rho_d]


def _compile(components, ctx) -> SrpData:
    if not components:
        return SrpData(False, 0.0, 0.0, 0.0, np.zeros((0, 8)), np.zeros(0), np.zeros(0, dtype=np.int64), -1,
                       -1, np.zeros((0, 2), dtype=np.int64))
    srp = components[0]
    occ = [b.lower() for b in srp.occulters]
    ns = len(srp.surfaces)
    return SrpData(True, float(srp.cr_area), float(srp.p_1au), float(srp.scale),
                   np.array([_surface_row(sf) for sf in srp.surfaces], dtype=float).reshape(-1, 8),
                   np.array([BODY_RADIUS[b] for b in occ], dtype=float),
                   np.array([ctx.slot.get(b, -1) for b in occ], dtype=np.int64),
                   ctx.slot.get("sun", -1), int(ctx.rows(["srp_scale"])[0]),
                   ctx.rows([f"rho_{c}[{k}]" for k in range(ns) for c in "sd"]).reshape(ns, 2))


def _bodies(components, center) -> list[str]:
    if not components:
        return []
    return [b.lower() for b in components[0].occulters if b.lower() != center] + (["sun"] if center != "sun" else [])


@kernel(SrpData)
def _kernel(data, t, r, v, env, acc, grad_r, grad_v, dadp):
    if not data.on:
        return
    r_sun = env.pos[data.sun_slot] if data.sun_slot >= 0 else np.zeros(3)
    nu = 1.0
    s_sun = (r_sun[0] - r[0], r_sun[1] - r[1], r_sun[2] - r[2])
    for k in range(data.occ_radius.shape[0]):
        slot = data.occ_slot[k]
        if slot >= 0:
            s_body = (env.pos[slot, 0] - r[0], env.pos[slot, 1] - r[1], env.pos[slot, 2] - r[2])
        else:   # the centre
            s_body = (-r[0], -r[1], -r[2])
        nu *= _shadow(s_sun, s_body, data.occ_radius[k])
    ns = data.surfaces.shape[0]
    partials = np.zeros(3 + 6 * ns)   # one allocation: d a / d scale, d a / d rho_s, d a / d rho_d
    d_scale = partials[0:3]
    d_rs = partials[3:3 + 3 * ns].reshape((ns, 3))
    d_rd = partials[3 + 3 * ns:].reshape((ns, 3))
    srp_acceleration(r, r_sun, nu, data.scale, data.p_1au, env.mass, data.cr_area, data.surfaces,
                     acc, grad_r, d_scale, d_rs, d_rd)
    if data.scale_row >= 0:
        dadp[data.scale_row] += d_scale
    for k in range(ns):
        if data.rho_rows[k, 0] >= 0:
            dadp[data.rho_rows[k, 0]] += d_rs[k]
        if data.rho_rows[k, 1] >= 0:
            dadp[data.rho_rows[k, 1]] += d_rd[k]


def _substitute(components, values) -> list:
    return [replace(c, scale=values.get("srp_scale", c.scale),
                    surfaces=[replace(s, rho_s=values.get(f"rho_s[{k}]", s.rho_s), rho_d=values.get(f"rho_d[{k}]", s.rho_d))
                              for k, s in enumerate(c.surfaces)]) for c in components]


SRP = Force("srp", (SolarRadiationPressure,), _compile, parameters=_parameters, bodies=_bodies, substitute=_substitute)
