"""Compiling a force model again for a span already flown reuses the field's rotation table, with the same
trajectory to the bit as a first compile (each fit pass integrates an arc's reference segments again)."""

import numpy as np
import pytest

from odpipe.dynamics import forces as F
from odpipe.dynamics import gravity_fields
from odpipe.dynamics.propagator import propagate
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.gravity import read_gravity
from odpipe.numerics.chebyshev import evaluate, stack_channels

pytestmark = pytest.mark.realdata

T0 = 387302466.0  # TDB s: 2012-04-10 04:00 UTC, a GRAIL-B daily arc's start


def test_second_compile_reuses_the_rotation_and_flies_the_same_trajectory(shared_data):
    field = read_gravity(shared_data / "gravity/tudat/lpe200.txt")
    model = F.ForceModel("moon", [F.PointMasses(["earth", "sun"]), F.SphericalHarmonics("moon", field, 20, 4)],
                         220.0, Ephemeris.open("de421"))
    x0 = np.array([1.79e6, 0.0, 0.0, 0.0, 300.0, 1600.0])   # ~50 km above the mean radius, near polar
    gravity_fields._ROTATIONS.clear()
    first = propagate(x0, T0, T0 + 1800.0, model)
    fitted = len(gravity_fields._ROTATIONS)
    held = next(iter(gravity_fields._ROTATIONS.values()))[0].copy()
    again = propagate(x0, T0, T0 + 1800.0, model)
    assert fitted == 1 and len(gravity_fields._ROTATIONS) == 1
    t = np.linspace(T0, T0 + 1800.0, 7)
    np.testing.assert_array_equal(again.state(t), first.state(t))
    np.testing.assert_array_equal(again.stm(t), first.stm(t))
    gravity_fields._ROTATIONS.clear()   # fitted afresh: the table held was the same
    propagate(x0, T0, T0 + 1800.0, model)
    np.testing.assert_array_equal(next(iter(gravity_fields._ROTATIONS.values()))[0], held)


def test_rotation_pieces_sit_on_a_fixed_grid_whatever_the_span(shared_data):
    """Spans inside the same whole pieces (a filter's steps, an arc's segments) share one fit, and the table
    matches the Moon's frame (DE421's libration angles through the default rotation) inside every piece: degree 12
    over a day holds it to 2e-12, under 10 um at the Moon's radius."""
    field = read_gravity(shared_data / "gravity/tudat/lpe200.txt")
    s = F.SphericalHarmonics("moon", field, 20, 4)
    gravity_fields._ROTATIONS.clear()
    wide = gravity_fields._rotation_channel(s, T0 - 3600.0, T0 + 5400.0)
    inner = gravity_fields._rotation_channel(s, T0 + 600.0, T0 + 1200.0)
    assert inner is wide and len(gravity_fields._ROTATIONS) == 1
    seg = gravity_fields.ROTATION_GRID["moon"][0]
    t_start, _, nseg = wide[1]
    assert t_start % seg == 0.0 and t_start <= T0 - 3600.0 and t_start + nseg * seg >= T0 + 5400.0
    coefs, meta = stack_channels([wide])
    rot = gravity_fields.default_rotation("moon")
    out = np.zeros(9)
    for t in np.linspace(T0 - 3600.0, T0 + 5400.0, 11):
        evaluate(coefs, meta, 0, t, out)
        np.testing.assert_allclose(out, np.asarray(rot(np.array([t]))).reshape(9), rtol=0, atol=5e-12)
