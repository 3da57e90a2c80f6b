"""odpipe overlap: RIC overlap precision between consecutive solutions given as OEM files."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from odpipe.analysis.overlap import PiecewiseTrajectory, SampledTrajectory, compare, plot_overlaps, summarize
from odpipe.products.atomic import write_text
from odpipe.time import utc_to_tdb
from parsers import oem

NAME = "overlap"
HELP = "overlap precision (RIC, 3D RMS) between consecutive arcs' OEM solutions"

_J2000 = np.datetime64("2000-01-01T12:00:00", "ns")


def add_arguments(p):
    p.add_argument("oem", nargs="+", type=Path, help="OEM files of consecutive arcs, in arc order")
    p.add_argument("-o", "--out", type=Path, default=Path("overlap"), help="output folder")
    p.add_argument("--step", type=float, default=600.0, help="comparison grid step (s)")


def trajectory_from_oem(path) -> PiecewiseTrajectory:
    """All segments of an OEM as one trajectory in TDB seconds past J2000 (m, m/s)."""
    pieces = []
    for seg in oem.read(path):
        scale = seg.meta.get("TIME_SYSTEM", "UTC")
        if scale == "TDB":
            t = (seg.epochs - _J2000) / np.timedelta64(1, "s")
        elif scale == "UTC":
            t = utc_to_tdb(seg.epochs)
        else:
            raise ValueError(f"{path}: TIME_SYSTEM {scale} not supported (TDB or UTC)")
        pieces.append(SampledTrajectory(t, seg.states))
    return PiecewiseTrajectory(pieces)


def _labels(paths) -> list[str]:
    """File stems, or the run's name when the stems repeat (run products are all ``trajectory.oem``)."""
    stems = [p.stem for p in paths]
    if len(set(stems)) == len(stems):
        return stems
    return [p.absolute().parent.parent.name if p.absolute().parent.name == "current" else p.absolute().parent.name
            for p in paths]


def run(args) -> int:
    if len(args.oem) < 2:
        raise SystemExit("odpipe overlap needs at least two OEM files")
    trajs = [trajectory_from_oem(p) for p in args.oem]
    names = _labels(args.oem)
    overlaps = [compare(a, b, f"{na} - {nb}", args.step)
                for (a, na), (b, nb) in zip(zip(trajs, names), zip(trajs[1:], names[1:]))]
    table = summarize(overlaps)
    args.out.mkdir(parents=True, exist_ok=True)
    write_text(args.out / "overlaps.csv", table.to_csv(index=False))
    plot_overlaps(table, args.out / "overlap_position.png", "pos")
    plot_overlaps(table, args.out / "overlap_velocity.png", "vel")
    mean, std = table.iloc[-2], table.iloc[-1]
    print(f"{len(overlaps)} overlaps; position 3D RMS {mean.pos_3d_rms:.3f} ± {std.pos_3d_rms:.3f} m, "
          f"velocity 3D RMS {mean.vel_3d_rms * 1e3:.4f} ± {std.vel_3d_rms * 1e3:.4f} mm/s")
    print(f"table and plots in {args.out}/")
    return 0
