"""Estimation-core speed: SRIF + SRIS linear algebra per fit iteration.

Two cases on the exactly linear test problem (so dynamics/measurement cost is
tiny and is measured and subtracted):
  A. 7-day arc, 12,096 scalar measurements, 12 parameters (state, 3 Gauss-Markov
     accelerations in 8-h batches, 3 biases), 10-min grid;
  B. 14-day arc, 8,064 measurements, 40 parameters (state, SRP scale, 3 Gauss-Markov
     accelerations in 8-h batches, 2 maneuvers, 24 per-pass biases), 10-min grid.
Also the two-body test problem (1 day, RK4 dynamics included) for reference.
Run: .venv/bin/python benchmarks/bench_estimation.py
Small matrices: on a busy machine OpenBLAS threading can cost 10x; compare with
OPENBLAS_NUM_THREADS=1.
"""

import sys
import time
from pathlib import Path

import numpy as np

from odpipe.estimation.fit import FitOptions, Observations, fit
from odpipe.estimation.registry import ParameterRegistry

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from estimation_cases import LinearProblem, twobody_case  # noqa: E402  (the test problems live with the tests)

DAY = 86400.0


class Timed:
    """Wraps a Problem, accumulating the time spent in the model callbacks."""

    def __init__(self, problem):
        self.p, self.registry, self.seconds = problem, problem.registry, 0.0

    def transition(self, *a):
        t = time.perf_counter()
        out = self.p.transition(*a)
        self.seconds += time.perf_counter() - t
        return out

    def predict(self, *a):
        t = time.perf_counter()
        out = self.p.predict(*a)
        self.seconds += time.perf_counter() - t
        return out


def linear_case(days, m, n_bias, n_man, srp, rng):
    reg = ParameterRegistry()
    reg.add_state("sc", np.zeros(6), 1e5, 1.0)
    if srp:
        reg.add("sc.srp", "dynamic", 1.0, 0.1, owner="sc")
    reg.add_stochastic_acceleration("sc", 5e-9, DAY, 8 * 3600.0)
    for j in range(n_man):
        reg.add_maneuver("sc", f"m{j}", (j + 1) * days * DAY / (n_man + 1))
    for j in range(n_bias):
        reg.add(f"bias.{j}", "bias", 0.0, 5.0, owner=f"pass{j}")
    n = len(reg)
    A = np.zeros((n, n))
    A[0:3, 3:6] = np.eye(3)
    A[3:6, reg.slice("stochastic")] = np.eye(3)
    if srp:
        A[3:6, reg.index("sc.srp")] = 1e-8
    t = np.sort(rng.uniform(0, days * DAY, m))
    H = np.zeros((m, n))
    H[:, :6] = rng.normal(size=(m, 6))
    if n_bias:
        H[np.arange(m), n - n_bias + (np.arange(m) * n_bias // m)] = 1.0
    prob = LinearProblem(reg, A, H, t)
    x_true = reg.apriori + rng.normal(size=n) * reg.sigma * 0.1
    y = H @ x_true + rng.normal(size=m)
    return Timed(prob), Observations(t, y, np.ones(m), np.zeros(m, int)), days * DAY


def run(label, prob, obs, arc, iters=2, block=600.0):
    prob.seconds = 0.0
    t, c = time.perf_counter(), time.process_time()
    sol = fit(prob, obs, 0.0, arc, FitOptions(block=block, max_iter=iters))
    total, cpu = time.perf_counter() - t, time.process_time() - c
    k = len(sol.history)
    print(f"{label}: n={len(prob.registry)} m={obs.time.size} grid={sol.grid.size} "
          f"iterations={k} total {total:.3f} s (CPU {cpu:.3f} s), models {prob.seconds:.3f} s, "
          f"filter+smoother linear algebra {(total - prob.seconds) / k:.3f} s/iteration "
          f"(covariances for the Solution included)")


def main():
    rng = np.random.default_rng(0)
    run("A 7-day 12k meas", *linear_case(7, 12096, 3, 0, False, rng))
    case_b = linear_case(14, 8064, 24, 2, True, rng)
    run("B 14-day 8k meas", *case_b)
    run("B same, 30-min grid", *case_b, block=1800.0)
    p, o, _ = twobody_case(np.random.default_rng(1))
    run("two-body 1-day (RK4 models)", Timed(p), o, DAY, iters=10)


if __name__ == "__main__":
    main()
