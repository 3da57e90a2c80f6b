"""Earth orientation parameters: UT1−UTC, polar motion, CIP offsets dX/dY, LOD.

Default source: the IERS tables shipped by ``astropy-iers-data`` — the
IERS 20 C04 series (``eopc04.1962-now``, final values, daily at 0h UTC) and,
after its last day, IERS Bulletin A (``finals2000A.all``, rapid values and
predictions). Values are interpolated with 4-point Lagrange polynomials;
UT1−UTC is interpolated as UT1−TAI so that leap seconds do not corrupt it.
The diurnal/semidiurnal ocean-tide terms (IERS Conventions 2010 §8.2, ≲0.5 mas,
≲0.05 ms) are added by default; the sub-diurnal libration terms (§5.5.1,
< 0.03 mas, < 3 µs: < 1 mm) are not.

Units out: s for UT1−UTC and LOD, rad for xp, yp, dX, dY.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

import astropy_iers_data
from odpipe.environment.eop_tides import ocean_tide_eop
from odpipe.constants import ARCSEC, MJD_UNIX, NS_PER_DAY, NS_PER_S, SECONDS_PER_DAY, TT_MINUS_TAI_NS
from odpipe.numerics.interpolation import lagrange4_uniform, on_uniform_grid
from parsers.leap_seconds import tai_minus_utc_ns
from odpipe.time.scales import as_utc_ns

_MJD_1972 = 41317
_TIDE_GRID_DAYS = 1.0 / 96.0


@dataclass(frozen=True)
class EOPValues:
    """EOP at a set of epochs: ut1_utc (s), xp, yp (rad), dx, dy (rad, CIP offsets w.r.t. IAU 2006/2000A), lod (s)."""

    ut1_utc: np.ndarray
    xp: np.ndarray
    yp: np.ndarray
    dx: np.ndarray
    dy: np.ndarray
    lod: np.ndarray


@dataclass(frozen=True)
class EOPTable:
    """Daily EOP nodes on a uniform MJD grid (UTC 0h), ready for interpolation."""

    mjd: np.ndarray       # days, uniform step 1
    ut1_tai: np.ndarray   # s
    xp: np.ndarray        # rad
    yp: np.ndarray        # rad
    dx: np.ndarray        # rad
    dy: np.ndarray        # rad
    lod: np.ndarray       # s
    source: str

    @classmethod
    def from_columns(cls, mjd, ut1_utc, xp, yp, dx, dy, lod, source: str) -> "EOPTable":
        mjd = np.asarray(mjd, dtype=float)
        step = np.diff(mjd)
        if mjd.size < 4 or np.any(np.abs(step - 1.0) > 1e-9):
            raise ValueError(f"{source}: EOP rows must be daily and contiguous (at least 4)")
        ns = np.round((mjd - MJD_UNIX) * NS_PER_DAY).astype(np.int64)
        ut1_tai = np.asarray(ut1_utc, float) - tai_minus_utc_ns(ns) * 1e-9
        return cls(mjd, ut1_tai, np.asarray(xp, float), np.asarray(yp, float), np.asarray(dx, float),
                   np.asarray(dy, float), np.asarray(lod, float), source)

    @property
    def span(self) -> tuple[np.datetime64, np.datetime64]:
        """First and last tabulated epochs (UTC)."""
        to = lambda m: np.datetime64(int(round((m - MJD_UNIX) * SECONDS_PER_DAY)), "s")  # noqa: E731
        return to(self.mjd[0]), to(self.mjd[-1])

    def at(self, epoch_utc, ocean_tides: bool = True) -> EOPValues:
        """Interpolated EOP at UTC epochs; ValueError naming the first epoch outside the table.

        ``ocean_tides`` adds the diurnal/semidiurnal ocean-tide terms of xp, yp and UT1
        (IERS ORTHO_EOP, :mod:`odpipe.environment.eop_tides`), which daily series omit.
        """
        ns = as_utc_ns(epoch_utc)
        mjd = ns / NS_PER_DAY + MJD_UNIX
        bad = (mjd < self.mjd[0]) | (mjd > self.mjd[-1])
        if np.any(bad):
            first = np.datetime64(int(np.asarray(ns)[bad].ravel()[0]), "ns")
            lo, hi = self.span
            raise ValueError(f"EOP requested at {first} UTC, outside the table {self.source} ({lo} .. {hi})")
        cols = np.stack([self.ut1_tai, self.xp, self.yp, self.dx, self.dy, self.lod], axis=-1)
        v = lagrange4_uniform(self.mjd[0], 1.0, cols, np.ravel(mjd)).reshape(np.shape(mjd) + (6,))
        dat = tai_minus_utc_ns(ns) * 1e-9
        ut1_utc, xp, yp = v[..., 0] + dat, v[..., 1], v[..., 2]
        if ocean_tides:
            tt_mjd = mjd + (dat + TT_MINUS_TAI_NS / NS_PER_S) / SECONDS_PER_DAY
            tides = on_uniform_grid(lambda d: np.stack(ocean_tide_eop(d), axis=-1), tt_mjd,
                                    _TIDE_GRID_DAYS)  # shortest period ~0.5 d: grid error < 1e-5 relative
            dx, dy, dut1 = tides[..., 0], tides[..., 1], tides[..., 2]
            ut1_utc, xp, yp = ut1_utc + dut1 * 1e-6, xp + dx * 1e-6 * ARCSEC, yp + dy * 1e-6 * ARCSEC
        return EOPValues(ut1_utc, xp, yp, v[..., 3], v[..., 4], v[..., 5])


def iers_data_dir() -> Path:
    """Folder of the IERS files shipped by astropy-iers-data."""
    return Path(astropy_iers_data.__file__).parent / "data"


def _read_c04(path: Path) -> dict[str, np.ndarray]:
    a = np.loadtxt(path, comments="#", usecols=(4, 5, 6, 7, 8, 9, 12))
    return {"mjd": a[:, 0], "xp": a[:, 1] * ARCSEC, "yp": a[:, 2] * ARCSEC, "ut1_utc": a[:, 3],
            "dx": a[:, 4] * ARCSEC, "dy": a[:, 5] * ARCSEC, "lod": a[:, 6]}


def _field(line: str, a: int, b: int) -> float:
    text = line[a:b].strip()
    return float(text) if text else np.nan


def _read_finals2000a(path: Path) -> dict[str, np.ndarray]:
    """Bulletin A columns of finals2000A.all (IERS readme.finals2000A layout)."""
    rows = []
    for line in path.read_text().splitlines():
        if len(line) < 68 or not line[58:68].strip():
            continue
        rows.append((_field(line, 7, 15), _field(line, 18, 27), _field(line, 37, 46), _field(line, 58, 68),
                     _field(line, 79, 86), _field(line, 97, 106), _field(line, 116, 125)))
    a = np.array(rows)
    return {"mjd": a[:, 0], "xp": a[:, 1] * ARCSEC, "yp": a[:, 2] * ARCSEC, "ut1_utc": a[:, 3],
            "lod": a[:, 4] * 1e-3, "dx": a[:, 5] * 1e-3 * ARCSEC, "dy": a[:, 6] * 1e-3 * ARCSEC}


def _fill_forward(x: np.ndarray) -> np.ndarray:
    """Carry the last known value over trailing/inner NaNs (Bulletin A predictions lack dX/dY/LOD)."""
    idx = np.where(np.isnan(x), 0, np.arange(x.size))
    np.maximum.accumulate(idx, out=idx)
    return x[idx]


@lru_cache(maxsize=1)
def default_eop() -> EOPTable:
    """IERS 20 C04 from 1972 extended by Bulletin A (finals2000A.all) after C04's last day."""
    d = iers_data_dir()
    c04 = _read_c04(d / "eopc04.1962-now")
    keep = c04["mjd"] >= _MJD_1972  # integer-second UTC only
    c04 = {k: v[keep] for k, v in c04.items()}
    fa = _read_finals2000a(d / "finals2000A.all")
    after = fa["mjd"] > c04["mjd"][-1]
    cols = {k: np.concatenate([c04[k], _fill_forward(fa[k])[after]]) for k in c04}
    return EOPTable.from_columns(source=f"{d / 'eopc04.1962-now'} + finals2000A.all", **cols)


def eop_at(epoch_utc, ocean_tides: bool = True) -> EOPValues:
    """EOP from the default IERS tables at UTC epochs (with ocean-tide terms unless disabled)."""
    return default_eop().at(epoch_utc, ocean_tides)


def read_jpl_eop(path) -> EOPTable:
    """EOP table from a JPL/DSN EOP file (``EOP=`` rows: MJD, PM x, PM y mas, TAI−UT1 s, TAI−UTC s, dPsi, dEps mas).

    The file's dPsi/dEps are offsets from the IAU 1980 nutation and do not apply to
    IAU 2006/2000A, so dX = dY = 0 here. LOD is the central difference of UT1.
    """
    path = Path(path)
    rows = []
    in_data = False
    for lineno, line in enumerate(path.read_text().splitlines(), start=1):
        body = line.split("$", 1)[0].strip()
        if body.startswith("EOP="):
            in_data = True
            body = body[4:].strip()
        if not in_data or not body:
            continue
        fields = [f for f in body.split(",") if f.strip()]
        if len(fields) != 7:
            raise ValueError(f"{path}:{lineno}: expected 7 comma-separated EOP fields, got {len(fields)}: {line!r}")
        try:
            rows.append([float(f) for f in fields])
        except ValueError as err:
            raise ValueError(f"{path}:{lineno}: non-numeric EOP field in {line!r}") from err
    if not rows:
        raise ValueError(f"{path}: no 'EOP=' data rows")
    a = np.array(rows)
    ut1_utc = a[:, 4] - a[:, 3]
    ut1_tai = -a[:, 3]
    lod = -np.gradient(ut1_tai, a[:, 0])  # s of excess length per day
    zero = np.zeros(len(a))
    mas = 1e-3 * ARCSEC
    return EOPTable.from_columns(a[:, 0], ut1_utc, a[:, 1] * mas, a[:, 2] * mas, zero, zero, lod, str(path))
