"""Compiling a force model again for a span already flown reuses the field's rotation table, with the same
trajectory to the bit as a first compile (each fit pass integrates an arc's reference segments again)."""

import numpy as np
import pytest

from odpipe.dynamics import forces as F
from odpipe.dynamics import gravity_fields
from odpipe.dynamics.propagator import propagate
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.gravity import read_gravity

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
