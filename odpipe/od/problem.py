"""TrackingProblem: the estimation ``Problem`` protocol over TrackingTable rows.

Glue between :mod:`odpipe.dynamics` (reference trajectories with STM and
sensitivities), :mod:`odpipe.measurements` (computed values and event partials)
and :func:`odpipe.estimation.fit.fit`. Registry entries it understands
(``owner`` = spacecraft id unless said otherwise; values SI):

==============  =================================================================================
state           epoch position/velocity (``registry.add_state``), relative to the force model centre
dynamic         a force-model parameter: ``info['model']`` in a name of ``ForceModel.parameter_names`` (``srp_scale``, ``rho_s[k]``, ``cd``, ``poly[k].x0``, ...), put in by ``ForceModel.with_parameters``
stochastic      RTN accelerations (``registry.add_stochastic_acceleration``, axes R, T, N), m/s^2
maneuver        impulsive ICRF dV (``registry.add_maneuver``; owner ``<sc>.<label>``), m/s
maneuver_epoch  offset (s) of that maneuver's firing from its logged epoch (``add_maneuver(sigma_epoch=)``);
                the segment still starts at the logged epoch; reference exact, partials first
                order in the offset (:mod:`.segment`)
clock           one-way oscillator ``owner`` (a name of :mod:`odpipe.measurements.oscillators`: the spacecraft,
                one band of it or one pass of that band): ``info['oscillator']`` 'y0' (fractional frequency
                offset) or 'y1' (its drift, 1/s); the reference epoch ``info['t_ref']`` (TDB s), else from
                ``setup.oscillators[owner]``
bias            measurement bias along the line of sight (m for range, m/s for Doppler; an angle in rad for
                angle rows, unit 'rad') of the rows matching ``info`` keys ``observable``, ``station``
                (receiver), ``pass_id``, ``spacecraft``
timing          time-tag offset (s, tags late) of the rows matching ``info`` as a bias's; partial minus the
                computed value's rate (:func:`odpipe.measurements.timetag.tag_rate`)
station         ITRS offset (m) of station ``owner`` from the catalog, ``info['axis']`` x/y/z (linear)
media           offset of the media scale from ``setup.media_scale`` (linear, exact)
==============  =================================================================================

Other kinds (``eop``) are refused. Linear kinds enter as
``computed + H x`` (exact for biases and the media scale; station offsets to first order).

Efficiency and exactness. The arc is cut into segments at the epochs where the
reference may change (stochastic-batch boundaries, maneuvers); each segment is
integrated once per relinearization (:class:`.segment.SegmentTrajectory`) and
all its rows are evaluated in one :func:`~odpipe.measurements.compute` call.
Over a grid interval ``[t0, t1]`` inside a segment (Phi, S = STM and
sensitivities from the segment start):

* ``Phi_xx = Phi(t1) Phi(t0)^-1`` and ``Phi_xp = S(t1) - Phi(t1) Phi(t0)^-1 S(t0)``;
* a row's partials at ``t0``: ``H_x = G_x Phi(t0)^-1``, ``H_p = G_p - H_x S(t0)``, with
  ``G`` the measurement's event partials already composed with ``Phi(t_event)``.

Both are exact for the linearized flow (no re-integration per interval). A
segment is reused while the reference handed in agrees bit for bit with it,
and rebuilt from ``t0`` otherwise, so any caller gets a consistent answer.
Media: a ``media_m`` column enters the computed value (``setup.media_in_model``),
which is the same as subtracting it from the observed value. Range rows with a
``range_modulus`` are wrapped to the computed value.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from odpipe.dynamics.forces import EmpiricalRTN, ForceModel
from odpipe.frames.tabulated import TabulatedRotation
from odpipe.measurements import MeasurementSetup, compute, residuals
from odpipe.measurements.compute import SPAN_MARGIN_S, prepare
from odpipe.measurements.timetag import tag_rate

from .segment import SegmentTrajectory, ShiftedSegmentTrajectory

_LINEAR = ("bias", "station", "media", "timing")
_REFERENCE = ("dynamic", "stochastic", "maneuver", "maneuver_epoch", "clock")
_SUPPORTED = ("state",) + _LINEAR + _REFERENCE
# a bias parameter's info key -> the row column it selects on
_BIAS_KEYS = {"observable": "observable", "station": "station_rx", "pass_id": "pass_id", "spacecraft": "spacecraft"}
LINEAR_REUSE = 1e-4  # relative state offset up to which a coarse reference is shifted, not integrated
# (1e-3 took GRAIL-B 04-11's loose stages far enough off, through the STM's gradient to degree 8 only,
# that its last stage needed two more passes)


@dataclass
class _Segment:
    a: float
    b: float
    key: np.ndarray            # registry values the reference was built with (_REFERENCE kinds)
    trajs: dict                # sc -> SegmentTrajectory
    pidx: dict                 # sc -> registry index per trajectory parameter
    lo: int                    # rows [lo, hi) of the problem
    hi: int
    value: np.ndarray          # computed (row units), linear terms at zero
    to_los: np.ndarray
    status: np.ndarray
    G_x: dict                  # sc -> (m, 6) d value / d x(a-)
    G_p: dict                  # sc -> (m, p) d value / d params (trajectory order)
    H_lin: np.ndarray          # (m, n) registry partials of the linear and clock terms
    coarse: bool = False       # integrated with the coarse settings (set_coarse)


class TrackingProblem:
    """Problem over ``rows`` (a TrackingTable slice, ordered by ``times``: TDB s, last event of each row).

    force_models: spacecraft id -> :class:`ForceModel` (without the estimated
    maneuvers and stochastic accelerations: the problem adds them);
    lookback: s before a segment start covered for light time and count intervals;
    epochs: where transitions will be asked (the filter grid), evaluated per segment in one pass;
    integrator: spacecraft id -> :func:`propagate` settings overriding ``rtol``/``atol`` (fixed steps
    as an onboard filter takes them: ``{"rtol": inf, "max_step": 60}``, or ``{"method": "rk4",
    "max_step": 60}``);
    coarse: integrator settings (e.g. ``{"rtol": 1e-9, "atol": 1e-5}``) of the references flown while
    :meth:`set_coarse` is on (the fit's loose-weight stages, where a reference need not be exact), for the
    spacecraft without ``integrator`` settings; None: always the exact ones. While it is on, a segment
    whose start state is within ``LINEAR_REUSE`` (relative) of one integrated with the same settings and
    parameter set is shifted from it to first order (:class:`.segment.ShiftedSegmentTrajectory`: its
    STM and sensitivities, no integration), so the loose stages after the first fly no new reference;
    shared: a dict shared by problems of one arc (e.g. the geometry step's a priori reference and the
    fit's problems): a segment integrated by one from the same start state, parameter values and
    settings is taken from it instead of integrated again (the latest per spacecraft and span is kept).
    """

    def __init__(self, registry, rows: pd.DataFrame, times: np.ndarray, force_models: dict,
                 setup: MeasurementSetup, t_start: float, t_end: float, lookback: float = 120.0,
                 rtol: float = 1e-12, atol: float = 1e-6, epochs=(), integrator=None, shared=None,
                 coarse=None):
        self.registry = registry
        self.rows = rows.reset_index(drop=True)
        self.times = np.asarray(times, float)
        if np.any(np.diff(self.times) < 0):
            raise ValueError("rows must be ordered by time")
        self.force_models, self.setup = dict(force_models), setup
        self._tabulated = None      # setup with the Earth orientation tabulated over the problem (first use)
        self.t_start, self.t_end = float(t_start), float(t_end)
        self.lookback, self.rtol, self.atol = lookback, rtol, atol
        self.integrator = dict(integrator or {})
        self.epochs = np.asarray(epochs, float)
        self.n_propagations = 0
        self.shared = {} if shared is None else shared
        self.coarse, self._coarse = coarse, False
        self._segments: list[_Segment] = []
        self._prepared: dict = {}   # (lo, hi) -> measurements.compute.Prepared of those rows
        self._selected: dict = {}   # (lo, hi) -> {registry index: rows of a bias or timing parameter}
        self._last = (None, None)   # (segment, x1) of the last transition, to skip re-checks
        params = registry.parameters
        bad = sorted({p.kind for p in params} - set(_SUPPORTED))
        if bad:
            raise ValueError(f"parameter kinds not modelled by TrackingProblem: {bad}")
        self._key_idx = np.array([i for i, p in enumerate(params) if p.kind in _REFERENCE], int)
        self._lin_idx = np.array([i for i, p in enumerate(params) if p.kind in _LINEAR], int)
        self._sc = {sc: self._spacecraft_indices(sc) for sc in self.force_models}
        self._state = {sc: slice(ix["state"][0], ix["state"][-1] + 1) for sc, ix in self._sc.items()}  # consecutive
        self._breaks = self._break_epochs()

    # -- registry layout ------------------------------------------------
    def _spacecraft_indices(self, sc) -> dict:
        reg = self.registry
        params = reg.parameters
        out = {"state": np.arange(reg.slice("state", sc).start, reg.slice("state", sc).stop)}
        out["dynamic"] = [(i, p.info["model"]) for i, p in enumerate(params)
                          if p.kind == "dynamic" and p.owner == sc]
        stoch = {p.info.get("axis"): i for i, p in enumerate(params)
                 if p.kind == "stochastic" and p.owner == sc}
        if stoch and set(stoch) != {"R", "T", "N"}:
            raise ValueError(f"{sc}: stochastic accelerations must be on axes R, T, N")
        out["stochastic"] = [stoch[a] for a in "RTN"] if stoch else []
        man: dict = {}
        for i, p in enumerate(params):
            if p.kind in ("maneuver", "maneuver_epoch") and p.owner.startswith(sc + "."):
                man.setdefault(float(p.epoch), {})["t" if p.kind == "maneuver_epoch" else p.name[-1]] = i
        if any(set(d) - {"t"} != set("xyz") for d in man.values()):
            raise ValueError(f"{sc}: every maneuver needs dv_x, dv_y, dv_z (an epoch offset alone is not a maneuver)")
        out["maneuvers"] = {t: [d[a] for a in "xyz"] for t, d in man.items()}
        out["maneuver_epochs"] = {t: d["t"] for t, d in man.items() if "t" in d}
        return out

    def _break_epochs(self) -> np.ndarray:
        pts = [self.t_end]
        for _, proc in self.registry.stochastic_groups():
            pts += list(np.arange(self.t_start + proc.batch, self.t_end, proc.batch))
        for ix in self._sc.values():
            pts += [t for t in ix["maneuvers"] if self.t_start < t < self.t_end]
        return np.unique(np.asarray(pts, float))

    def set_coarse(self, on: bool) -> None:
        """Fly the references built from now on with the ``coarse`` settings (when given) or the exact ones."""
        self._coarse = bool(on) and self.coarse is not None

    # -- segments -------------------------------------------------------
    def _find(self, t0, x0):
        for seg in self._segments:
            if seg.a <= t0 < seg.b:
                if seg.coarse != self._coarse:
                    return None
                if (seg is self._last[0] and x0 is self._last[1] and t0 > seg.a) or self._agrees(seg, t0, x0):
                    return seg
                return None
        return None

    def _agrees(self, seg, t0, x0) -> bool:
        if not np.array_equal(x0[self._key_idx], seg.key):
            return False
        for sc, traj in seg.trajs.items():
            if not np.array_equal(x0[self._sc[sc]["state"]], traj.at(t0)[0]):
                return False
        return True

    def segment(self, t0: float, x0: np.ndarray) -> _Segment:
        """The segment holding ``t0`` whose reference passes through ``x0`` (built if needed)."""
        x0 = np.asarray(x0, float)
        seg = self._find(t0, x0)
        return seg if seg is not None else self._build(float(t0), x0)

    def _segment_model(self, sc, x0, a, b) -> tuple[ForceModel, list, list]:
        fm, ix = self.force_models[sc], self._sc[sc]
        values = {name: x0[i] for i, name in ix["dynamic"]}
        comps = list(fm.with_parameters(values).components)
        names = [name for _, name in ix["dynamic"]]
        idx = [i for i, _ in ix["dynamic"]]
        if ix["stochastic"]:
            b0 = sum(len(np.atleast_2d(e.batches)) for e in fm.of_type(EmpiricalRTN))
            acc = x0[ix["stochastic"]]
            comps.append(EmpiricalRTN(np.array([[a - self.lookback - 1.0, b + 1.0, *acc]])))
            names += [f"emp[{b0}].{c}" for c in "RTN"]
            idx += ix["stochastic"]
        return replace(fm, components=comps), names, idx

    def trajectories(self, a: float, x0: np.ndarray) -> tuple[float, dict, dict]:
        """(segment end b, sc -> reference trajectory from ``a`` through ``x0``, sc -> registry indices
        of its parameters); no measurement is evaluated (products use this after a fit)."""
        later = self._breaks[self._breaks > a]
        b = float(later[0]) if later.size else self.t_end
        trajs, pidx = {}, {}
        for sc, ix in self._sc.items():
            fm, names, idx = self._segment_model(sc, x0, a, b)
            dv_idx = ix["maneuvers"].get(a)
            dt_idx = ix["maneuver_epochs"].get(a)
            dv = x0[dv_idx] if dv_idx is not None else None
            dt = x0[dt_idx] if dt_idx is not None else None
            settings = {"rtol": self.rtol, "atol": self.atol, **self.integrator.get(sc, {})}
            if self._coarse and sc not in self.integrator:
                settings.update(self.coarse)
            pidx[sc] = np.array(idx + (dv_idx or []) + ([dt_idx] if dt_idx is not None else []), int)
            key = (x0[ix["state"]].tobytes(), x0[pidx[sc]].tobytes(), tuple(names),
                   tuple(self.registry.names[i] for i in pidx[sc]), id(self.force_models[sc]), self.lookback,
                   repr(sorted(settings.items())))
            held = self.shared.get((sc, a, b))
            if held is not None and held[0] == key:
                trajs[sc] = held[1]
            elif self._coarse and self._near(held, key, x0[ix["state"]], dt):
                trajs[sc] = ShiftedSegmentTrajectory(held[1], x0[ix["state"]],
                                                     x0[pidx[sc]] - np.frombuffer(held[0][1]))
            else:
                trajs[sc] = SegmentTrajectory(x0[ix["state"]], a, b, fm, names, dv, self.lookback, dt=dt, **settings)
                self.shared[(sc, a, b)] = (key, trajs[sc])
                self.n_propagations += 1
            trajs[sc].preload(self.epochs[(self.epochs > a) & (self.epochs <= b)])
        return b, trajs, pidx

    @staticmethod
    def _near(held, key, x_start, dt) -> bool:
        """Whether a coarse reference from ``x_start`` may be taken to first order from the segment ``held``
        (key, trajectory) integrated with the same parameters and settings: offsets within
        ``LINEAR_REUSE`` of the state (position and velocity, relative), no estimated firing epoch."""
        if held is None or held[0][2:] != key[2:] or dt is not None:
            return False
        base = getattr(held[1], "base", held[1])
        d = x_start - base.x_start
        return bool(np.linalg.norm(d[:3]) <= LINEAR_REUSE * np.linalg.norm(base.x_start[:3])
                    and np.linalg.norm(d[3:]) <= LINEAR_REUSE * np.linalg.norm(base.x_start[3:]))

    def linearized(self, a: float, x_a: np.ndarray) -> tuple[float, dict] | None:
        """(segment end b, sc -> ``states(t)`` (N, 6)) of the trajectory through ``x_a`` at ``a``, to first
        order about the reference segment held from ``a`` (``x_ref(t) + stm(t) dx(a-) + S(t) dp``), without
        integrating; None when no held segment starts at ``a``. The error is second order in the difference:
        for a converged fit's last correction (the smoothed solution against the last reference) it is
        negligible, which is what products use it for."""
        seg = next((s for s in self._segments if s.a == a), None)
        if seg is None:
            return None
        x_a = np.asarray(x_a, float)
        ref = np.zeros(x_a.size)
        ref[self._key_idx] = seg.key
        out = {}
        for sc, traj in seg.trajs.items():
            dx = x_a[self._sc[sc]["state"]] - traj.x_start
            dp = x_a[seg.pidx[sc]] - ref[seg.pidx[sc]]

            def states(t, traj=traj, dx=dx, dp=dp):
                return traj.state(t) + traj.stm(t) @ dx + traj.sensitivity(t) @ dp
            out[sc] = states
        return seg.b, out

    def _build(self, a, x0) -> _Segment:
        b, trajs, pidx = self.trajectories(a, x0)
        self._segments = [s for s in self._segments if s.b <= a or s.a >= b]
        lo = int(np.searchsorted(self.times, a, "left"))
        hi = self.times.size if b >= self.t_end else int(np.searchsorted(self.times, b, "left"))
        seg = _Segment(a, b, x0[self._key_idx].copy(), trajs, pidx, lo, hi, *self._evaluate(lo, hi, trajs, x0),
                       coarse=self._coarse)
        self._segments.append(seg)
        self._segments.sort(key=lambda s: s.a)
        return seg

    def _arc_setup(self) -> MeasurementSetup:
        """``setup`` with the GCRS->ITRS rotation tabulated once over the problem's span and rows (compute()'s margin),
        instead of at every compute() call (every segment and iteration); the table's hourly segments are fitted
        on the same nodes either way, so the values are the same."""
        if self._tabulated is None:
            rot = self.setup.gcrs_to_itrs
            if rot is not None and not isinstance(rot, TabulatedRotation):
                t = np.r_[self.t_start - self.lookback, self.t_end, self.times[:1], self.times[-1:]]
                rot = TabulatedRotation(rot, t.min() - SPAN_MARGIN_S, t.max() + SPAN_MARGIN_S)
            self._tabulated = replace(self.setup, gcrs_to_itrs=rot)
        return self._tabulated

    def _measurement_setup(self, x0) -> MeasurementSetup:
        """The measurement set-up with every estimated oscillator's terms from ``x0``."""
        osc = dict(self.setup.oscillators)
        for i, p in enumerate(self.registry.parameters):
            if p.kind == "clock" and "oscillator" in p.info:   # not a clock polynomial (studies' 'clock' kind)
                terms = list(osc.get(p.owner, (0.0, 0.0, 0.0)))
                terms[2] = p.info.get("t_ref", terms[2])
                terms[("y0", "y1").index(p.info["oscillator"])] = x0[i]
                osc[p.owner] = tuple(terms)
        return replace(self._arc_setup(), oscillators=osc)

    def _evaluate(self, lo, hi, trajs, x0):
        n, m = len(self.registry), hi - lo
        G_x = {sc: np.zeros((m, 6)) for sc in trajs}
        G_p = {sc: np.zeros((m, len(trajs[sc].param_names))) for sc in trajs}
        H_lin = np.zeros((m, n))
        if m == 0:   # a segment without rows (span still reads its partials)
            return np.zeros(0), np.zeros(0), np.zeros(0, object), G_x, G_p, H_lin
        if (lo, hi) not in self._prepared:   # a segment's rows are grouped once, not at every iteration
            self._prepared[(lo, hi)] = prepare(self.rows.iloc[lo:hi])
        prepared = self._prepared[(lo, hi)]
        rows = prepared.rows
        setup = replace(self._measurement_setup(x0),
                        station_partials=any(p.kind == "station" for p in self.registry.parameters))
        ev = compute(rows, trajs, setup, prepared)
        res, _ = residuals(rows, ev)
        observed = rows["value"].to_numpy(float)
        value = np.where(np.isfinite(observed), observed - res, ev.value)  # computed, wrapped to the observation
        for sc in trajs:
            G_x[sc] = ev.partials.get(f"state:{sc}", G_x[sc])
            G_p[sc] = ev.partials.get(f"dynamic:{sc}", G_p[sc])
        params = self.registry.parameters
        if (lo, hi) not in self._selected:
            columns = {col: rows[col].to_numpy() for col in _BIAS_KEYS.values() if col in rows}
            self._selected[(lo, hi)] = {i: self._bias_rows(p, columns, m) for i, p in enumerate(params)
                                        if p.kind in ("bias", "timing")}
        selected = self._selected[(lo, hi)]
        if any(p.kind == "bias" for p in params):
            per_bias = (ev.partials["bias"][:, 0] if "bias" in ev.partials else np.ones(m)) \
                / np.where(rows["unit"].to_numpy() == "rad", 1.0, ev.to_los)  # angles stay angles
        rate = tag_rate(rows, trajs, setup, ev.value) if any(p.kind == "timing" for p in params) else None
        for i, p in enumerate(params):
            if p.kind == "timing":
                H_lin[selected[i], i] = -rate[selected[i]]
            elif p.kind == "bias":
                H_lin[selected[i], i] = per_bias[selected[i]]
            elif p.kind == "station" and f"station:{p.owner}" in ev.partials:
                H_lin[:, i] = ev.partials[f"station:{p.owner}"][:, "xyz".index(p.info["axis"])]
            elif p.kind == "media" and "media_scale" in ev.partials:
                H_lin[:, i] = ev.partials["media_scale"][:, 0]
            elif p.kind == "clock" and f"oscillator:{p.owner}" in ev.partials:
                H_lin[:, i] = ev.partials[f"oscillator:{p.owner}"][:, ("y0", "y1").index(p.info["oscillator"])]
        return value, ev.to_los, ev.status, G_x, G_p, H_lin

    @staticmethod
    def _bias_rows(p, columns: dict, m: int) -> np.ndarray:
        """Rows (of m) a bias parameter applies to, from the rows' columns as arrays."""
        sel = np.ones(m, bool)
        for key, col in _BIAS_KEYS.items():
            if key in p.info:
                sel &= columns[col] == p.info[key]
        return sel

    # -- the Problem protocol -------------------------------------------
    def predict(self, t0, x0, rows):
        """Computed values (row units) of rows (positions, all in one segment) and H = d value / d x(t0)."""
        x0 = np.asarray(x0, float)
        seg = self.segment(t0, x0)
        loc = np.asarray(rows) - seg.lo
        if loc.size and (loc.min() < 0 or loc.max() >= seg.hi - seg.lo):
            raise ValueError(f"rows outside the segment [{seg.a}, {seg.b}) of t0={t0}")
        if loc.size and loc[-1] - loc[0] == loc.size - 1:   # consecutive rows (the filter's blocks): a slice
            loc = slice(int(loc[0]), int(loc[-1]) + 1)
        H = seg.H_lin[loc].copy()
        computed = seg.value[loc] + H[:, self._lin_idx] @ x0[self._lin_idx]
        for sc, traj in seg.trajs.items():
            _, _, Phi0_inv, S0 = traj.at(t0)
            Hx = seg.G_x[sc][loc] @ Phi0_inv
            H[:, self._state[sc]] = Hx
            H[:, seg.pidx[sc]] += seg.G_p[sc][loc] - Hx @ S0
        return computed, H

    def transition(self, t0, t1, x0):
        """Reference at t1 (parameters held) and Phi = d x(t1) / d x(t0) over the registry."""
        x0 = np.asarray(x0, float)
        seg = self.segment(t0, x0)
        if t1 > seg.b:
            raise ValueError(f"interval [{t0}, {t1}] crosses the segment end {seg.b}")
        x1, Phi = x0.copy(), np.eye(x0.size)
        for sc, traj in seg.trajs.items():
            st = self._state[sc]
            _, _, Phi0_inv, S0 = traj.at(t0)
            x_1, Phi1, _, S1 = traj.at(t1)
            M = Phi1 @ Phi0_inv
            x1[st] = x_1
            Phi[st, st] = M
            Phi[st, seg.pidx[sc]] = S1 - M @ S0
        self._last = (seg, x1)
        return x1, Phi

    def span(self, epochs, x0, bounds):
        """:meth:`predict` and :meth:`transition` over the grid intervals from ``epochs[0]`` (reference ``x0``)
        up to ``epochs[-1]`` or the segment's end, at once: (references at the J + 1 epochs (J + 1, n),
        Phi (J, n, n), computed values and H of the rows ``bounds[0]:bounds[J]``), ``bounds`` the rows'
        bounds at the epochs."""
        x0 = np.asarray(x0, float)
        seg = self.segment(epochs[0], x0)
        J = int(np.searchsorted(epochs, seg.b, "right")) - 1
        ts, n = np.asarray(epochs[:J + 1], float), x0.size
        loc = slice(bounds[0] - seg.lo, bounds[J] - seg.lo)
        k_row = np.repeat(np.arange(J), np.diff(bounds[:J + 1]))
        H = seg.H_lin[loc].copy()
        computed = seg.value[loc] + H[:, self._lin_idx] @ x0[self._lin_idx]
        refs, Phi = np.repeat(x0[None], J + 1, 0), np.repeat(np.eye(n)[None], J, 0)
        for sc, traj in seg.trajs.items():
            st, p = self._state[sc], seg.pidx[sc]
            x, Phi_t, Phi_inv, S = traj.at_many(ts)
            M = Phi_t[1:] @ Phi_inv[:-1]
            refs[1:, st] = x[1:]
            Phi[:, st, st] = M
            Phi[:, st, p] = S[1:] - M @ S[:-1]
            Hx = np.einsum("ri,rij->rj", seg.G_x[sc][loc], Phi_inv[k_row])
            H[:, st] = Hx
            H[:, p] += seg.G_p[sc][loc] - np.einsum("ri,rip->rp", Hx, S[k_row])
        self._last = (seg, refs[-1])
        return refs, Phi, computed, H

    # -- whole-arc reference --------------------------------------------
    def reference(self, x0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(computed, to_los, status) of every row on the reference from ``x0`` at ``t_start``
        with every parameter held (the fit's first pass when stochastic means are zero)."""
        n = self.times.size
        value, to_los, status = np.full(n, np.nan), np.full(n, np.nan), np.full(n, "", object)
        t, x = self.t_start, np.asarray(x0, float)
        while t < self.t_end:
            seg = self.segment(t, x)
            s = slice(seg.lo, seg.hi)
            value[s] = seg.value + seg.H_lin[:, self._lin_idx] @ x[self._lin_idx]
            to_los[s], status[s] = seg.to_los, seg.status
            x, _ = self.transition(t, seg.b, x)
            t = seg.b
        return value, to_los, status
