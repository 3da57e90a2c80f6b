"""Moon body-fixed frames: principal axes (PA) from DE421 librations, mean Earth (ME), IAU model.

* ``moon_pa_to_icrf(t)`` — rotation PA → ICRF from the DE421 lunar libration
  Euler angles (φ, θ, ψ): ICRF→PA = R3(ψ)·R1(θ)·R3(φ). Source by default the
  ``de421`` package ('jpl-librations.npy', no kernel needed); or a binary PCK
  such as NAIF ``moon_pa_de421_1900-2050.bpc`` (same angles, frame 31006),
  given by path. The DE axes are the ICRF (SPICE's 'J2000' label; no frame
  bias is applied, as in SPICE).
* ``moon_me_to_pa()`` — constant ME → PA rotation of NAIF ``moon_080317.tf``
  (MOON_ME_DE421: angles 67.92″, 78.56″, 0.30″ about axes 3, 2, 1).
* ``moon_iau_to_icrf(t)`` — IAU WGCCRE 2009 model (Archinal et al. 2011, the
  constants of NAIF ``pck00010.tpc``): a fallback accurate to ~100 m on the
  lunar surface relative to PA/ME.

``t`` is TDB seconds past J2000 (float); results (N,3,3), or (3,3) for scalars.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from odpipe.constants import ARCSEC, DAYS_PER_JULIAN_CENTURY, SECONDS_PER_DAY
from odpipe.environment.ephemeris import jd_split
from odpipe.frames.rotations import frame_rotation

_DEG = np.pi / 180.0
# MOON_ME_DE421 relative to MOON_PA_DE421 (NAIF moon_080317.tf, TKFRAME_31007), arcsec, axes (3, 2, 1)
ME_DE421_ANGLES_ARCSEC = (67.92, 78.56, 0.30)


@lru_cache(maxsize=4)
def _libration_source(path: str | None):
    """Callable (jd1, jd2) -> (3, N) Euler angles (rad) from the de421 package or a binary PCK."""
    if path is None:
        import de421
        from jplephem.ephem import Ephemeris as PackageEphemeris
        eph = PackageEphemeris(de421)
        return lambda jd1, jd2: eph.position("librations", jd1, jd2)
    from jplephem.pck import PCK
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"lunar orientation kernel {p} does not exist")
    seg = PCK.open(str(p)).segments[0]
    return lambda jd1, jd2: seg.compute(jd1, jd2, derivative=False)


def moon_pa_to_icrf(t_tdb, kernel: str | Path | None = None) -> np.ndarray:
    """Rotation matrices Moon PA → ICRF at TDB s past J2000 (DE421 librations)."""
    t = np.asarray(t_tdb, dtype=float)
    jd1, jd2 = jd_split(t)
    try:
        angles = _libration_source(None if kernel is None else str(kernel))(jd1, jd2)
    except ValueError as err:  # jplephem's DateError is a ValueError
        raise ValueError(f"lunar librations unavailable for TDB {t.min():.1f}..{t.max():.1f} s past J2000: "
                         f"{err}") from err
    phi, theta, psi = np.reshape(angles, (3, -1))
    icrf_to_pa = frame_rotation(3, psi) @ frame_rotation(1, theta) @ frame_rotation(3, phi)
    return np.swapaxes(icrf_to_pa, -1, -2).reshape(t.shape + (3, 3))


def moon_me_to_pa() -> np.ndarray:
    """Constant rotation Moon ME → PA (DE421 realization, NAIF moon_080317.tf)."""
    a3, a2, a1 = (x * ARCSEC for x in ME_DE421_ANGLES_ARCSEC)
    # SPICE TKFRAME convention: the rotation maps the frame (ME) to its RELATIVE frame (PA)
    return frame_rotation(3, a3) @ frame_rotation(2, a2) @ frame_rotation(1, a1)


def moon_me_to_icrf(t_tdb, kernel: str | Path | None = None) -> np.ndarray:
    """Rotation matrices Moon ME → ICRF at TDB s past J2000."""
    return moon_pa_to_icrf(t_tdb, kernel) @ moon_me_to_pa()


# IAU WGCCRE 2009 lunar model (Archinal et al. 2011; NAIF pck00010.tpc): deg, deg/century, deg/day
_E_ANGLES = np.array([
    [125.045, -1935.5364525], [250.089, -3871.0729050], [260.008, 475263.3328725],
    [176.625, 487269.6299850], [357.529, 35999.0509575], [311.589, 964468.4993100],
    [134.963, 477198.8693250], [276.617, 12006.3007650], [34.226, 63863.5132425],
    [15.134, -5806.6093575], [119.743, 131.8406400], [239.961, 6003.1503825],
    [25.053, 473327.7964200]])
_RA = (269.9949, 0.0031, np.array([-3.8787, -0.1204, 0.0700, -0.0172, 0.0, 0.0072, 0.0, 0.0, 0.0, -0.0052,
                                   0.0, 0.0, 0.0043]))
_DEC = (66.5392, 0.0130, np.array([1.5419, 0.0239, -0.0278, 0.0068, 0.0, -0.0029, 0.0009, 0.0, 0.0, 0.0008,
                                   0.0, 0.0, -0.0009]))
_PM = (38.3213, 13.17635815, -1.4e-12, np.array([3.5610, 0.1208, -0.0642, 0.0158, 0.0252, -0.0066, -0.0047,
                                                 -0.0046, 0.0028, 0.0052, 0.0040, 0.0019, -0.0044]))


def moon_iau_to_icrf(t_tdb) -> np.ndarray:
    """Rotation matrices IAU_MOON → ICRF (IAU 2009 model) at TDB s past J2000."""
    t = np.asarray(t_tdb, dtype=float)
    d = t / SECONDS_PER_DAY
    cent = d / DAYS_PER_JULIAN_CENTURY
    e = (_E_ANGLES[:, 0] + _E_ANGLES[:, 1] * cent[..., None]) * _DEG
    ra = _RA[0] + _RA[1] * cent + np.sin(e) @ _RA[2]
    dec = _DEC[0] + _DEC[1] * cent + np.cos(e) @ _DEC[2]
    w = _PM[0] + _PM[1] * d + _PM[2] * d**2 + np.sin(e) @ _PM[3]
    icrf_to_body = (frame_rotation(3, w * _DEG) @ frame_rotation(1, (90.0 - dec) * _DEG)
                    @ frame_rotation(3, (90.0 + ra) * _DEG))
    return np.swapaxes(icrf_to_body, -1, -2)
