"""One media model per run: troposphere and ionosphere path delays of a ground leg.

Sources, in order of preference, with the label each value carries:

- troposphere zenith delays: TRK-2-23 .TRO adjustments on top of the DSN
  seasonal model (``"<file>:<line> ... + DSN-seasonal"``); the seasonal model
  alone where no .TRO card covers a DSN time (``"DSN-seasonal (no TRO)"``);
  the Saastamoinen standard atmosphere at the site for non-DSN stations
  (``"standard-atmosphere"``); mapped to the elevation with Niell (1996).
  With ``standard_troposphere="modified-saastamoinen"`` non-DSN stations get
  Orekit's modified Saastamoinen slant delay on its standard atmosphere
  instead (``"standard-atmosphere (modified Saastamoinen)"``).
- ionosphere: TRK-2-23 .ION line-of-sight cards for the spacecraft — "the
  one-way ionospheric range delay to the spacecraft, in meters at a nominal
  S-band frequency of 2295 MHz", one normalized polynomial per pass from rise
  to set (TRK-2-23 product description, PDS MESSENGER RSS ION) — scaled by
  ``(f_S / f)^2``; else IONEX maps; else none (0 m, labelled ``"none"``).

Delays are group (range) delays in m along one leg; a caller wanting the
phase delay negates the ionosphere part.
"""

from __future__ import annotations

import numpy as np

from odpipe.media import modified_saastamoinen, niell, saastamoinen
from odpipe.media.ionosphere import IonexModel, group_delay
from odpipe.media.seasonal import dsn_seasonal
from parsers.trk223 import CalibrationSet, complex_of

F_S_BAND_HZ = 2295e6    # TRK-2-23 CHPART calibrations are range delays at S-band downlink (2295 MHz)
STANDARD_TROPOSPHERES = ("saastamoinen-niell", "modified-saastamoinen")


class MediaModel:
    """Troposphere and ionosphere leg delays from calibrations, maps or climatology."""

    def __init__(self, calibrations: CalibrationSet | None = None, ionex: IonexModel | None = None,
                 standard_troposphere: str = "saastamoinen-niell"):
        if standard_troposphere not in STANDARD_TROPOSPHERES:
            raise ValueError(f"standard troposphere {standard_troposphere!r}: one of {STANDARD_TROPOSPHERES}")
        self.standard_troposphere = standard_troposphere
        self.calibrations = calibrations or CalibrationSet([])
        self.seasonal = dsn_seasonal()
        self.ionex = ionex

    def troposphere(self, station, t_utc, elevation, latitude, height_m):
        """(slant delay m, source label per sample) at one station."""
        t = np.asarray(t_utc, dtype="datetime64[ns]")
        doy = (t - t.astype("datetime64[Y]")) / np.timedelta64(1, "D") + 1.0
        mh = niell.hydrostatic(elevation, latitude, height_m, doy)
        mw = niell.wet(elevation, latitude)
        if complex_of(station):
            names = np.array([c.label + " + DSN-seasonal" for c in self.calibrations.cards]
                             + ["DSN-seasonal (no TRO)"], dtype=object)
            zd, label = {}, np.full(t.shape, len(names) - 1)
            for part, model in (("wet", "WET NUPART"), ("dry", "DRY NUPART")):
                adj, used = self.calibrations.evaluate(model, station, t)
                zd[part] = self.seasonal.zenith_delay(station, t, part) + np.where(used >= 0, adj, 0.0)
                label = np.where(used >= 0, used, label)
            return zd["dry"] * mh + zd["wet"] * mw, names[label]
        if self.standard_troposphere == "modified-saastamoinen":
            return (np.broadcast_to(modified_saastamoinen.standard_slant_delay(elevation, height_m), t.shape),
                    np.full(t.shape, "standard-atmosphere (modified Saastamoinen)", dtype=object))
        dry, wet = saastamoinen.standard_zenith_delays(latitude, height_m)
        return dry * mh + wet * mw, np.full(t.shape, "standard-atmosphere", dtype=object)

    def ionosphere(self, station, spacecraft, t_utc, elevation, azimuth, latitude, longitude, frequency_hz):
        """(group delay m, source label per sample) at one station for one spacecraft.

        ``latitude`` is geocentric (rad): IONEX's single layer is a sphere.
        """
        t = np.asarray(t_utc, dtype="datetime64[ns]")
        delay = np.full(t.shape, np.nan)
        label = np.full(t.shape, "none", dtype=object)
        if spacecraft not in (None, "") and len(self.calibrations):
            los, used = self.calibrations.evaluate("CHPART", station, t, spacecraft=spacecraft)
            ok = used >= 0
            delay[ok] = los[ok] * (F_S_BAND_HZ / np.broadcast_to(frequency_hz, t.shape)[ok]) ** 2
            names = np.array([c.label for c in self.calibrations.cards], dtype=object)
            label[ok] = names[used[ok]]
        if self.ionex is not None:
            todo = np.isnan(delay)
            stec = self.ionex.slant_tec(latitude, longitude, azimuth, elevation, t)
            fill = todo & np.isfinite(stec)
            f = np.broadcast_to(frequency_hz, t.shape)
            delay[fill] = group_delay(stec[fill], f[fill])
            label[fill] = "IONEX " + self.ionex.source
        return np.where(np.isnan(delay), 0.0, delay), label
