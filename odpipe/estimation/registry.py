"""Parameter registry: every estimated or considered quantity of an arc.

The filter works on one flat vector; the registry says what each slot is
(name, kind, owner, a priori value and sigma, process noise) and hands out
index ranges. Canonical order: estimated parameters in insertion order, then
consider parameters, so that a square-root information array can be
partitioned ``[estimated | consider]``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

KINDS = (
    "state",        # epoch position/velocity of a spacecraft (m, m/s)
    "dynamic",      # dynamic model parameter (SRP scale, reflectivity, ...)
    "stochastic",   # stochastic acceleration (m/s^2), piecewise constant over batches
    "bias",         # measurement bias per pass/station/observable (observable units)
    "clock",        # clock offset/drift
    "timing",       # a station's time-tag offset (s, tags late)
    "maneuver",     # impulsive maneuver dV component (m/s)
    "maneuver_epoch",  # impulsive maneuver epoch offset (s)
    "station",      # station coordinate (m)
    "media",        # media calibration scale or offset
    "eop",          # Earth orientation parameter
)


@dataclass(frozen=True)
class GaussMarkov:
    """First-order Gauss-Markov process, piecewise constant over batches.

    tau: correlation time (s); 0 gives white noise (independent per batch),
    ``inf`` a random walk with increment sigma per batch.
    sigma: steady-state standard deviation (parameter units).
    batch: batch length (s); the value changes only at batch boundaries.
    """

    tau: float
    sigma: float
    batch: float

    def step(self, dt: float | None = None) -> tuple[float, float]:
        """Return (m, q): p_next = m p + w, w ~ N(0, q) over dt (default: one batch)."""
        dt = self.batch if dt is None else dt
        if np.isinf(self.tau):
            return 1.0, self.sigma**2
        m = float(np.exp(-dt / self.tau)) if self.tau > 0 else 0.0
        return m, self.sigma**2 * (1.0 - m * m)


@dataclass(frozen=True)
class Parameter:
    """One scalar entry of the registry (SI units)."""

    name: str
    kind: str
    owner: str
    apriori: float
    sigma: float
    consider: bool = False
    process: GaussMarkov | None = None
    epoch: float | None = None  # TDB s past J2000, for maneuvers
    info: dict = field(default_factory=dict, compare=False)


class ParameterRegistry:
    """Ordered collection of :class:`Parameter`; the filter sees index ranges only."""

    def __init__(self) -> None:
        self._params: list[Parameter] = []

    # -- building -------------------------------------------------------
    def add(self, name, kind, apriori, sigma, *, owner="", consider=False,
            process=None, epoch=None, **info) -> Parameter:
        if kind not in KINDS:
            raise ValueError(f"unknown parameter kind {kind!r}; one of {KINDS}")
        if any(p.name == name for p in self._params):
            raise ValueError(f"parameter {name!r} already registered")
        if not sigma > 0:
            raise ValueError(f"parameter {name!r}: a priori sigma must be > 0")
        if process is not None and consider:
            raise ValueError(f"parameter {name!r}: a stochastic parameter cannot be considered")
        p = Parameter(name, kind, owner, float(apriori), float(sigma), consider,
                      process, epoch, info)
        self._params.append(p)
        return p

    def add_state(self, spacecraft, x0, sigma_pos, sigma_vel):
        """Epoch position (m) and velocity (m/s) of a spacecraft."""
        for i, axis in enumerate(("x", "y", "z", "vx", "vy", "vz")):
            self.add(f"{spacecraft}.{axis}", "state", x0[i],
                     sigma_pos if i < 3 else sigma_vel, owner=spacecraft)

    def add_stochastic_acceleration(self, spacecraft, sigma, tau, batch,
                                    axes=("R", "T", "N")):
        """Gauss-Markov accelerations (m/s^2) on each axis (RTN by default); ``sigma`` one value
        or one per axis (axes of equal sigma share one process)."""
        sigmas = [float(s) for s in np.broadcast_to(np.asarray(sigma, float), (len(axes),))]
        procs = {s: GaussMarkov(tau, s, batch) for s in sigmas}
        for a, s in zip(axes, sigmas):
            self.add(f"{spacecraft}.acc_{a}", "stochastic", 0.0, s,
                     owner=spacecraft, process=procs[s], axis=a)

    def add_maneuver(self, spacecraft, label, epoch, sigma_dv=0.01,
                     designed=(0.0, 0.0, 0.0), sigma_epoch=None):
        """Impulsive maneuver: dV components (m/s) about ``designed``, zero a priori
        deviation; optionally its epoch offset (s). Defaults as Table 4.1."""
        owner = f"{spacecraft}.{label}"
        for a, dv in zip(("x", "y", "z"), designed):
            self.add(f"{owner}.dv_{a}", "maneuver", dv, sigma_dv, owner=owner,
                     epoch=epoch)
        if sigma_epoch is not None:
            self.add(f"{owner}.dt", "maneuver_epoch", 0.0, sigma_epoch,
                     owner=owner, epoch=epoch)

    def add_time_offset(self, station, sigma, **info):
        """Time-tag offset (s) of ``station``'s rows, positive when its tags are late (the row at tag t
        saw t - dt); ``info`` narrows the rows as a bias's does (``observable``, ``spacecraft``)."""
        self.add(f"timing.{station}", "timing", 0.0, sigma, owner=station, station=station, **info)

    # -- reading --------------------------------------------------------
    @property
    def parameters(self) -> list[Parameter]:
        """Parameters in canonical order (estimated first, then consider)."""
        return ([p for p in self._params if not p.consider]
                + [p for p in self._params if p.consider])

    def __len__(self) -> int:
        return len(self._params)

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.parameters]

    @property
    def n_estimated(self) -> int:
        return sum(not p.consider for p in self._params)

    @property
    def apriori(self) -> np.ndarray:
        return np.array([p.apriori for p in self.parameters])

    @property
    def sigma(self) -> np.ndarray:
        return np.array([p.sigma for p in self.parameters])

    def index(self, name: str) -> int:
        return self.names.index(name)

    def indices(self, kind=None, owner=None, consider=None) -> np.ndarray:
        """Canonical indices of parameters matching kind / owner (prefix) / consider."""
        return np.array([i for i, p in enumerate(self.parameters)
                         if (kind is None or p.kind == kind)
                         and (owner is None or p.owner == owner
                              or p.owner.startswith(owner + "."))
                         and (consider is None or p.consider == consider)], dtype=int)

    def slice(self, kind=None, owner=None) -> slice:
        """Contiguous index range of the matching parameters (raises if none or split)."""
        idx = self.indices(kind, owner)
        if idx.size == 0 or idx[-1] - idx[0] + 1 != idx.size:
            raise KeyError(f"no contiguous range for kind={kind!r} owner={owner!r}")
        return slice(int(idx[0]), int(idx[-1]) + 1)

    def stochastic_groups(self) -> list[tuple[np.ndarray, GaussMarkov]]:
        """(indices, process) for each distinct stochastic process, canonical order."""
        groups: dict = {}
        for i, p in enumerate(self.parameters):
            if p.process is not None:
                groups.setdefault(id(p.process), (p.process, []))[1].append(i)
        return [(np.array(ix), proc) for proc, ix in groups.values()]
