"""``odpipe apriori``: a run's a priori orbit from its own two-way Doppler, printed as ``[initial_state]``."""

from __future__ import annotations

from dataclasses import fields, replace
from pathlib import Path

import numpy as np

NAME = "apriori"
HELP = "find a lunar orbiter's a priori orbit from the run's two-way Doppler; prints the [initial_state] entries"


def add_arguments(parser) -> None:
    parser.add_argument("config", type=Path, help="run configuration (TOML): its data, arc, centre and field are used")
    parser.add_argument("--station", help="receiving station of the Doppler used, e.g. DSS-24 (default: the config's "
                                          "[initial_state.from_doppler], else the one with the most 60-s points in "
                                          "the arc's first 8 h)")
    parser.add_argument("--span", type=float, help="hours of that station's Doppler used (default: the config's, else 5.5)")
    parser.add_argument("--degree", type=int, help="degree of the central body's field (default: the config's, else 12)")


def run(args) -> int:
    from odpipe.pipeline.apriori import doppler_apriori, initial_state_toml
    from odpipe.pipeline.config import DopplerAprioriSection, load_config

    cfg = load_config(args.config)
    how = cfg.initial_state.from_doppler or DopplerAprioriSection()
    given = {k: (option, v) for k, option, v in (("station", "--station", args.station),
                                                 ("span_hours", "--span", args.span),
                                                 ("degree", "--degree", args.degree)) if v is not None}
    for f in fields(how):   # the configuration's own checks of [initial_state.from_doppler]
        if f.name in given and "check" in f.metadata:
            for _, reason in f.metadata["check"](given[f.name][1]):
                raise ValueError(f"{given[f.name][0]}: {reason}")
    how = replace(how, **{k: v for k, (_, v) in given.items()})
    res, rows = doppler_apriori(cfg, how)
    el = res.elements
    print(f"# {len(rows)} 60-s two-way Doppler points of {rows['station_rx'].iloc[0]}, "
          f"{rows['epoch'].min():%Y-%m-%dT%H:%M:%S} .. {rows['epoch'].max():%Y-%m-%dT%H:%M:%S} UTC; "
          f"post-fit {res.rms_los * 1e3:.0f} mm/s ({res.rms_hz * 1e3:.0f} mHz)")
    print(f"# altitude {el['altitude'] / 1e3:.1f} km, period {el['period'] / 60:.2f} min, e {el['e']:.4f}, "
          f"inclination {np.degrees(el['inc']):.2f} deg, node {np.degrees(el['raan']):.2f} deg (body frame)")
    print(initial_state_toml(res), end="")
    return 0
