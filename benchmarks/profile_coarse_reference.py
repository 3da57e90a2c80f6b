"""What the fit's coarse references cost and miss: one hour of GRAIL-B's lunar orbit at several tolerances.

    python benchmarks/profile_coarse_reference.py [trajectory.oem] [--hours 1]

Integrates, with the STM and the SRP-scale sensitivity, the nightly config's force model
(runs/grail_b_2012_04_10.toml: LP field to degree 150, partials to 8, Earth, Sun, SRP) from a
state of a fitted GRAIL-B trajectory (default: the 04-10 arc's OEM; run
``odpipe batch runs/grail_b_nightly.toml`` first), with the exact settings of the fit's
references (rtol 1e-12, atol 1e-6) and looser ones. Prints the force evaluations and CPU
seconds of each, and the position and velocity at the end against the exact settings'.
The fit's loose-weight stages fly ``odpipe.od.arc.COARSE_INTEGRATION``. Printed, never asserted.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from odpipe.analysis.overlap import oem_trajectory  # noqa: E402
from odpipe.dynamics.propagator import propagate  # noqa: E402
from odpipe.pipeline import setup as build  # noqa: E402
from odpipe.pipeline.config import load_config  # noqa: E402

SETTINGS = [(1e-12, 1e-6), (1e-10, 1e-6), (1e-9, 1e-5), (1e-8, 1e-4)]  # (rtol, atol m and m/s); first: exact


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("oem", nargs="?", type=Path,
                    default=ROOT / "runs" / "out" / "grail_b_2012_04_10" / "current" / "trajectory.oem")
    ap.add_argument("--hours", type=float, default=1.0)
    args = ap.parse_args(argv)
    if not args.oem.is_file():
        print(f"{args.oem}: not found (run `odpipe batch runs/grail_b_nightly.toml` first)")
        return 1
    fm = build.force_model(load_config(ROOT / "runs" / "grail_b_2012_04_10.toml"))
    traj = oem_trajectory(args.oem)
    t0 = traj.t0 + 600.0
    t1 = t0 + args.hours * 3600.0
    x0 = traj.state(np.array([t0]))[0]
    propagate(x0, t0, t0 + 60.0, fm, params=fm.parameter_names())   # kernels loaded before timing
    exact = None
    print(f"{args.hours:g} h from {args.oem.name}, degree-150 field, STM and {fm.parameter_names()}")
    for rtol, atol in SETTINGS:
        c = time.process_time()
        tr = propagate(x0, t0, t1, fm, params=fm.parameter_names(), rtol=rtol, atol=atol)
        cpu = time.process_time() - c
        x1 = tr.state(np.array([t1]))[0]
        exact = x1 if exact is None else exact
        print(f"rtol {rtol:g}, atol {atol:g}: {tr.n_eval} force evaluations, {cpu:.2f} s CPU; "
              f"|dr| {np.linalg.norm(x1[:3] - exact[:3]):.3g} m, |dv| {np.linalg.norm(x1[3:] - exact[3:]):.3g} m/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
