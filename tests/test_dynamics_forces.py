"""Force components vs independent values; every acceleration partial vs central differences."""

import numpy as np
import pytest

from odpipe.numerics.chebyshev import evaluate
from odpipe.dynamics.forces import (Cylinder, EmpiricalRTN, FiniteBurn, ForceModel, Plate, PointMasses,
                                    Relativity, SolarRadiationPressure, SphericalHarmonics,
                                    compile_model)
from odpipe.dynamics.rhs import acceleration
from odpipe.dynamics.srp import AU, R_SUN, shadow_factor, surfaces_force
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.gravity import read_gravity

T0 = 387_000_000.0  # 2012-04-07, TDB s past J2000


@pytest.fixture(scope="module")
def eph():
    return Ephemeris.open("de440")


def _accel(model, t, x):
    model.segment[0] = t  # the segment containing t (selects empirical batch and burn)
    npar = model.n_params
    acc, gr, gv, dp = np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((npar, 3))
    acceleration(t, x[:3].copy(), x[3:].copy(), model, acc, gr, gv, dp)
    return acc, gr, gv, dp


def _full_model(shared_data, eph, **srp_kw):
    jgm3 = read_gravity(shared_data / "gravity/gmat/JGM3.cof")
    lp = read_gravity(shared_data / "gravity/gmat/LP165P.cof")
    srp = SolarRadiationPressure(cr_area=6.5, surfaces=[
        Plate(np.array([0.6, 0.0, 0.8]), 2.0, 0.3, 0.1), Plate("sun", 1.5, 0.2, 0.2),
        Cylinder(np.array([0.0, 0.6, 0.8]), 0.5, 0.8, 0.3, 0.2)], **srp_kw)
    comps = [PointMasses(["moon", "sun", "jupiter"]), SphericalHarmonics("earth", jgm3, 8),
             SphericalHarmonics("moon", lp, 8), srp,
             EmpiricalRTN(np.array([[T0 - 1e5, T0 + 1e5, 1e-8, 2e-8, -1e-8]])), Relativity(),
             FiniteBurn(T0 - 50.0, T0 + 50.0, 20.0, np.array([0.0, 0.6, 0.8]), 0.01, "rtn")]
    return ForceModel("earth", comps, mass=500.0, ephemeris=eph)


X_CISLUNAR = np.array([2.1e8, -1.4e8, -0.6e8, 300.0, 600.0, 200.0])
X_LEO = np.array([6.9e6, 1.1e6, 0.7e6, -1.2e3, 7.3e3, 1.1e3])


@pytest.mark.realdata
@pytest.mark.parametrize("x", [X_CISLUNAR, X_LEO])
def test_every_acceleration_partial_vs_central_differences(shared_data, eph, x):
    fm = _full_model(shared_data, eph)
    names = fm.parameter_names()
    model = compile_model(fm, T0, T0 + 3600.0, names, True)
    t = T0 + 10.0  # inside the burn and the empirical batch; sunlit
    acc, gr, gv, dp = _accel(model, t, x)
    fd_r = np.empty((3, 3))
    fd_v = np.empty((3, 3))
    for j in range(3):
        e = np.zeros(6)
        e[j] = 1.0
        fd_r[:, j] = (_accel(model, t, x + e)[0] - _accel(model, t, x - e)[0]) / 2.0
        e = np.zeros(6)
        e[3 + j] = 1e-2
        fd_v[:, j] = (_accel(model, t, x + e)[0] - _accel(model, t, x - e)[0]) / 2e-2
    np.testing.assert_allclose(gr, fd_r, rtol=0, atol=1e-7 * np.abs(fd_r).max())
    np.testing.assert_allclose(gv, fd_v, rtol=0, atol=1e-6 * np.abs(fd_v).max() + 1e-22)
    assert np.abs(gv).max() > 0  # GR, RTN empirical and RTN thrust depend on v
    # parameters: rebuild the model with each parameter moved
    srp = fm.of_type(SolarRadiationPressure)[0]
    emp = fm.of_type(EmpiricalRTN)[0]
    for p, name in enumerate(names):
        h = 0.05  # every parameter enters linearly: no truncation error, small round-off

        def moved(delta, name=name):
            if name == "srp_scale":
                srp.scale += delta
            elif name.startswith("rho_"):
                k = int(name[6:-1])
                surf = srp.surfaces[k]
                setattr(surf, name[:5], getattr(surf, name[:5]) + delta)
            else:
                emp.batches[0, 2 + "RTN".index(name[-1])] += delta * 1e-6
            a = _accel(compile_model(fm, T0, T0 + 3600.0, [], False), t, x)[0]
            return a

        up = moved(h)
        down = moved(-2 * h)
        moved(h)
        scale = 1e-6 if name.startswith("emp") else 1.0
        fd = (up - down) / (2 * h * scale)
        np.testing.assert_allclose(dp[p], fd, rtol=1e-6, atol=1e-5 * np.abs(fd).max() + 1e-24,
                                   err_msg=name)
        assert np.abs(dp[p]).max() > 0, name


def test_third_body_matches_ephemeris_directly(eph):
    fm = ForceModel("earth", [PointMasses(["moon", "sun"])], ephemeris=eph)
    model = compile_model(fm, T0, T0 + 86400.0, [], False)
    t = T0 + 12345.6
    acc = _accel(model, t, X_CISLUNAR)[0]
    r = X_CISLUNAR[:3]
    ref = -eph.gm("earth") * r / np.linalg.norm(r) ** 3
    for body in ("moon", "sun"):
        s = eph.position(body, "earth", np.array([t]))[0]
        ref += eph.gm(body) * ((s - r) / np.linalg.norm(s - r) ** 3 - s / np.linalg.norm(s) ** 3)
    np.testing.assert_allclose(acc, ref, rtol=1e-9)


def test_moon_centred_third_body_earth(eph):
    """Same physics seen from the Moon: the relative acceleration is frame-consistent."""
    t = T0 + 500.0
    r_moon = eph.position("moon", "earth", np.array([t]))[0]
    x_moon = np.r_[X_CISLUNAR[:3] - r_moon, 0, 0, 0]
    fm = ForceModel("moon", [PointMasses(["earth"])], ephemeris=eph)
    acc_m = _accel(compile_model(fm, T0, T0 + 3600.0, [], False), t, x_moon)[0]
    fe = ForceModel("earth", [PointMasses(["moon"])], ephemeris=eph)
    acc_e = _accel(compile_model(fe, T0, T0 + 3600.0, [], False), t, X_CISLUNAR)[0]
    # a_sc/moon = a_sc/earth - a_moon/earth, where a_moon/earth = -(GMe + GMm) r_moon / |r_moon|^3
    a_moon = -(eph.gm("earth") + eph.gm("moon")) * r_moon / np.linalg.norm(r_moon) ** 3
    np.testing.assert_allclose(acc_m, acc_e - a_moon, rtol=1e-9)


def test_rotation_tables_match_direct_calls():
    from odpipe.frames.earth import gcrs_to_itrs
    from odpipe.frames.moon import moon_pa_to_icrf

    from odpipe.numerics.chebyshev import fit_channel, stack_channels
    from odpipe.dynamics.forces import ROTATION_GRID

    t1 = T0 + 3 * 86400.0
    seg_e, deg_e = ROTATION_GRID["earth"]
    seg_m, deg_m = ROTATION_GRID["moon"]
    coefs, meta = stack_channels([
        fit_channel(lambda t: gcrs_to_itrs(t).reshape(-1, 9), T0, t1, seg_e, deg_e),
        fit_channel(lambda t: np.swapaxes(moon_pa_to_icrf(t), -1, -2).reshape(-1, 9), T0, t1, seg_m, deg_m)])
    tq = np.random.default_rng(1).uniform(T0, t1, 40)
    out = np.empty(9)
    for ch, direct in ((0, gcrs_to_itrs(tq)), (1, np.swapaxes(moon_pa_to_icrf(tq), -1, -2))):
        err = 0.0
        for k, t in enumerate(tq):
            evaluate(coefs, meta, ch, t, out)
            err = max(err, np.abs(out.reshape(3, 3) - direct[k]).max())
        assert err < 1e-11, (ch, err)  # rad: < 0.1 mm on the Earth's surface (measured 3e-12)


def test_conical_shadow_cases():
    r_sun = np.array([AU, 0.0, 0.0])
    re = 6378136.3
    assert shadow_factor(np.array([0.0, 2 * re, 0.0]), r_sun, np.zeros(3), re) == 1.0
    assert shadow_factor(np.array([-2 * re, 0.0, 0.0]), r_sun, np.zeros(3), re) == 0.0
    # far behind a small body the Sun is an annulus: 1 - (b/a)^2 with apparent radii a, b
    far = np.array([-0.5 * AU, 0.0, 0.0])
    small = 1.0e5
    a = np.arcsin(R_SUN / (1.5 * AU))
    b = np.arcsin(small / (0.5 * AU))
    assert shadow_factor(far, r_sun, np.zeros(3), small) == pytest.approx(1 - b * b / (a * a), rel=1e-12)
    # penumbra is monotonic across the shadow edge
    ys = np.linspace(re * 0.95, re * 1.05, 51)
    nu = [shadow_factor(np.array([-3e7, y, 0.0]), r_sun, np.zeros(3), re) for y in ys]
    assert nu[0] == 0.0 and nu[-1] == 1.0 and np.all(np.diff(nu) >= 0) and 0 < nu[25] < 1


def test_cylinder_closed_form_vs_facet_sum():
    """Lateral cylinder force vs a sum of 2000 flat facets plus the end cap."""
    axis = np.array([0.0, 0.0, 1.0])
    radius, length, rs, rd = 0.9, 1.3, 0.35, 0.25
    for phi in (0.3, 1.0, 1.5, 2.4):
        e = np.array([np.sin(phi), 0.0, np.cos(phi)])
        F = np.zeros(3)
        J = np.zeros((3, 3))
        surfaces_force(e, np.array([[2, *axis, radius, length, rs, rd]]), F, np.zeros((1, 3)),
                       np.zeros((1, 3)), J)
        n = 2000
        alpha = (np.arange(n) + 0.5) * 2 * np.pi / n
        rows = [[0, np.cos(a), np.sin(a), 0.0, radius * length * 2 * np.pi / n, 0, rs, rd] for a in alpha]
        rows.append([0, *(axis if np.cos(phi) > 0 else -axis), np.pi * radius**2, 0, rs, rd])
        F_ref = np.zeros(3)
        surfaces_force(e, np.array(rows), F_ref, np.zeros((n + 1, 3)), np.zeros((n + 1, 3)), J)
        np.testing.assert_allclose(F, F_ref, rtol=1e-5, atol=1e-6)


@pytest.mark.realdata
@pytest.mark.parametrize("body", ["earth", "moon"])
def test_body_fixed_field_through_the_force_model(shared_data, eph, body):
    """Field acceleration in ICRF = R^T grad U(R r), with R from the frames module directly
    and U summed with scipy (orientation convention of ITRS and DE421 PA checked)."""
    from test_gravity_harmonics import _potential

    from odpipe.frames.earth import gcrs_to_itrs
    from odpipe.frames.moon import moon_pa_to_icrf

    name = "gravity/gmat/JGM3.cof" if body == "earth" else "gravity/gmat/LP165P.cof"
    g = read_gravity(shared_data / name).truncated(6)
    fm = ForceModel(body, [SphericalHarmonics(body, g, 6)], ephemeris=eph)
    model = compile_model(fm, T0, T0 + 86400.0, [], False)
    t = T0 + 30000.0
    x = np.r_[np.array([0.8, -0.5, 0.45]) * 1.15 * g.radius, 0.0, 0.0, 0.0]
    acc = _accel(model, t, x)[0]
    R = gcrs_to_itrs(t) if body == "earth" else moon_pa_to_icrf(t).T
    r_bf = R @ x[:3]
    h = 1.0
    grad = np.array([(_potential(r_bf + e, g.gm, g.radius, g.C, g.S, 6)
                      - _potential(r_bf - e, g.gm, g.radius, g.C, g.S, 6)) / (2 * h) for e in np.eye(3) * h])
    central = -g.gm * x[:3] / np.linalg.norm(x[:3]) ** 3
    np.testing.assert_allclose(acc - central, R.T @ grad, rtol=0, atol=1e-8 * np.abs(grad).max())
