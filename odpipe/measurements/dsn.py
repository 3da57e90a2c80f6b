"""DSN radiometric observables (Moyer, DESCANSO Monograph 2, ch. 13), from light-time solutions.

Conventions, all tested:

* Time tags are reception times at the receiving station (UTC, ``t3``);
  light times are converted from TDB to station time (TT, = UTC + const) with
  each station's TDB - TT before they enter a phase integral or a range.
* Two- and three-way paths are ``[station_tx, spacecraft, station_rx]``
  solved with ``anchor='receive'``; the round-trip light time rho is in station seconds.
* **Range** (sequential or PN) in range units:
  ``R = F * integral(f_T dt, t1, t3) mod M`` with F the range-unit factor of the
  uplink band (:mod:`.bands`), f_T the transmitter's uplink (ramped or
  constant), t1 = t3 - rho - delay (station plus transponder delay, s).
  In metres: ``R = c (rho + delay) / 2``; in seconds (ODF type 41): ``rho + delay``.
  A row may read the uplink phase at an epoch s other than reception:
  ``R = F * integral(f_T dt, t1, s) mod M`` (``uplink_epoch``; MESSENGER's
  odf07155 has such passes, s = 599 s into the 20-min ramp segment of the tag).
  PN range uses the same range unit.
* **Two/three-way Doppler** (Hz), count interval [t3s, t3e] of Tc s, turnaround M2:
  ``F = (M2/Tc) [integral(f_R, t3s, t3e) - integral(f_T, t1s, t1e)]``,
  with f_R the receiver's reference: the same ramp as f_T by default, the
  receiver's own ramp, or a constant f_REF (ODF ramped data are referenced to
  the record's reference frequency: their values are M2 f_REF - f_received,
  checked on MESSENGER and Cassini ODFs where M2 (f_REF - f_T) is ~1 MHz; tudat's
  model of the same records is Moyer eq. 13-54, ``M2 f_REF - (M2/Tc) integral(f_T dt1)``).
  Data transmitted while the uplink is being acquired (retune, sweep) do not follow
  the ramp table and are edited (:mod:`odpipe.preprocess.uplink`).
  It is **positive when the spacecraft recedes** (the received
  frequency falls below M2 f). For a constant uplink it reduces to
  ``F = M2 f (rho_e - rho_s) / Tc``. Evaluated as
  ``(M2/Tc)[integral(f_T, t1e, t3e) - integral(f_T, t1s, t3s)]`` (+ the
  reference difference over [t3s, t3e]) so no 1e11-cycle terms cancel.
* **One-way Doppler** (Hz) against a spacecraft oscillator f_S(t) = f_S0 + df + fdot (t - t_ref) (t in TDB):
  ``F1 = f_ref - (1/Tc) integral(f_S dt, t2s, t2e)``, positive when receding;
  df and fdot are estimable. The spacecraft's proper time is not modelled
  (it is absorbed by df and fdot).
"""

from __future__ import annotations

import numpy as np

from odpipe.constants import C_LIGHT

from .computed import Computed, EventPartial

_ROLES = ("station_tx", "spacecraft", "station_rx")


def _events(sols_and_gains) -> list[EventPartial]:
    """Event partials of the three-node path for each (solution, gain) pair: gain * d(rho)/d(position)."""
    out = []
    for sol, gain in sols_and_gains:
        for i, role in enumerate(_ROLES):
            out.append(EventPartial(role, sol.epochs[:, i], gain[:, None] * sol.dlt_dr[:, i]))
    return out


def dsn_range(sol, uplink, station_tx, t3_utc, ru_factor, unit: str = "RU", delay_s=0.0, modulus=np.nan,
              uplink_epoch=None) -> Computed:
    """Two/three-way range (RU, m or s) of rows with reception epochs ``t3_utc`` (datetime64[ns]).

    ``uplink``: ramp store or :class:`ConstantUplink`; ``ru_factor``: F per row;
    ``modulus``: M in RU per row (NaN: no wrap); ``uplink_epoch``: UTC datetime64[ns] per row at which
    the range reads the uplink phase (RU only; NaT or None: reception). Parameters: 'bias' (unit) and
    'delay' (d value/d delay_s).
    """
    delay = np.broadcast_to(np.asarray(delay_s, dtype=float), sol.epochs[:, 0].shape)
    rho = sol.clock_time + delay
    if unit == "RU":
        f1 = uplink.frequency(station_tx, t3_utc, -rho)
        gain = np.asarray(ru_factor, dtype=float) * f1
        t3 = np.asarray(t3_utc, dtype="datetime64[ns]")
        read = t3 if uplink_epoch is None else np.where(np.isnat(uplink_epoch), t3, uplink_epoch)
        value = np.asarray(ru_factor, dtype=float) * uplink.phase(station_tx, t3, read, -rho, 0.0)
        m = np.broadcast_to(np.asarray(modulus, dtype=float), value.shape)
        value = np.where(np.isfinite(m), np.mod(value, np.where(np.isfinite(m), m, 1.0)), value)
    elif unit in ("m", "s"):
        gain = np.full(rho.shape, C_LIGHT / 2 if unit == "m" else 1.0)
        value = gain * rho
    else:
        raise ValueError(f"range unit must be 'RU', 'm' or 's', not {unit!r}")
    return Computed(value, unit, _events([(sol, gain)]), {"bias": np.ones_like(value), "delay": gain},
                    to_los=C_LIGHT / (2 * gain))


def dsn_doppler(sol_s, sol_e, uplink, station_tx, t3s_utc, t3e_utc, m2, reference=None,
                station_rx=None) -> Computed:
    """Two/three-way count-averaged Doppler (Hz) over [t3s, t3e] (UTC datetime64[ns]).

    ``sol_s``/``sol_e``: path solutions anchored at t3s and t3e; ``m2``: turnaround
    ratio per row; ``reference``: the receiver's reference f_R, either None (the
    transmitter's uplink), a ramp store (the receiver's own ramp, ``station_rx``)
    or constant frequencies per row (Hz; the ODF's reference frequency). Parameter: 'bias' (Hz).
    """
    tc = (np.asarray(t3e_utc, "datetime64[ns]") - np.asarray(t3s_utc, "datetime64[ns]")).astype(np.int64) * 1e-9
    m2 = np.broadcast_to(np.asarray(m2, dtype=float), tc.shape)
    rho_s, rho_e = sol_s.clock_time, sol_e.clock_time
    cycles = uplink.phase(station_tx, t3e_utc, t3e_utc, -rho_e, 0.0) - uplink.phase(station_tx, t3s_utc, t3s_utc,
                                                                                  -rho_s, 0.0)
    if reference is not None:  # + integral of (f_R - f_T) over the count interval at the receiver
        f_r = reference.phase(station_rx, t3s_utc, t3e_utc) if hasattr(reference, "phase") \
            else np.asarray(reference, dtype=float) * tc
        cycles = cycles + f_r - uplink.phase(station_tx, t3s_utc, t3e_utc)
    value = m2 / tc * cycles
    f1e = uplink.frequency(station_tx, t3e_utc, -rho_e)
    f1s = uplink.frequency(station_tx, t3s_utc, -rho_s)
    events = _events([(sol_e, m2 / tc * f1e), (sol_s, -m2 / tc * f1s)])
    return Computed(value, "Hz", events, {"bias": np.ones_like(value)}, to_los=C_LIGHT / (2 * m2 * f1e))


def one_way_doppler(sol_s, sol_e, f_ref, count_time, y0=0.0, y1=0.0, t_ref=0.0, proper=0.0) -> Computed:
    """One-way Doppler (Hz) of paths ``[spacecraft, station_rx]`` anchored at t3s and t3e.

    ``f_ref``: the station's reference, the transmitted frequency it expects (Hz). The spacecraft
    oscillator transmits ``f_ref (1 + y0 + y1 (t2 - t_ref))``: ``y0`` fractional frequency offset,
    ``y1`` its drift (1/s) about ``t_ref`` (TDB s), scalars or one per row (each row its oscillator,
    :mod:`.oscillators`); as fractions, one oscillator serves every band it drives.
    That frequency is in the spacecraft's proper time; ``proper`` (N,) is 1 - dτ/dt over the count
    (:func:`.nodes.proper_rate_offset`), which lowers it in TDB (±175 mm/s at X band about the Moon).
    Parameters: 'osc_y0', 'osc_y1' (the estimable oscillator terms), 'bias' (Hz).
    """
    tc = np.asarray(count_time, dtype=float)
    dtau = sol_e.light_time - sol_s.light_time
    dclk = sol_e.clock[:, -1] - sol_s.clock[:, -1]
    span = tc + dclk - dtau  # t2e - t2s, TDB s
    t2_mid = 0.5 * ((sol_s.epochs[:, 0] + sol_s.epoch_corr[:, 0]) + (sol_e.epochs[:, 0] + sol_e.epoch_corr[:, 0]))
    f_ref = np.asarray(f_ref, dtype=float)
    f_mean = f_ref * (1.0 + y0 + y1 * (t2_mid - t_ref)) * (1.0 - proper)
    value = (f_ref - f_mean) + f_mean * (dtau - dclk) / tc
    events = []
    for sol, sign in ((sol_e, 1.0), (sol_s, -1.0)):
        gain = sign * f_mean / tc
        events += [EventPartial("spacecraft", sol.epochs[:, 0], gain[:, None] * sol.dlt_dr[:, 0]),
                   EventPartial("station_rx", sol.epochs[:, 1], gain[:, None] * sol.dlt_dr[:, 1])]
    scale = -f_ref * (1.0 - proper) * span / tc
    params = {"osc_y0": scale, "osc_y1": scale * (t2_mid - t_ref),
              "bias": np.ones_like(value)}
    return Computed(value, "Hz", events, params, to_los=C_LIGHT / f_mean)
