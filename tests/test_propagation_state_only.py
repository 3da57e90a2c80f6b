"""State-only queries (``Trajectory.state``, ``SegmentTrajectory.state``) interpolate the six state
components alone: the same values, bit for bit, as the full interpolation with the STM and sensitivities,
and Kepler's closed form on a two-body orbit restarted at batch boundaries and across a burn."""

import numpy as np

from odpipe.dynamics.forces import EmpiricalRTN, ForceModel
from odpipe.dynamics.propagator import propagate
from odpipe.od.segment import SegmentTrajectory, ShiftedSegmentTrajectory

from test_propagation_twobody import GM, X0, kepler

T1 = 3 * 8600.0
# zero accelerations: the orbit stays Keplerian, but the integration restarts at 4000 s and 9000 s
BATCHES = np.array([[0.0, 4000.0, 0, 0, 0], [4000.0, 9000.0, 0, 0, 0], [9000.0, T1 + 1.0, 0, 0, 0]])


def _model():
    return ForceModel("earth", [EmpiricalRTN(BATCHES)], central_gm=GM)


def test_trajectory_state_is_the_full_interpolation_and_kepler():
    traj = propagate(X0, 0.0, T1, _model(), rtol=1e-13, atol=1e-12)
    assert len(traj.segments) == 3
    tq = np.r_[0.0, 4000.0, np.linspace(1.0, T1, 301), 9000.0, T1]   # step ends, inside steps, restarts
    state = traj.state(tq)
    assert state.shape == (tq.size, 6) and state.flags.c_contiguous
    assert np.array_equal(state, traj.variational(tq)[0])
    assert np.array_equal(traj.state(2500.0), traj.variational(2500.0)[0])   # a scalar epoch
    ref = np.array([kepler(X0, t) for t in tq])
    assert np.abs(state[:, :3] - ref[:, :3]).max() < 1e-3


def test_one_piece_trajectory_without_stm():
    traj = propagate(X0, 0.0, 5000.0, ForceModel("earth", central_gm=GM), with_stm=False, rtol=1e-13, atol=1e-12)
    tq = np.linspace(0.0, 5000.0, 77)
    ref = np.array([kepler(X0, t) for t in tq])
    assert np.abs(traj.state(tq)[:, :3] - ref[:, :3]).max() < 1e-3


def test_segment_state_both_sides_of_a_burn_and_shifted():
    a, b, dv = 4000.0, 9000.0, np.array([1.5, -0.5, 2.0])
    x_a = kepler(X0, a)
    seg = SegmentTrajectory(x_a, a, b, _model(), ["emp[1].T"], dv=dv, lookback=300.0, rtol=1e-13, atol=1e-12)
    tq = np.r_[a - 300.0, np.linspace(a - 299.0, b, 203), a, b]   # look-back, the burn epoch, the end
    assert np.array_equal(seg.state(tq), seg._full(tq)[0])
    before, after = tq[tq < a], tq[tq >= a]
    x_plus = x_a + np.r_[0.0, 0.0, 0.0, dv]
    assert np.abs(seg.state(before)[:, :3] - np.array([kepler(x_a, t - a) for t in before])[:, :3]).max() < 1e-3
    assert np.abs(seg.state(after)[:, :3] - np.array([kepler(x_plus, t - a) for t in after])[:, :3]).max() < 1e-3
    # a shifted segment's state carries the first-order shift (its STM and sensitivities)
    dx = np.r_[10.0, -5.0, 3.0, 0.01, 0.0, -0.02]
    shifted = ShiftedSegmentTrajectory(seg, x_a + dx, np.zeros(4))
    x, phi, _ = seg._full(tq)
    assert np.array_equal(shifted.state(tq), x + phi @ ((x_a + dx) - x_a))


def test_read_only_epochs_use_the_writable_signature():
    """Epochs from a read-only array (the measurement models' per-group memo) are interpolated as a writable
    copy: one compiled signature of ``dense``, not a second one compiled on a fresh checkout; same values."""
    from odpipe.dynamics.dop853 import dense

    traj = propagate(X0, 0.0, 3000.0, ForceModel("earth", central_gm=GM))
    tq = np.linspace(10.0, 2990.0, 7)
    frozen = tq.copy()
    frozen.flags.writeable = False
    assert np.array_equal(traj.state(frozen), traj.state(tq))
    assert all(sig[3].mutable for sig in dense.signatures), dense.signatures
