"""odpipe overlap: RIC overlap precision between consecutive solutions given as OEM files."""

from __future__ import annotations

from pathlib import Path

from odpipe.commands._values import number
from odpipe.errors import Exit

NAME = "overlap"
HELP = "overlap precision (RIC, 3D RMS) between consecutive arcs' OEM solutions"


def add_arguments(p):
    p.add_argument("oem", nargs="+", type=Path, help="OEM files of consecutive arcs, in arc order (at least two)")
    p.add_argument("-o", "--out", type=Path, default=Path("overlap"), help="output folder")
    p.add_argument("--step", type=number(), default=600.0, help="comparison grid step (s)")


def _labels(paths) -> list[str]:
    """File stems, or the run's name when the stems repeat (run products are all ``trajectory.oem``)."""
    stems = [p.stem for p in paths]
    if len(set(stems)) == len(stems):
        return stems
    return [p.absolute().parent.parent.name if p.absolute().parent.name == "current" else p.absolute().parent.name
            for p in paths]


def run(args) -> int:
    from odpipe.analysis.overlap import compare, oem_trajectory, plot_overlaps, summarize
    from odpipe.numerics.precision import plus_minus
    from parsers.atomic import write_text

    if len(args.oem) < 2:
        raise ValueError(f"odpipe overlap needs at least two OEM files, got {len(args.oem)}")
    trajs = [oem_trajectory(p) for p in args.oem]
    names = _labels(args.oem)
    overlaps = [compare(a, b, f"{na} - {nb}", args.step)
                for (a, na), (b, nb) in zip(zip(trajs, names), zip(trajs[1:], names[1:]))]
    table = summarize(overlaps)
    args.out.mkdir(parents=True, exist_ok=True)
    write_text(args.out / "overlaps.csv", table.to_csv(index=False))
    plot_overlaps(table, args.out / "overlap_position.png", "pos")
    plot_overlaps(table, args.out / "overlap_velocity.png", "vel")
    mean, std = table.iloc[-2], table.iloc[-1]
    print(f"{len(overlaps)} overlaps; position 3D RMS {plus_minus(mean.pos_3d_rms, std.pos_3d_rms)} m, "
          f"velocity 3D RMS {plus_minus(mean.vel_3d_rms * 1e3, std.vel_3d_rms * 1e3)} mm/s")
    print(f"table and plots in {args.out}/")
    return Exit.OK
