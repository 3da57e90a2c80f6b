"""A Klobuchar-size ionosphere, to size the error of leaving the ionosphere out (error budget).

The GPS broadcast model (Klobuchar 1987; IS-GPS-200 §20.3.3.5.2.5): a thin shell at 350 km, a cosine
day bump of amplitude AMP and period PER (polynomials in geomagnetic latitude with coefficients alpha,
beta) peaking at 14:00 local time over a 5 ns (L1) night floor, times the obliquity
F = 1 + 16 (0.53 - E)^3, angles in semicircles. Its delay at L1 is turned to TEC so that
:class:`odpipe.media.model.MediaModel` scales it to each leg's frequency like an IONEX map.

No broadcast coefficients for the GRAIL days are in the data: :data:`RINEX_EXAMPLE` is the set printed
in the RINEX 2.11 navigation-file example, a daytime peak near 30 TECU at mid-latitudes, a size typical
of 2012 (rising solar cycle 24) and used here as that, a size, not a calibration.
"""

from __future__ import annotations

import numpy as np

C = 299792458.0          # m/s
F_L1 = 1575.42e6         # Hz
K_IONO = 40.3e16         # m Hz^2 per TECU (group delay = K TEC / f^2)
RINEX_EXAMPLE = ((0.1676e-07, 0.2235e-07, -0.1192e-06, -0.1192e-06),
                 (0.1208e+06, 0.1310e+06, -0.1310e+06, -0.1966e+06))


class KlobucharIonosphere:
    """Slant TEC (TECU) of the Klobuchar model with coefficients ``alpha`` (s, s/sc, ...) and
    ``beta`` (s, s/sc, ...); ``scale`` multiplies it (1 = the model). Duck-types the IONEX model."""

    def __init__(self, alpha=RINEX_EXAMPLE[0], beta=RINEX_EXAMPLE[1], scale: float = 1.0):
        self.alpha, self.beta, self.scale = np.asarray(alpha, float), np.asarray(beta, float), float(scale)
        self.source = f"Klobuchar x{scale:g}"

    def l1_delay(self, latitude, longitude, azimuth, elevation, t_utc):
        """Slant group delay at L1 (s): latitude, longitude, azimuth, elevation in rad, UTC datetime64."""
        e = np.asarray(elevation, float) / np.pi
        psi = 0.0137 / (e + 0.11) - 0.022
        phi_i = np.clip(np.asarray(latitude) / np.pi + psi * np.cos(azimuth), -0.416, 0.416)
        lam_i = np.asarray(longitude) / np.pi + psi * np.sin(azimuth) / np.cos(phi_i * np.pi)
        phi_m = phi_i + 0.064 * np.cos((lam_i - 1.617) * np.pi)
        t = np.asarray(t_utc, "datetime64[ns]")
        sod = (t - t.astype("datetime64[D]")) / np.timedelta64(1, "s")
        local = np.mod(43200.0 * lam_i + sod, 86400.0)
        powers = phi_m[..., None] ** np.arange(4)
        amp = np.maximum(powers @ self.alpha, 0.0)
        per = np.maximum(powers @ self.beta, 72000.0)
        x = 2 * np.pi * (local - 50400.0) / per
        f = 1.0 + 16.0 * (0.53 - e) ** 3
        bump = np.where(np.abs(x) < 1.57, amp * (1 - x**2 / 2 + x**4 / 24), 0.0)
        return f * (5e-9 + bump)

    def slant_tec(self, latitude, longitude, azimuth, elevation, t_utc):
        """Slant TEC (TECU) along az/el (rad) from a site at UTC times, times ``scale``."""
        return self.scale * self.l1_delay(latitude, longitude, azimuth, elevation, t_utc) * C * F_L1**2 / K_IONO
