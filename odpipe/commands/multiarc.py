"""odpipe multiarc: arcs that were each run already, refitted as one solution sharing force-model parameters
(:mod:`odpipe.od.multiarc`): the shared values combined from every arc, then each arc refitted with them fixed."""

from pathlib import Path

from odpipe.errors import Exit

NAME = "multiarc"
HELP = ("refit arcs already run (odpipe run or batch) as one multi-arc solution sharing force-model "
        "parameters (srp_scale, cd, poly[k].*): [multiarc] name, arcs, shared, output, rounds")


def add_arguments(p):
    p.add_argument("config", type=Path, help="multi-arc config: [multiarc] name = ..., arcs = [run configs, "
                                             "relative to this file], shared = [\"srp_scale\"], output = folder")


def run(args) -> int:
    from odpipe.pipeline.multiarc import run_multiarc

    result = run_multiarc(args.config)
    print(result["shared"].to_string(index=False))
    print(f"products in {result['folder']}/ (shared.csv, one folder per arc)")
    return Exit.OK if all(result["converged"]) else Exit.FIT
