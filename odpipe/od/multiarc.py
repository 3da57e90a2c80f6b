"""Multi-arc solution: dynamic parameters shared by several arcs, each arc with its own state.

Each arc is fitted on its own (:func:`odpipe.od.arc.fit_arc`) with the shared parameters estimated about a
common a priori ``N(g0, S0)`` (the registry's values and sigmas; the same in every arc). The smoothed epoch
covariance of arc i holds everything its data say about them, the arc's own state, stochastic accelerations
and biases marginalised (a Schur complement): posterior ``N(g_i, P_i)`` with its prior ``N(a_i, S0)``, so the
data's information is ``L_i = P_i^-1 - S0^-1`` and ``e_i = P_i^-1 g_i - S0^-1 a_i``. The combined estimate
counts the prior once::

    P = (S0^-1 + sum L_i)^-1,   g = P (S0^-1 g0 + sum e_i)

Then every arc is fitted again with the shared parameters fixed at ``g`` (its state, stochastic accelerations
and biases conditioned on them: the multi-arc solution's local part); its state covariances get the shared
parameters' share, ``K P K^T`` with ``K = P_xg P_gg^-1`` the slope of the state with them in the arc's own fit
(the conditional covariance alone is too small by that: the combination's error moves every arc). With ``rounds`` > 1 the arcs are
fitted again about ``g`` (prior ``N(g, S0)``, counted out as above) until ``g`` moves by less than ``tol`` of
its sigma. Each arc's consistency with the others: ``d_i = g_i - g`` with ``g_i`` the arc's own estimate
with the common prior, ``(S0^-1 + L_i)^-1 (S0^-1 g0 + e_i)``, tested as chi-square with the covariance of a
sub-estimate's difference from the whole, ``(S0^-1 + L_i)^-1 - P``.

Shared parameters are force-model parameters by name (:meth:`ForceModel.parameter_names`: ``srp_scale``,
``cd``, ``poly[k].x0`` ...; registry name ``<spacecraft>.<name>``). Fixing one removes its sigma from the
arc set-up, so a polynomial acceleration is shared whole (all its coefficients) or not at all.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from .arc import ArcSetup, ArcSolution, fit_arc

# a shared parameter's name prefix -> the ArcSetup field whose None fixes it
_SIGMA_FIELD = {"srp_scale": "srp_scale_sigma", "cd": "cd_sigma", "poly[": "polynomial_sigma"}


def _field(name: str) -> str:
    for prefix, fld in _SIGMA_FIELD.items():
        if name.startswith(prefix):
            return fld
    raise ValueError(f"shared parameter {name!r}: not one of {sorted(_SIGMA_FIELD)} (a multi-arc solution shares "
                     "force-model parameters the arc set-up estimates)")


@dataclass(frozen=True)
class ArcShare:
    """What one arc's fit says about the shared parameters: its smoothed epoch estimate and covariance
    (prior included), the prior it was fitted with (mean, sigma) and ``gain`` (K, 6, n): the slope of the
    smoothed state at each grid epoch with the shared parameters, ``P_xg P_gg^-1`` (None: not known)."""

    estimate: np.ndarray
    covariance: np.ndarray
    prior_mean: np.ndarray
    prior_sigma: np.ndarray
    gain: np.ndarray | None = None

    def information(self) -> tuple[np.ndarray, np.ndarray]:
        """(L, e): the data's information matrix and vector about the shared parameters (prior counted out)."""
        Pi = np.linalg.inv(self.covariance)
        S0i = np.diag(self.prior_sigma ** -2.0)
        return Pi - S0i, Pi @ self.estimate - S0i @ self.prior_mean


def solution_share(sol, spacecraft: str, shared, prior_mean, prior_sigma) -> ArcShare:
    """The shared parameters' part of a fit's :class:`~odpipe.estimation.solution.Solution` (e.g. a run's
    ``solution.npz``) fitted with the prior ``N(prior_mean, prior_sigma^2)``. KeyError naming the parameters
    the arc did not estimate."""
    names = list(sol.names)
    missing = [n for n in shared if f"{spacecraft}.{n}" not in names]
    if missing:
        raise KeyError(f"shared parameter(s) {missing} not estimated in the arc of {spacecraft} (set their sigma)")
    idx = [names.index(f"{spacecraft}.{n}") for n in shared]
    st = [names.index(f"{spacecraft}.{a}") for a in ("x", "y", "z", "vx", "vy", "vz")]
    P = np.asarray(sol.smoothed_P)
    gain = P[:, st][:, :, idx] @ np.linalg.inv(P[:, idx][:, :, idx])
    return ArcShare(np.asarray(sol.smoothed_x[0][idx], float), P[0][np.ix_(idx, idx)],
                    np.asarray(prior_mean, float), np.asarray(prior_sigma, float), gain)


def share_of(arc: ArcSolution, shared) -> ArcShare:
    """The shared parameters' part of a fitted arc, the prior from its own registry."""
    reg = arc.registry
    missing = [n for n in shared if f"{arc.spacecraft}.{n}" not in reg.names]
    if missing:
        raise KeyError(f"shared parameter(s) {missing} not estimated in the arc of {arc.spacecraft} (set their sigma)")
    idx = [reg.index(f"{arc.spacecraft}.{n}") for n in shared]
    return solution_share(arc.solution, arc.spacecraft, shared, reg.apriori[idx], reg.sigma[idx])


@dataclass(frozen=True)
class Combined:
    """Combined shared parameters: ``names``, ``estimate``, ``covariance``; per arc its data-only estimate
    with the common prior (``arc_estimates``, ``arc_covariances``) and its consistency chi-square with the
    combination (``chi2``, len(names) degrees of freedom)."""

    names: tuple
    estimate: np.ndarray
    covariance: np.ndarray
    arc_estimates: np.ndarray
    arc_covariances: np.ndarray
    chi2: np.ndarray

    @property
    def sigma(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))

    def table(self, labels) -> pd.DataFrame:
        """One row per arc and one for the combination: estimate (and sigma) of each shared parameter."""
        rows = [{"arc": lab, "chi2": c, **dict(zip(self.names, est)),
                 **{f"{n}_sigma": s for n, s in zip(self.names, np.sqrt(np.diag(cov)))}}
                for lab, est, cov, c in zip(labels, self.arc_estimates, self.arc_covariances, self.chi2)]
        rows.append({"arc": "combined", "chi2": np.nan, **dict(zip(self.names, self.estimate)),
                     **{f"{n}_sigma": s for n, s in zip(self.names, self.sigma)}})
        return pd.DataFrame(rows)


def combine(shares, prior_mean, prior_sigma, names=()) -> Combined:
    """The shared parameters from every arc's ``ArcShare``, the prior ``N(prior_mean, diag(prior_sigma^2))``
    counted once (see the module)."""
    g0, s0 = np.asarray(prior_mean, float), np.asarray(prior_sigma, float)
    S0i = np.diag(s0 ** -2.0)
    infos = [s.information() for s in shares]
    L = S0i + sum(i[0] for i in infos)
    P = np.linalg.inv(L)
    g = P @ (S0i @ g0 + sum(i[1] for i in infos))
    own, cov, chi2 = [], [], []
    for Li, ei in infos:
        Pi = np.linalg.inv(S0i + Li)           # the arc alone with the prior: a sub-estimate of the combination
        gi = Pi @ (S0i @ g0 + ei)
        d = gi - g
        own.append(gi)
        cov.append(Pi)
        chi2.append(float(d @ np.linalg.pinv(Pi - P) @ d))
    return Combined(tuple(names), g, 0.5 * (P + P.T), np.array(own), np.array(cov), np.array(chi2))


def with_shared(setup: ArcSetup, names, values, fixed: bool) -> ArcSetup:
    """``setup`` with the shared parameters' model values set to ``values`` (their a priori when estimated),
    and with them fixed (their sigmas removed) when ``fixed``. ValueError when fixing would also fix a
    parameter that is not shared (a polynomial acceleration's other coefficients)."""
    fm = setup.force_model.with_parameters(dict(zip(names, map(float, values))))
    out = replace(setup, force_model=fm)
    if fixed:
        fields = {_field(n) for n in names}
        if "polynomial_sigma" in fields:
            poly = [p for p in fm.parameter_names() if p.startswith("poly[")]
            if set(poly) - set(names):
                raise ValueError(f"a multi-arc solution shares the polynomial acceleration whole: also share "
                                 f"{sorted(set(poly) - set(names))}")
        out = replace(out, **{f: None for f in fields})
    return out


@dataclass
class MultiArcSolution:
    """``arcs``: each arc fitted with the shared parameters fixed at ``shared.estimate`` (its ``covariances``
    with the shared parameters' share added); ``shared``: the combination (last round); ``rounds``: the
    combination of each round."""

    arcs: list
    shared: Combined
    rounds: list


def fit_multiarc(arcs, shared, rounds: int = 1, tol: float = 0.1, first=None, log=None) -> MultiArcSolution:
    """Multi-arc fit of ``arcs`` [(table, ArcSetup)] sharing the force-model parameters ``shared`` (names).

    Every set-up must estimate them with the same a priori value and sigma (the common prior). ``first``:
    the arcs' own fits (``ArcShare`` per arc) when already made, used for the first round instead of fitting.
    ``rounds``: estimation rounds at most (each about the last combination), stopping when the estimate moves
    by less than ``tol`` sigma. ValueError when the set-ups' priors differ.
    """
    shared = tuple(shared)
    log = log or (lambda s: None)
    for n in shared:
        _field(n)
    g0 = s0 = None
    combos: list[Combined] = []
    g = None
    for r in range(rounds):
        if r == 0 and first is not None:
            shares = list(first)
        else:
            shares = []
            for k, (table, setup) in enumerate(arcs):
                s = setup if g is None else with_shared(setup, shared, g, fixed=False)
                shares.append(share_of(fit_arc(table, s), shared))
                log(f"multi-arc round {r + 1}: arc {k + 1} of {len(arcs)} fitted with {', '.join(shared)} estimated")
        if g0 is None:
            g0, s0 = shares[0].prior_mean, shares[0].prior_sigma
            for k, s in enumerate(shares):
                if not (np.allclose(s.prior_mean, g0, rtol=1e-12, atol=0) and np.allclose(s.prior_sigma, s0)):
                    raise ValueError(f"arc {k + 1}: the shared parameters' a priori {s.prior_mean} ± {s.prior_sigma}"
                                     f" differs from arc 1's {g0} ± {s0}; a multi-arc solution needs one prior")
        c = combine(shares, g0, s0, shared)
        combos.append(c)
        log(f"multi-arc round {r + 1}: " + ", ".join(f"{n} {v:.6g} ± {s:.2g}" for n, v, s in
                                                       zip(shared, c.estimate, c.sigma)))
        moved = np.inf if g is None else np.max(np.abs(c.estimate - g) / c.sigma)
        g = c.estimate
        if moved < tol:
            break
    fitted = []
    for k, (table, setup) in enumerate(arcs):
        arc = fit_arc(table, with_shared(setup, shared, g, fixed=True))
        K = shares[k].gain
        if K is not None:
            if K.shape[0] != arc.covariances.shape[0]:
                raise ValueError(f"arc {k + 1}: its own fit has {K.shape[0]} grid epochs, the refit "
                                 f"{arc.covariances.shape[0]} (the same set-up must give the same grid)")
            arc.covariances = arc.covariances + K @ combos[-1].covariance @ K.transpose(0, 2, 1)
        fitted.append(arc)
        log(f"multi-arc: arc {k + 1} of {len(arcs)} fitted with the shared parameters fixed")
    return MultiArcSolution(fitted, combos[-1], combos)
