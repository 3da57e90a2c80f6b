"""Iterated SRIF + SRIS over an arc, relinearized about the smoothed solution.

The fit talks to the models only through the :class:`Problem` protocol, in
registry coordinates (the full parameter vector, state and parameters alike):

* ``transition(t0, t1, x0) -> (x1, Phi)``: reference propagation over a grid
  interval with every parameter (stochastic ones too) held constant, and
  ``Phi = dx1/dx0`` (n x n, invertible). An impulsive maneuver at a grid epoch
  ``t0`` is applied at the start of the interval.
* ``predict(t0, x0, rows) -> (computed, H)``: computed values of observation
  rows (all with ``t0 <= t < t1``) and their partials w.r.t. the vector at ``t0``.
* optionally ``span(epochs, x0, bounds) -> (refs, Phi, computed, H)``: ``predict`` and ``transition``
  over the grid intervals from ``epochs[0]`` (reference ``x0``) for as many intervals as the
  reference holds (J >= 1: references at J + 1 epochs, J transitions, the rows
  ``bounds[0]:bounds[J]``), answered at once instead of interval by interval;
* optionally ``set_coarse(on)``: the fit turns it on for the passes of its loose-weight
  stages (all but the last ``sigma_scale``) and for the first pass of the last stage (whose
  edits the next, exact pass decides again), whose references need not be exact (they only bring the reference near
  the solution), and off for the other passes of the last stage and once the iterations
  end; a fit never ends converged on a coarse pass.

Each pass first flies the reference over the grid (the problem's answers do not depend on the
filter), then filters each stretch between stochastic steps in one compiled loop
(:meth:`.srif.SRIF.intervals`).

The grid holds the arc ends, a regular spacing (``block`` s), the batch
boundaries of every stochastic parameter and any extra epochs (maneuvers). At a
batch boundary the SRIF applies ``p+ = m p + w``; the measurements of each grid
interval are absorbed in one Householder update, after an innovation k-sigma
test against the filter's prediction; with ``edit_against_reference`` a row is
edited only when it also misses the reference (the last smoothed solution) by k
of its sigma, so a row only the forward filter finds surprising (a burn's a
priori overruled by the data) is kept and the filter is not locked out of the
rows after it.

Each iteration is one filter pass and one smoother pass about a reference; the
next reference starts from the smoothed epoch vector and takes the smoothed
stochastic values after each batch boundary. The fit stops when every epoch
correction is below ``tol_dx`` of its sigma and the post-fit RMS is stable.

A row whose value or sigma is not finite, whose sigma is not positive, or whose
computed value or partials are not finite is flagged ``NONFINITE`` and not used;
a fit left with no usable row, or whose data carry no information about any
estimated parameter (every row deweighted), raises :class:`NothingToFit`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import pandas as pd

from .registry import ParameterRegistry
from .smoother import smooth_arrays
from .solution import Solution, checksum
from .srif import SRIF, information_estimates, solve_information, solve_informations

_log = logging.getLogger(__name__)

EDIT_INNOVATION = 1  # row rejected by the innovation (pre-fit) k-sigma test
OUTSIDE_ARC = 2      # row time outside [t_start, t_end]
NONFINITE = 4        # value, sigma, computed value or partials not finite, or sigma <= 0
NO_INFORMATION = 1e-9  # relative variance reduction below which an estimated parameter learned nothing


class Problem(Protocol):
    registry: ParameterRegistry

    def transition(self, t0: float, t1: float, x0: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...

    def predict(self, t0: float, x0: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...


@dataclass(frozen=True)
class Observations:
    """Observation rows in time order: TDB s, value and sigma (SI), weighting group label."""

    time: np.ndarray
    value: np.ndarray
    sigma: np.ndarray
    group: np.ndarray

    def __post_init__(self):
        if np.any(np.diff(self.time) < 0):
            raise ValueError("observations must be time ordered")


@dataclass(frozen=True)
class FitOptions:
    """max_iter; block: regular grid spacing (s); edit_k: innovation-test k-sigma per
    iteration (last value repeats; inf = off), applied only once the previous post-fit
    RMS (whitened) is below edit_gate_rms, so that a far-off first reference does not
    reject good data; reweight: scale each group's sigma by its post-fit RMS (last stage).

    sigma_scale: data-weight stages multiplying every sigma, loose to tight (e.g. (30, 5, 1)):
    a far-off reference is first fitted with loose weights; the next stage starts once the
    epoch correction is below stage_tol sigma, inside the tight fit's linear regime, and its
    first pass edits as the schedule says (gated by edit_gate_rms in the new stage's units).
    max_halvings: when the models cannot be evaluated about a
    corrected reference (an orbit driven into the central body), the correction is halved
    up to this many times before FitDiverged, which is also raised when the iterations end
    unconverged with the post-fit RMS above diverged_rms sigma and above its best iteration's.

    tol_dx: converged (at the last stage) when every epoch correction < tol_dx sigma and
    the post-fit RMS changed by < tol_rms (relative; in sigma below an RMS of 1, where noise
    absorbed by process noise leaves changes of 1e-4 sigma that mean nothing); extra_epochs: more grid epochs (TDB s);
    output_at_measurements: put every observation time on the grid, so filtered and
    smoothed estimates exist at each measurement time. edit_against_reference: edit a row
    only when it misses the reference (the last smoothed solution) by edit_k of its sigma as
    well as the filter's prediction (arcs across burns with unmodelled accelerations after
    them); off, the innovation test alone edits (GRAIL-B's first arc, kilometres off at the
    start: with both tests its edits swung between iterations and it did not converge)."""

    max_iter: int = 10
    block: float = 600.0
    edit_k: tuple = (np.inf, 10.0, 5.0)
    edit_gate_rms: float = 3.0
    reweight: bool = False
    sigma_scale: tuple = (1.0,)
    stage_tol: float = 1.0
    max_halvings: int = 6
    diverged_rms: float = 100.0
    tol_dx: float = 1e-2
    tol_rms: float = 1e-3
    extra_epochs: tuple = ()
    output_at_measurements: bool = False
    edit_against_reference: bool = False


def build_grid(registry, t_start, t_end, block, extra=()) -> tuple[np.ndarray, dict]:
    """Grid epochs and, per grid index, the stochastic groups that step there."""
    pts = [np.arange(t_start, t_end, block), [t_start, t_end],
           [e for e in extra if t_start < e < t_end],
           [p.epoch for p in registry.parameters
            if p.epoch is not None and t_start < p.epoch < t_end]]
    groups = registry.stochastic_groups()
    for _, proc in groups:
        pts.append(np.arange(t_start + proc.batch, t_end, proc.batch))
    grid = np.unique(np.concatenate([np.asarray(p, float) for p in pts]))
    steps: dict = {}
    for idx, proc in groups:
        for e in np.arange(t_start + proc.batch, t_end, proc.batch):
            k = int(np.searchsorted(grid, e))
            steps.setdefault(k, []).append((idx, proc.step()))
    return grid, steps


def _edit_k(options, it, prev_rms):
    if prev_rms is not None and prev_rms > options.edit_gate_rms:
        return np.inf
    return options.edit_k[min(it, len(options.edit_k) - 1)]


class FitDiverged(RuntimeError):
    """The iterations drove the reference where the models cannot be evaluated."""


class NothingToFit(FitDiverged):
    """No usable row is left (all outside the arc, not finite or edited), or the rows carry no information."""


def _nothing_left(flags: np.ndarray, it: int) -> str:
    """Why no row is used, counted by reason (``flags`` of one pass)."""
    n = flags.size
    parts = [f"{np.count_nonzero(flags & bit)} {what}" for bit, what in
             ((OUTSIDE_ARC, "outside the arc"), (NONFINITE, "with a non-finite value, sigma or computed value "
                                                 "or a sigma <= 0"), (EDIT_INNOVATION, "edited by the innovation test"))
             if np.any(flags & bit)]
    return f"iteration {it + 1}: nothing left to fit: of {n} rows, " + (", ".join(parts) or "none given")


@dataclass
class _Pass:
    """One filter-smoother pass about a reference."""

    srif: SRIF          # the filter after the last grid epoch (n_est, consider a priori)
    refs: list          # reference vector at each grid epoch (after any stochastic step)
    filtered: list      # filter information arrays (R, z) at each grid epoch
    smoothed: dict      # smoother information arrays (R, z) by grid index
    rows: slice         # the rows inside the arc
    k_row: np.ndarray   # grid index of each of those rows' interval
    H: np.ndarray       # their partials w.r.t. the vector at that grid epoch
    y: np.ndarray       # their pre-fit residuals
    flags: np.ndarray
    prefit: np.ndarray
    innovation: np.ndarray
    innovation_sigma: np.ndarray


def _unusable(obs: Observations) -> np.ndarray:
    """Rows that cannot be weighted: value or sigma not finite, or sigma not positive."""
    return ~np.isfinite(obs.value) | ~np.isfinite(obs.sigma) | ~(obs.sigma > 0)


@dataclass
class _Sweep:
    """The reference through the grid and the problem's answers along it (independent of the filter)."""

    refs: list          # reference vector at each grid epoch (after any stochastic step), K + 1
    Phi: np.ndarray     # (K, n, n) transition of each interval
    computed: np.ndarray  # computed values of the rows bounds[0]:bounds[-1]
    H: np.ndarray       # their partials w.r.t. the vector at their interval's start
    noise: dict         # grid index -> [(idx, m, q, offset)] process-noise steps there


def _sweep(problem, grid, steps, bounds, x_ref0, p_after) -> _Sweep:
    """Fly the reference over the grid: the stochastic steps (their reference values from ``p_after``, else
    ``m p``), each interval's rows (``problem.predict``) and transition. A problem with ``span`` answers the
    intervals up to where its reference changes at once."""
    K, n = grid.size - 1, x_ref0.size
    lo0 = bounds[0]
    Phi = np.empty((K, n, n))
    computed, H = np.full(bounds[-1] - lo0, np.nan), np.zeros((bounds[-1] - lo0, n))
    refs, noise = [], {}
    span = getattr(problem, "span", None)
    xr = x_ref0.copy()
    k = 0
    while k < K:
        for j, (idx, (m, q)) in enumerate(steps.get(k, ())):
            new = p_after.get((k, j), m * xr[idx])
            noise.setdefault(k, []).append((idx, m, q, m * xr[idx] - new))
            xr = xr.copy()
            xr[idx] = new
        lo, hi = bounds[k] - lo0, bounds[k + 1] - lo0
        if span is not None:
            end = next((e for e in sorted(steps) if e > k), K)
            xs, Phi_k, c, H_k = span(grid[k:end + 1], xr, bounds[k:end + 1])
            j = Phi_k.shape[0]
            if j == 0:   # the sweep would never advance
                raise RuntimeError(f"the problem's span answered no grid interval from {grid[k]:.3f} s TDB")
            refs.extend(xs[:-1])
            Phi[k:k + j] = Phi_k
            hi = bounds[k + j] - lo0
            computed[lo:hi], H[lo:hi] = c, H_k
            xr, k = xs[-1], k + j
            continue
        refs.append(xr)
        if hi > lo:
            computed[lo:hi], H[lo:hi] = problem.predict(grid[k], xr, np.arange(lo + lo0, hi + lo0))
        xr, Phi[k] = problem.transition(grid[k], grid[k + 1], xr)
        k += 1
    refs.append(xr)
    return _Sweep(refs, Phi, computed, H, noise)


def _filter_smoother_pass(problem, obs, grid, steps, bounds, x_ref0, p_after, sig_row, edit_k,
                          against_reference=False):
    reg = problem.registry
    m_obs = obs.time.size
    flags = np.zeros(m_obs, int)
    flags[: bounds[0]] |= OUTSIDE_ARC
    flags[bounds[-1]:] |= OUTSIDE_ARC
    sw = _sweep(problem, grid, steps, bounds, x_ref0, p_after)
    rows = slice(bounds[0], bounds[-1])
    y = obs.value[rows] - sw.computed
    sig = sig_row[rows]
    unusable = _unusable(obs)[rows] | ~np.isfinite(sig) | ~(sig > 0)
    use = ~(unusable | ~np.isfinite(y) | ~np.isfinite(sw.H).all(axis=1))
    flags[rows][~use] |= NONFINITE
    srif = SRIF.from_apriori(reg.sigma, dx=reg.apriori - x_ref0, n_est=reg.n_estimated)
    K = grid.size - 1
    local = bounds - bounds[0]
    nu, s, bad, filt = np.full(y.size, np.nan), np.full(y.size, np.nan), np.zeros(y.size, bool), []
    cuts = sorted({0, K} | {k for k in sw.noise if k < K})
    for k0, k1 in zip(cuts[:-1], cuts[1:]):
        for idx, m, q, offset in sw.noise.get(k0, ()):
            srif.process_noise(idx, m, q, offset=offset)
        r = slice(local[k0], local[k1])
        Rs, zs, nu[r], s[r], bad[r] = srif.intervals(k0, sw.Phi[k0:k1], sw.H[r], y[r], sig[r], use[r],
                                                      local[k0:k1 + 1] - local[k0], edit_k, against_reference)
        filt.extend(zip(Rs, zs))
    srif.mark(K)
    filt.append((srif.R, srif.z))
    flags[rows][bad] |= EDIT_INNOVATION
    prefit, innov, innov_sig = (np.full(m_obs, np.nan) for _ in range(3))
    prefit[rows], innov[rows], innov_sig[rows] = y, nu, s
    k_row = np.repeat(np.arange(K), np.diff(local))
    return _Pass(srif, sw.refs, filt, smooth_arrays(srif), rows, k_row, sw.H, y, flags, prefit, innov, innov_sig)


def _symmetric(P) -> np.ndarray:
    """Covariances (K, n, n) made exactly symmetric (their products of factors differ by rounding)."""
    P = np.asarray(P)
    return 0.5 * (P + P.transpose(0, 2, 1))


def _gaussian(ps: _Pass, R, z):
    f = ps.srif
    return solve_information(R, z, f.n_est, f.c_bar, f.c_sigma)


def _estimates(ps: _Pass, arrays: dict) -> dict:
    """Estimates (no covariance) from the information arrays ``{k: (R, z)}``, at once."""
    keys = list(arrays)
    x = information_estimates(np.array([arrays[k][0] for k in keys]), np.array([arrays[k][1] for k in keys]),
                              ps.srif.n_est, ps.srif.c_bar)
    return dict(zip(keys, x))


def _gaussians(ps: _Pass, arrays: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x (K, n), P (K, n, n), P_consider (K, n, n) of the information arrays ``[(R, z)]``, at once."""
    f = ps.srif
    return solve_informations(np.array([R for R, _ in arrays]), np.array([z for _, z in arrays]), f.n_est,
                              f.c_bar, f.c_sigma)


def fit(problem: Problem, obs: Observations, t_start: float, t_end: float,
        options: FitOptions = FitOptions(), x_ref=None, earlier: Solution | None = None) -> Solution:
    """Iterated filter-smoother fit of ``obs`` over ``[t_start, t_end]`` (TDB s).

    ``x_ref``: initial reference vector (default: the registry's a priori values); ``earlier``: a fit
    of a shorter arc whose smoothed stochastic values after its batch boundaries start the reference
    there (otherwise their a priori mean: over an unstable orbit far from the earlier fit's solution).
    Rows outside the arc are flagged ``OUTSIDE_ARC`` and not used.
    """
    reg = problem.registry
    n_est = reg.n_estimated
    x_ref0 = reg.apriori.copy() if x_ref is None else np.asarray(x_ref, float).copy()
    extra = np.concatenate([np.asarray(options.extra_epochs, float),
                            np.unique(obs.time) if options.output_at_measurements else []])
    grid, steps = build_grid(reg, t_start, t_end, options.block, extra)
    bounds = np.searchsorted(obs.time, grid, side="left")
    bounds[-1] = np.searchsorted(obs.time, t_end, side="right")
    groups = np.unique(obs.group)
    scale = {g: 1.0 for g in groups}
    p_after = {}           # (grid index, group) -> reference stochastic values after the step
    if earlier is not None:
        for k, group in steps.items():
            i = int(np.searchsorted(earlier.grid, grid[k]))
            if i < earlier.grid.size and earlier.grid[i] == grid[k]:
                p_after.update({(k, j): earlier.smoothed_x[i][idx] for j, (idx, _) in enumerate(group)})
    history, prev_rms, converged = [], None, False
    stage, last_stage = 0, len(options.sigma_scale) - 1
    last_step, halvings, stage_start = None, 0, False
    coarse = getattr(problem, "set_coarse", lambda on: None)
    for it in range(options.max_iter):
        coarse_pass = stage < last_stage or stage_start
        coarse(coarse_pass)
        sig_row = obs.sigma * np.array([scale[g] for g in obs.group]) * options.sigma_scale[stage]
        kk = _edit_k(options, it, prev_rms)  # a new stage's first pass edits too: rows let back in pull it off
        stage_start = False
        for halving in range(options.max_halvings + 1):
            try:
                ps = _filter_smoother_pass(problem, obs, grid, steps, bounds, x_ref0, p_after, sig_row, kk,
                                           options.edit_against_reference)
                break
            except (RuntimeError, ValueError) as err:  # e.g. an orbit driven into the body, light time off its span
                if last_step is None or halving == options.max_halvings:
                    raise FitDiverged(f"iteration {it + 1}: the models cannot be evaluated about the "
                                      f"reference ({err})") from err
                step_x, step_p = last_step
                last_step = (0.5 * step_x, {key: 0.5 * v for key, v in step_p.items()})
                x_ref0 = x_ref0 - last_step[0]
                for key, v in last_step[1].items():
                    p_after[key] -= v
                halvings += 1
        needed = {0} | set(np.unique(ps.k_row).tolist()) | set(steps)
        dx = _estimates(ps, {k: ps.smoothed[k] for k in sorted(needed)})
        ok = ps.flags == 0
        if not ok.any():
            raise NothingToFit(_nothing_left(ps.flags, it))
        postfit = np.full(obs.time.size, np.nan)
        if ps.k_row.size:
            keys = np.array(sorted(needed))
            dx_rows = np.array([dx[k] for k in keys])[np.searchsorted(keys, ps.k_row)]
            with np.errstate(invalid="ignore"):
                postfit[ps.rows] = ps.y - np.einsum("ij,ij->i", ps.H, dx_rows)
        postfit[(ps.flags & NONFINITE) != 0] = np.nan
        rms = float(np.sqrt(np.mean((postfit[ok] / sig_row[ok]) ** 2)))
        P0 = _gaussian(ps, *ps.smoothed[0]).P
        if np.all(np.diag(P0)[:n_est] >= reg.sigma[:n_est] ** 2 * (1.0 - NO_INFORMATION)):
            raise NothingToFit(f"iteration {it + 1}: the {int(ok.sum())} rows used carry no information about "
                               f"any estimated parameter (every row deweighted?); sigmas "
                               f"{np.nanmin(sig_row[ok]):.3g}..{np.nanmax(sig_row[ok]):.3g}")
        corr = np.max(np.abs(dx[0][:n_est]) / np.sqrt(np.diag(P0)[:n_est]))
        history.append({"iteration": it + 1, "postfit_rms": rms,
                        "prefit_rms": float(np.sqrt(np.mean((ps.prefit[ok] / sig_row[ok]) ** 2))),
                        "edited": int(np.sum(ps.flags & EDIT_INNOVATION > 0)),
                        "nonfinite": int(np.sum(ps.flags & NONFINITE > 0)),
                        "max_correction_sigma": float(corr), "edit_k": float(kk),
                        "sigma_scale": float(options.sigma_scale[stage]),
                        "halvings": halvings,
                        "scales": {str(g): float(v) for g, v in scale.items()}})
        _log.info("fit iteration %d: post-fit RMS %.4g sigma (pre-fit %.4g), %d rows edited, largest epoch "
                  "correction %.3g sigma", it + 1, rms, history[-1]["prefit_rms"], history[-1]["edited"], corr)
        # relinearize about the smoothed solution
        step_x = np.zeros_like(x_ref0)
        step_x[:n_est] = dx[0][:n_est]
        x_ref0 = x_ref0 + step_x
        step_p = {}
        for k in steps:
            for j, (idx, _) in enumerate(steps[k]):
                step_p[(k, j)] = dx[k][idx]
                p_after[(k, j)] = ps.refs[k][idx] + dx[k][idx]
        last_step, halvings = (step_x, step_p), 0
        rms_ok = prev_rms is not None and abs(rms - prev_rms) <= options.tol_rms * max(prev_rms, 1.0)
        prev_rms = rms
        if options.reweight and stage == last_stage:
            for g in groups:
                sel = ok & (obs.group == g)
                if sel.sum() >= 10:
                    scale[g] *= float(np.sqrt(np.mean((postfit[sel] / sig_row[sel]) ** 2)))
        if stage < last_stage:
            if corr < options.stage_tol:
                prev_rms *= options.sigma_scale[stage] / options.sigma_scale[stage + 1]  # in the next stage's units
                stage, stage_start = stage + 1, True
            continue
        if corr < options.tol_dx and rms_ok and it >= 1 and not coarse_pass:
            converged = True
            break
    coarse(False)

    best = min(h["postfit_rms"] for h in history)
    if not converged and not rms <= max(options.diverged_rms, best):  # NaN: everything edited
        raise FitDiverged(f"not converged in {options.max_iter} iterations; post-fit RMS {rms:.3g} sigma "
                          f"(best iteration {best:.3g})")
    refs = np.array(ps.refs)
    residuals = pd.DataFrame({"time": obs.time, "group": obs.group, "prefit": ps.prefit,
                              "postfit": postfit, "innovation": ps.innovation,
                              "innovation_sigma": ps.innovation_sigma, "sigma": sig_row,
                              "flags": ps.flags})
    f_x, _, f_Pc = _gaussians(ps, ps.filtered)
    s_x, s_P, s_Pc = _gaussians(ps, [ps.smoothed[k] for k in range(grid.size)])
    return Solution(
        names=reg.names, grid=grid,
        filtered_x=refs + f_x,
        filtered_P=_symmetric(f_Pc),
        smoothed_x=refs + s_x,
        smoothed_P=_symmetric(s_P),
        smoothed_P_consider=_symmetric(s_Pc),
        residuals=residuals, history=history, converged=converged,
        inputs={"observations": checksum(obs.time, obs.value, obs.sigma),
                "apriori": checksum(reg.apriori, reg.sigma),
                "n_observations": int(obs.time.size)})
