"""A simulated case description (TOML), e.g. ``runs/artemis_p2_like.toml``.

Schema (SI units unless the key says otherwise; times UTC ISO 8601)::

    name, seed, start, days, spacecraft (DSN id, int), naif_id (int, negative)
    [orbit]        point = 1|2 (Earth-Moon L1/L2), amplitude (CRTBP units, planar Lyapunov)
    [spacecraft]   mass_kg, radius_m, length_m, rho_s, rho_d, spin_axis ([x,y,z] ICRF),
                   spin_rpm, antenna_offset_m (0: no spin signature in the Doppler)
    [stochastic]   sigma (m/s^2 per RTN axis), tau_s (Gauss-Markov time; 0 = white), batch_s
    [station_keeping] first_days, every_days (epochs after the start), gap_days (list), horizon_days
                   (designed at run time: perpendicular x-z crossing after gap, see odpipe.simulate.stationkeeping)
    [[maneuver]]   name, epoch, kind (e.g. 'attitude'), dv ([x,y,z] ICRF m/s, designed)
    [execution]    sigma_magnitude (fraction), sigma_pointing_deg (per maneuver)
    [media]        sigma_wet_m, sigma_dry_m (per-day deviations from the DSN seasonal model),
                   sigma_ion_m (S-band line-of-sight delay scale per DSN pass)
    [[network]]    station, format ('trk234'|'utdf'), pad (UTDF pad id), band, uplink_hz,
                   every_days, offset_days, passes (per tracking day), pass_s, mask_deg,
                   doppler_count_s, sigma_doppler (m/s), range_step_s (0: no range),
                   sigma_range (m), range_bias_sigma (m, per pass), ramp_rate_sigma (Hz/s; >0: ramped)
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class Network:
    station: str
    format: str = "trk234"
    pad: int = 0
    band: str = "S"
    uplink_hz: float = 2.0e9
    every_days: float = 2.0
    offset_days: float = 0.0
    passes: int = 1
    pass_s: float = 12600.0
    mask_deg: float = 10.0
    doppler_count_s: float = 60.0
    sigma_doppler: float = 1e-4
    range_step_s: float = 0.0
    sigma_range: float = 2.0
    range_bias_sigma: float = 0.0
    ramp_rate_sigma: float = 0.0


@dataclass(frozen=True)
class Case:
    name: str
    seed: int
    start: np.datetime64
    days: float
    spacecraft: int
    naif_id: int
    orbit: dict
    body: dict
    stochastic: dict
    maneuvers: list
    execution: dict
    media: dict
    station_keeping: dict
    networks: tuple = field(default_factory=tuple)

    @property
    def end(self) -> np.datetime64:
        return self.start + np.timedelta64(int(self.days * 86400e9), "ns")

    def station_keeping_epochs(self) -> np.ndarray:
        """UTC epochs of the station-keeping maneuvers inside the case span."""
        sk = self.station_keeping
        days = np.arange(float(sk["first_days"]), self.days, float(sk["every_days"]))
        return self.start + (days * 86400e9).astype("timedelta64[ns]")

    def shortened(self, days: float) -> "Case":
        """The same case over its first ``days`` (maneuvers after the end dropped)."""
        end = self.start + np.timedelta64(int(days * 86400e9), "ns")
        return replace(self, days=days, maneuvers=[m for m in self.maneuvers if m["epoch"] < end])


def load(path) -> Case:
    """Read a case file (schema in the module docstring)."""
    d = tomllib.loads(Path(path).read_text())

    def utc(v):
        return np.datetime64(str(v).replace("Z", "").replace("+00:00", ""), "ns")

    mans = [dict(m, epoch=utc(m["epoch"]), dv=np.asarray(m["dv"], float)) for m in d.get("maneuver", [])]
    return Case(d["name"], int(d["seed"]), utc(d["start"]), float(d["days"]), int(d["spacecraft"]),
                int(d["naif_id"]), d["orbit"], d["spacecraft_model"], d["stochastic"],
                sorted(mans, key=lambda m: m["epoch"]), d["execution"], d["media"],
                d["station_keeping"], tuple(Network(**n) for n in d["network"]))
