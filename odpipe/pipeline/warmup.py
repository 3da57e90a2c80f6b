"""Ahead-of-time numba compilation: ``python -m odpipe.pipeline.warmup`` (``make`` runs it at install).

Every numba kernel is cached on disk (``cache=True``), but a fresh checkout's cache is
empty, and the first demo would wait for the compiler. This runs the demo on the first
``DAYS`` days of its case in a temporary folder, with one worker: the same simulation,
readers, force models, fits, products and report on less data, so every kernel signature
the demo uses is compiled once into the checkout's cache. Then it compiles the signatures
the demo does not reach (:func:`other_kernels`: fixed-step RK4, the CRTBP right-hand side
called directly, NRLMSISE-00 called directly), which studies and the tests use. It prints
the demo's own compile line (functions and seconds, main process and worker), the other
kernels' and the warm-up's wall time.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

DAYS = 11.0  # two station-keeping maneuvers (days 3.5 and 10.5) and an attitude burn: short and long arcs
GM_EARTH = 3.986004415e14  # m^3/s^2


def other_kernels() -> None:
    """One call of each kernel signature outside the demo: RK4 through the compiled force model
    (one type for every model), ``crtbp_rhs`` on writable arrays (``studies.crtbp_orbits``),
    ``gtd7`` on writable arrays (drag and direct calls differ in array mutability), the a priori
    orbit search's grid kernels (``od.apriori.circular_search``, about 6 s to compile) and the flyby
    search's (``od.flyby_apriori.radial_los``, 1.5 s)."""
    from odpipe.dynamics.crtbp import crtbp_rhs
    from odpipe.dynamics.forces import ForceModel
    from odpipe.dynamics.propagator import propagate
    from odpipe.environment.atmosphere.nrlmsise00 import gtd7
    from odpipe.od.apriori import LineOfSight, circular_search
    from odpipe.od.flyby_apriori import radial_los

    x0 = np.array([7.0e6, 0.0, 0.0, 0.0, 7.5e3, 0.0])
    propagate(x0, 0.0, 120.0, ForceModel("earth", central_gm=GM_EARTH), with_stm=True, method="rk4", max_step=60.0)
    crtbp_rhs(0.0, np.array([0.82, 0.0, 0.1, 0.0, 0.2, 0.0]), np.array([0.0121]), np.empty(6))
    gtd7(172, 29000.0, 400.0, 60.0, -70.0, 16.0, 150.0, 150.0, 4.0)
    tau = np.linspace(0.0, 3600.0, 12)
    u = np.tile([0.6, 0.0, 0.8], (tau.size, 1))
    circular_search(tau, np.sin(tau / 1000.0), u, 4.9e12, [6800.0], np.radians([0.0, 90.0]), np.radians([85.0, 90.0]),
                    keep=2)
    radial_los(LineOfSight(tau, tau + 60.0, 1e11 + u, 1e11 + u, tau), 1e5, 3.2e14, u[:2], 9e3)


def warm_worker(configs: list) -> None:
    """What a batch worker's first arc would otherwise pay before its fit (``run_batch(..., warm=)``): the
    run's imports, matplotlib's, and for each distinct force model of ``configs`` (run configuration files)
    its gravity files (kept per process, :func:`odpipe.environment.gravity.read_gravity`) and a minute of
    its dynamics with the STM and an RTN batch as a fit segment flies it (loading those kernels from
    numba's cache). A configuration that does not load is passed over: its arc reports that."""
    from dataclasses import replace

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401  (the products' residual plots)

    from odpipe.dynamics.forces import BODY_RADIUS, EmpiricalRTN
    from odpipe.dynamics.propagator import propagate
    from odpipe.pipeline import run  # noqa: F401  (every stage's imports)
    from odpipe.pipeline.config import load_config
    from odpipe.pipeline.setup import force_model, tdb

    seen = set()
    for path in configs:
        try:
            cfg = load_config(path)
        except (ValueError, OSError):
            continue
        key = repr(cfg.dynamics)
        if key in seen:
            continue
        seen.add(key)
        fm = force_model(cfg)
        t0 = tdb(cfg.arc.start)
        r = 3.0 * BODY_RADIUS.get(fm.center, 6.4e6)
        fm = replace(fm, components=list(fm.components) + [EmpiricalRTN(np.array([[t0 - 1.0, t0 + 61.0, 0, 0, 0]]))])
        propagate(np.array([r, 0.0, 0.0, 0.0, 1.0e3, 0.0]), t0, t0 + 60.0, fm).state(t0 + 30.0)


def warm_up(days: float = DAYS) -> str:
    """Run the shortened demo in a temporary folder, then :func:`other_kernels`; one line on what was compiled."""
    from odpipe.dynamics.compile_timer import compile_timer
    from odpipe.pipeline.demo import run_demo

    t0 = time.perf_counter()
    lines: list[str] = []
    with tempfile.TemporaryDirectory(prefix="odpipe-warmup-") as tmp:
        run_demo(Path(tmp) / "demo", workers=1, progress=lines.append, days=days)
    note = next((line for line in lines if line.startswith("numba:")), "numba: no compile report")
    with compile_timer() as ct:
        other_kernels()
    return (f"warm-up on {days:g} days of the demo case, {time.perf_counter() - t0:.1f} s: {note}; "
            f"kernels outside the demo: {ct.functions} functions in {ct.seconds:.1f} s")


if __name__ == "__main__":
    print(warm_up())
    sys.exit(0)
