"""Overlap statistics on synthetic trajectories whose differences are known in closed form."""

import numpy as np
import pandas as pd
import pytest

from odpipe.analysis.overlap import (PiecewiseTrajectory, SampledTrajectory, compare, long_arc_schedule,
                                     plot_overlaps, short_arc_schedule, summarize)
from odpipe.frames.local import rtn_matrix

GM = 3.986004418e14
RADIUS = 384e6  # a Moon-distance circular orbit, as for a libration-orbit spacecraft's scale
N = np.sqrt(GM / RADIUS**3)


def circular(t):
    u = N * t
    return np.stack([RADIUS * np.cos(u), RADIUS * np.sin(u), 0 * u,
                     -RADIUS * N * np.sin(u), RADIUS * N * np.cos(u), 0 * u], axis=1)


class Analytic:
    """A closed-form trajectory plus a difference given in RIC as a function of time."""

    def __init__(self, t0, t1, dr_ric=lambda t: np.zeros((t.size, 3)), dv_ric=lambda t: np.zeros((t.size, 3))):
        self.t0, self.t1, self.dr, self.dv = t0, t1, dr_ric, dv_ric

    def state(self, t):
        t = np.atleast_1d(t)
        x = circular(t)
        rot = rtn_matrix(x[:, :3], x[:, 3:])
        return x + np.hstack([np.einsum("nji,nj->ni", rot, self.dr(t)), np.einsum("nji,nj->ni", rot, self.dv(t))])


def test_constant_ric_offset_recovered_exactly():
    a = Analytic(0.0, 5 * 86400.0)
    b = Analytic(2 * 86400.0, 9 * 86400.0, lambda t: np.tile([10.0, -20.0, 30.0], (t.size, 1)),
                 lambda t: np.tile([1e-4, -2e-4, 3e-4], (t.size, 1)))
    ov = compare(a, b, "a-b", step=600.0)
    assert ov.t_tdb[0] == 2 * 86400.0 and ov.t_tdb[-1] == 5 * 86400.0
    s = ov.statistics()
    # A - B = -offset: RMS per component is |offset|, 3D RMS is its norm.
    assert s["pos_radial_rms"] == pytest.approx(10.0, abs=1e-6)
    assert s["pos_intrack_rms"] == pytest.approx(20.0, abs=1e-6)
    assert s["pos_crosstrack_rms"] == pytest.approx(30.0, abs=1e-6)
    assert s["pos_3d_rms"] == pytest.approx(np.sqrt(1400.0), abs=1e-6)
    assert s["vel_crosstrack_rms"] == pytest.approx(3e-4, abs=1e-12)
    assert np.allclose(ov.dr_ric, [-10.0, 20.0, -30.0], atol=1e-6)


def test_sinusoidal_intrack_difference_has_rms_amplitude_over_root_two():
    period = 6 * 3600.0
    a = Analytic(0.0, 86400.0)
    b = Analytic(0.0, 86400.0, lambda t: np.stack([0 * t, 50.0 * np.sin(2 * np.pi * t / period), 0 * t], 1))
    s = compare(a, b, step=60.0).statistics()
    assert s["pos_intrack_rms"] == pytest.approx(50.0 / np.sqrt(2), rel=2e-3)
    assert s["pos_radial_rms"] < 1e-6
    assert s["pos_3d_max"] == pytest.approx(50.0, rel=1e-6)


def test_summary_mean_and_std_over_overlaps(tmp_path):
    a = Analytic(0.0, 86400.0)
    overlaps = [compare(a, Analytic(0.0, 86400.0, lambda t, k=k: np.tile([0, 0, 10.0 * k], (t.size, 1))), f"o{k}")
                for k in (1, 2, 3)]
    table = summarize(overlaps)
    mean, std = table.set_index("overlap").loc[["mean", "std"], "pos_crosstrack_rms"]
    assert mean == pytest.approx(20.0, abs=1e-6) and std == pytest.approx(10.0, abs=1e-6)
    plot_overlaps(table, tmp_path / "pos.png", "pos")
    assert (tmp_path / "pos.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("n", [1, 3, 9])
def test_overlap_plot_keeps_long_arc_names_inside_the_figure(monkeypatch, n):
    """The GRAIL night's names ('grail_b_2012_04_08 - grail_b_2012_04_09', 30° slanted) ran off the
    figure's left and bottom edges, the x label with them: every text's box lies inside the figure, and
    the legend on no bar."""
    import parsers.atomic

    saved = []
    monkeypatch.setattr(parsers.atomic, "save_figure", lambda path, fig, **kw: saved.append(fig))
    names = [f"grail_b_2012_04_{k:02d} - grail_b_2012_04_{k + 1:02d}" for k in range(8, 8 + n)]
    cols = [f"{q}_{c}_rms" for q in ("pos", "vel") for c in ("radial", "intrack", "crosstrack", "3d")]
    plot_overlaps(pd.DataFrame({"overlap": names, **{c: np.linspace(1.0, 500.0, n) for c in cols}}), "x.png", "pos")
    fig = saved[0]
    fig.canvas.draw()
    ax = fig.axes[0]
    texts = ax.get_xticklabels() + [ax.xaxis.label, ax.yaxis.label, ax.title]
    assert [t.get_text() for t in ax.get_xticklabels()] == names
    for t in texts:
        box = t.get_window_extent()
        assert box.x0 >= 0 and box.y0 >= 0 and box.x1 <= fig.bbox.x1 and box.y1 <= fig.bbox.y1, (t.get_text(), box)
    legend = ax.get_legend().get_window_extent()   # it hid the top of the tallest bars
    assert not any(legend.overlaps(bar.get_window_extent()) for bar in ax.patches)


def test_arcs_that_do_not_overlap_are_refused():
    with pytest.raises(ValueError, match="do not overlap"):
        compare(Analytic(0.0, 10.0), Analytic(20.0, 30.0), "gap")


def test_sampled_trajectory_interpolates_between_nodes():
    t = np.arange(0.0, 86400.0 + 1, 60.0)
    traj = SampledTrajectory(t, circular(t))
    tm = t[:-1] + 23.0
    err = traj.state(tm) - circular(tm)
    assert np.max(np.linalg.norm(err[:, :3], axis=1)) < 1e-3
    assert np.max(np.linalg.norm(err[:, 3:], axis=1)) < 1e-6
    with pytest.raises(ValueError, match="outside"):
        traj.state(t[-1] + 10.0)


def test_arc_schedules_follow_the_artemis_strategy():
    day = 86400.0
    m = np.array([0.0, 7.0, 14.0, 21.0]) * day
    short = short_arc_schedule(m, arc_days=5.0, margin_s=0.0)
    assert short[0] == ((0.0, 5 * day), (2 * day, 7 * day))  # a 3-day overlap, as seed 004 §4.5
    long = long_arc_schedule(m, margin_s=0.0)
    assert long == [((0.0, 14 * day), (7 * day, 21 * day))]  # a 7-day overlap spanning one maneuver each


def test_overlap_command_on_oem_products(tmp_path):
    from odpipe.cli import main
    from odpipe.products.segments import EphemerisSegment
    from odpipe.products.oem import write_oem

    day = 86400.0
    paths = []
    for k, (t0, shift) in enumerate([(0.0, 0.0), (day, 5.0), (2 * day, -5.0)]):
        t = np.arange(t0, t0 + 2 * day + 1, 60.0)
        x = circular(t)
        x[:, 2] += shift  # out of plane: a pure cross-track difference
        paths.append(write_oem(tmp_path / f"arc{k}.oem", [EphemerisSegment(t, x, "earth")], "SC", "1",
                               time_system="UTC" if k == 1 else "TDB"))
    # Arc 1 is written in UTC: its epochs must come back to the same TDB instants.
    assert main(["overlap", *map(str, paths), "-o", str(tmp_path / "ov")]) == 0
    import pandas as pd
    table = pd.read_csv(tmp_path / "ov" / "overlaps.csv")
    assert table["pos_crosstrack_rms"].iloc[:2].tolist() == pytest.approx([5.0, 10.0], abs=1e-3)
    assert (tmp_path / "ov" / "overlap_velocity.png").exists()


def test_piecewise_trajectory_switches_at_the_maneuver():
    from odpipe.analysis.overlap import PiecewiseTrajectory

    t1 = np.arange(0.0, 3601.0, 60.0)
    t2 = np.arange(3600.0, 7201.0, 60.0)
    x2 = circular(t2)
    x2[:, 3] += 0.01  # a 1 cm/s burn at 3600 s
    traj = PiecewiseTrajectory([SampledTrajectory(t2, x2), SampledTrajectory(t1, circular(t1))])
    assert (traj.t0, traj.t1) == (0.0, 7200.0)
    assert traj.state(3600.0)[0, 3] == pytest.approx(circular(np.array([3600.0]))[0, 3] + 0.01)
    assert traj.state(3599.0)[0, 3] == pytest.approx(circular(np.array([3599.0]))[0, 3], abs=1e-9)


def test_oem_trajectory_keeps_its_centre_for_the_measurement_models(tmp_path):
    """An OEM about the Moon read back is a Moon-centred trajectory (the measurement models add the Moon's
    barycentric state); without the centre a GRAIL product was evaluated as if about the SSB."""
    from odpipe.analysis.overlap import oem_trajectory
    from odpipe.measurements.nodes import SpacecraftNode
    from odpipe.products.segments import EphemerisSegment
    from odpipe.products.oem import write_oem
    from odpipe.environment.ephemeris import Ephemeris

    t = np.arange(3.87e8, 3.87e8 + 7201.0, 60.0)
    x = circular(t - t[0]) * 0.3
    path = write_oem(tmp_path / "moon.oem", [EphemerisSegment(t, x, "moon")], "SC", "1", time_system="TDB")
    traj = oem_trajectory(path)
    assert traj.center == "moon"
    eph = Ephemeris.open("de421")
    node = SpacecraftNode(traj, eph, "ssb")
    np.testing.assert_allclose(node.state(t[:3]), x[:3] + eph.state("moon", "ssb", t[:3]), rtol=0, atol=1e-6)
    with pytest.raises(ValueError, match="different centres"):
        PiecewiseTrajectory([SampledTrajectory(t, x, "moon"), SampledTrajectory(t + 7200.0, x, "earth")])
