"""Tracking stations: catalog, plate motion, geodetic coordinates, topocentric az/el/range.

``StationCatalog.default()`` reads the project's own catalog
``odpipe/environment/data/stations.csv`` (DSN antennas from JPL 810-005
module 301 Rev. M, ITRF93 epoch 2003.0 with plate motion; ESTRACK antennas).
``catalog.with_csv(path)`` adds or overrides stations from a user CSV with
columns ``name`` (or ``station``) and either ``x_m, y_m, z_m`` (ITRS, m) or
``lat_deg, lon_deg, h_m`` (WGS84 geodetic); optional ``vx_m_per_yr`` (or
``vx``), ``vy…``, ``vz…`` and ``epoch_year`` (decimal year, default 2003.0).

``catalog.with_sinex(path, at, eccentricities)`` adds the sites of a SINEX
solution (e.g. ILRS SLRF2014) by their 4-digit code, e.g. '7090'.

Station ids: 'DSS-14', 'DSS14', 'DSS 14', the ODF/TRK-2-34 integer 14, or an
alias listed in the catalog (e.g. ESTRACK 'NNO').
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import erfa
import numpy as np
import pandas as pd

from odpipe.constants import DAYS_PER_JULIAN_YEAR, J2000, SECONDS_PER_DAY
from odpipe.frames.epochs import utc_and_tt

CATALOG_FILE = Path(__file__).parent / "data" / "stations.csv"
JULIAN_YEAR_S = DAYS_PER_JULIAN_YEAR * SECONDS_PER_DAY
WGS84 = 1  # ERFA ellipsoid id
GRS80 = 2


@lru_cache(maxsize=64)
def _calendar_year_s(year: float) -> float:
    """Seconds past J2000 of a decimal calendar year (e.g. 2003.0 = 2003-01-01T00:00)."""
    y = int(np.floor(year))
    start = np.datetime64(f"{y:04d}-01-01T00:00:00", "s")
    length = (np.datetime64(f"{y + 1:04d}-01-01", "s") - start).astype(float)
    t = (start - J2000.astype("datetime64[s]")).astype(float)
    return t + (year - y) * length


def geodetic_to_itrs(lat, lon, h, ellipsoid: int = WGS84) -> np.ndarray:
    """ITRS position (…,3) m from geodetic latitude, longitude (rad) and height (m)."""
    return erfa.gd2gc(ellipsoid, np.asarray(lon, float), np.asarray(lat, float), np.asarray(h, float))


def itrs_to_geodetic(r_itrs, ellipsoid: int = WGS84):
    """(lat rad, lon rad, h m) of ITRS positions (…,3) m."""
    lon, lat, h = erfa.gc2gd(ellipsoid, np.asarray(r_itrs, float))
    return lat, lon, h


def enu_matrix(lat, lon) -> np.ndarray:
    """Rotation ITRS → local east-north-up (…,3,3) at geodetic lat, lon (rad)."""
    sl, cl = np.sin(lat), np.cos(lat)
    so, co = np.sin(lon), np.cos(lon)
    z = np.zeros_like(sl)
    return np.stack([np.stack([-so, co, z], -1),
                     np.stack([-sl * co, -sl * so, cl], -1),
                     np.stack([cl * co, cl * so, sl], -1)], -2)


@dataclass(frozen=True)
class Station:
    """A ground antenna: ITRS position (m) at ``epoch_year`` and velocity (m/yr)."""

    name: str
    r_itrs: np.ndarray
    v_itrs_per_yr: np.ndarray = field(default_factory=lambda: np.zeros(3))
    epoch_year: float = 2003.0
    complex: str = ""
    aliases: tuple[str, ...] = ()

    @property
    def dss(self) -> int | None:
        """DSN station number (ODF/TRK-2-34 id) or None."""
        up = self.name.upper().replace(" ", "").replace("-", "")
        return int(up[3:]) if up.startswith("DSS") and up[3:].isdigit() else None

    def position_itrs(self, t=None) -> np.ndarray:
        """ITRS position (m) with plate motion at epochs ``t`` (datetime64 UTC or TDB s); epoch position if None."""
        if t is None:
            return self.r_itrs.copy()
        arr = np.asarray(t)
        # TDB seconds stand for TT here: 2 ms apart, nothing at plate-motion rates (cm/yr)
        tt_days = arr / SECONDS_PER_DAY if arr.dtype.kind in "fiu" else utc_and_tt(arr)[1]
        years = (np.asarray(tt_days) * SECONDS_PER_DAY - _calendar_year_s(self.epoch_year)) / JULIAN_YEAR_S
        return self.r_itrs + np.asarray(years)[..., None] * self.v_itrs_per_yr

    def geodetic(self, ellipsoid: int = WGS84):
        """(lat rad, lon rad, h m) of the epoch position."""
        return itrs_to_geodetic(self.r_itrs, ellipsoid)


def topocentric(station: Station, r_target_itrs, t=None):
    """(azimuth rad from north through east in [0, 2π), elevation rad, range m) of ITRS targets."""
    r0 = station.position_itrs(t)
    lat, lon, _ = itrs_to_geodetic(r0)
    d = np.asarray(r_target_itrs, float) - r0
    enu = np.einsum("...ij,...j->...i", enu_matrix(lat, lon), d)
    rng = np.linalg.norm(enu, axis=-1)
    az = np.mod(np.arctan2(enu[..., 0], enu[..., 1]), 2 * np.pi)
    el = np.arcsin(enu[..., 2] / rng)
    return az, el, rng


def _key(name) -> str:
    if isinstance(name, (int, np.integer)):
        return f"DSS{int(name)}"
    k = str(name).strip().upper().replace(" ", "").replace("-", "").replace("_", "")
    return f"DSS{int(k)}" if k.isdigit() else k


class StationCatalog:
    """Stations by name, DSS number or alias."""

    def __init__(self, stations: list[Station], source: str = ""):
        self.stations = {s.name: s for s in stations}
        self.source = source
        self._index = {}
        for s in stations:
            for k in (s.name, *s.aliases):
                self._index[_key(k)] = s.name

    @classmethod
    def default(cls) -> "StationCatalog":
        """The project's catalog (DSN per 810-005 Rev. M, ESTRACK)."""
        return cls.from_csv(CATALOG_FILE)

    @classmethod
    def from_csv(cls, path) -> "StationCatalog":
        """Catalog from a CSV file (columns described in the module docstring)."""
        return cls(_read_stations(Path(path)), str(path))

    def with_csv(self, path) -> "StationCatalog":
        """This catalog plus (overridden by) the stations of a CSV file."""
        merged = dict(self.stations)
        merged.update({s.name: s for s in _read_stations(Path(path))})
        return StationCatalog(list(merged.values()), f"{self.source} + {path}")

    def with_sinex(self, path, at, eccentricities=None) -> "StationCatalog":
        """This catalog plus the sites of a SINEX file whose solution span holds UTC ``at``, named by site code.

        Positions (ITRS of the file's frame, m) at each solution's reference epoch
        with its velocities; ``eccentricities`` (a SINEX SITE/ECCENTRICITY file)
        moves each marker to its instrument reference point (UNE turned to ITRS
        at the marker's WGS84 latitude and longitude).
        """
        from parsers import sinex

        ecc = sinex.read(eccentricities) if eccentricities is not None else None
        merged = dict(self.stations)
        for r in sinex.read(path).stations(at).itertuples():
            pos = np.array([r.x_m, r.y_m, r.z_m])
            e = ecc.eccentricity(r.code, at) if ecc is not None else None
            if e is not None:
                lat, lon, _ = itrs_to_geodetic(pos)
                une = e[["east_m", "north_m", "up_m"]].to_numpy(float)
                pos = pos + (une @ enu_matrix(lat, lon) if e["system"] == "UNE" else e[["x_m", "y_m", "z_m"]]
                             .to_numpy(float))
            ref = pd.Timestamp(r.ref_epoch)
            year_s = (pd.Timestamp(ref.year + 1, 1, 1) - pd.Timestamp(ref.year, 1, 1)).total_seconds()
            merged[r.code] = Station(r.code, pos, np.array([r.vx_m_per_yr, r.vy_m_per_yr, r.vz_m_per_yr]),
                                     ref.year + (ref - pd.Timestamp(ref.year, 1, 1)).total_seconds() / year_s)
        return StationCatalog(list(merged.values()), f"{self.source} + {path}")

    def __getitem__(self, name) -> Station:
        k = _key(name)
        if k not in self._index:
            raise KeyError(f"unknown station {name!r} in catalog {self.source}; known: {sorted(self.stations)}")
        return self.stations[self._index[k]]

    def __contains__(self, name) -> bool:
        return _key(name) in self._index

    def __iter__(self):
        return iter(self.stations.values())

    def __len__(self) -> int:
        return len(self.stations)


def _column(df: pd.DataFrame, *names, default=None):
    for n in names:
        if n in df.columns:
            return df[n]
    if default is None:
        raise ValueError(f"station file lacks column {names[0]!r} (looked for {names})")
    return pd.Series([default] * len(df), index=df.index)


def _read_stations(path: Path) -> list[Station]:
    if not path.is_file():
        raise FileNotFoundError(f"station catalog {path} does not exist")
    df = pd.read_csv(path, comment="#")
    names = _column(df, "name", "station")
    if {"x_m", "y_m", "z_m"} <= set(df.columns):
        r = df[["x_m", "y_m", "z_m"]].to_numpy(float)
    elif {"lat_deg", "lon_deg", "h_m"} <= set(df.columns):
        r = geodetic_to_itrs(np.radians(df.lat_deg.to_numpy(float)), np.radians(df.lon_deg.to_numpy(float)),
                             df.h_m.to_numpy(float))
    else:
        raise ValueError(f"{path}: need columns x_m,y_m,z_m or lat_deg,lon_deg,h_m")
    v = np.stack([pd.to_numeric(_column(df, f"v{c}_m_per_yr", f"v{c}", default=0.0), errors="coerce")
                  .fillna(0.0).to_numpy(float) for c in "xyz"], -1)
    epoch = pd.to_numeric(_column(df, "epoch_year", default=2003.0), errors="coerce").fillna(2003.0).to_numpy(float)
    cplx = _column(df, "complex", default="").astype(object).fillna("").astype(str)
    aliases = _column(df, "aliases", default="").astype(object).fillna("").astype(str)
    if np.any(~np.isfinite(r)):
        bad = names[~np.isfinite(r).all(axis=1)].iloc[0]
        raise ValueError(f"{path}: station {bad!r} has non-numeric coordinates")
    return [Station(str(n), r[i], v[i], float(epoch[i]), cplx.iloc[i],
                    tuple(a for a in aliases.iloc[i].split(";") if a))
            for i, n in enumerate(names)]
