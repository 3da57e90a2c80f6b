"""Seeded Monte Carlo driver: serial by default, on a local Dask cluster when asked.

Each run gets its own ``numpy.random.Generator`` spawned from one
``SeedSequence(seed)``, so results are identical serial or parallel and do not
depend on scheduling. The error statistic of Turan et al. eq. 28 is
:func:`rms_over_runs`: RMSE_k = sqrt(mean over runs of (x - x_hat)^2) per epoch and component.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np


def run_generators(seed: int, n_runs: int) -> list[np.random.Generator]:
    """Independent generators of runs 0..n_runs-1 from one seed."""
    return [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(n_runs)]


def _one(trial, rng, index):
    return trial(rng, index)


def parallel_map(fn: Callable, *iterables, parallel: bool = False, n_workers: int | None = None) -> list:
    """[fn(*args) for args in zip(*iterables)], in order; on a ``dask.distributed.LocalCluster``
    (processes, ``n_workers`` default: the CPU count) when ``parallel`` (``fn`` picklable)."""
    if not parallel:
        return [fn(*args) for args in zip(*iterables)]
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:
        return client.gather(client.map(fn, *iterables, pure=False))


def monte_carlo(trial: Callable[[np.random.Generator, int], Any], n_runs: int, seed: int = 0,
                parallel: bool = False, n_workers: int | None = None) -> list:
    """[trial(rng_i, i) for i in range(n_runs)], in run order.

    ``parallel``: map the runs on a ``dask.distributed.LocalCluster`` (processes,
    ``n_workers`` default: the CPU count); ``trial`` must then be picklable.
    """
    return parallel_map(_one, [trial] * n_runs, run_generators(seed, n_runs), range(n_runs),
                        parallel=parallel, n_workers=n_workers)


def rms_over_runs(errors: np.ndarray) -> np.ndarray:
    """RMS over runs (axis 0) of errors (runs, epochs, components) -> (epochs, components)."""
    return np.sqrt(np.mean(np.square(errors), axis=0))


def rss(rms: np.ndarray, components=slice(0, 3)) -> np.ndarray:
    """3-D figure from per-component RMS (epochs, n): sqrt of the sum of squares of ``components``."""
    return np.sqrt(np.sum(np.square(rms[..., components]), axis=-1))
