"""``odpipe simulate``: generate a simulated tracking case (truth, tracking files, calibrations) from a case file."""

from __future__ import annotations

from pathlib import Path

from odpipe.errors import Exit

NAME = "simulate"
HELP = "simulate a tracking case (e.g. runs/artemis_p2_like.toml) into a directory"


def add_arguments(parser) -> None:
    parser.add_argument("case", type=Path, help="case description (TOML, schema in odpipe/simulate/case.py)")
    parser.add_argument("-o", "--output", type=Path, required=True, help="output directory")
    parser.add_argument("--days", type=float, help="simulate only the first DAYS of the case")


def check_case(path: Path) -> None:
    """ConfigError naming the case file and key when :func:`odpipe.simulate.case.load` cannot read it."""
    import tomllib

    from odpipe.operations.schema import ConfigError
    from odpipe.simulate.case import load

    try:
        load(path)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(path, "", f"not valid TOML: {exc}") from None
    except KeyError as exc:
        raise ConfigError(path, str(exc.args[0]), "required key is missing") from None
    except TypeError as exc:  # a [[network]] key Network does not have
        raise ConfigError(path, "network", str(exc).replace("Network.__init__() ", "")) from None


def run(args) -> int:
    from odpipe.simulate import run_case

    if args.days is not None and not args.days > 0:
        raise ValueError(f"--days {args.days}: must be positive")
    check_case(args.case)
    paths, truth, obs = run_case(args.case, args.output, days=args.days)
    t = obs.table
    print(f"{len(t)} observables in {t['pass_id'].nunique()} passes, {len(truth.epochs)} maneuvers; files:")
    for role, p in paths.items():
        print(f"  {role}: {p}")
    return Exit.OK
