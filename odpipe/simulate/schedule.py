"""Tracking passes and sample epochs from visibility and cadence rules.

A :class:`TrackingPlan` tracks from each of its stations whenever the spacecraft is above the
mask (:func:`visible_epochs`). A network rule (:class:`odpipe.simulate.case.Network`) tracks on days
``offset_days + k * every_days`` after the case start. On a tracking day the
longest run of the spacecraft above the elevation mask (60-s grid, elevation
from the measurement models) holds the passes: one pass centred on the
culmination, or several of ``pass_s`` spread from rise to set. Inside a pass,
Doppler intervals of ``doppler_count_s`` are contiguous and tagged at their end;
range samples every ``range_step_s`` at reception.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from odpipe.constants import NS_PER_DAY, NS_PER_S
from odpipe.measurements import compute
from parsers.table import build

GRID_S = 60


class StateOnly:
    """A trajectory seen as a reference ephemeris (state and centre, no STM): the models give values only."""

    def __init__(self, trajectory):
        self.center = trajectory.center
        self.state = trajectory.state


def elevation(traj, setup, station: str, spacecraft: str, epochs: np.ndarray) -> np.ndarray:
    """Elevation (rad) of the spacecraft seen from ``station`` at reception times ``epochs`` (UTC)."""
    rows = build(epochs.size, epoch=epochs, observable="angle_el", unit="rad", station_rx=station,
                 station_tx=station, spacecraft=spacecraft, tag="receive", count_time=0.0)
    return compute(rows, {spacecraft: StateOnly(traj)}, setup).value


@dataclass(frozen=True)
class TrackingPlan:
    """What to simulate: stations, span (UTC datetime64), cadences (s), mask (rad), noise (LOS units);
    doppler: 'doppler_2way' or 'doppler_1way' (reference frequency ``uplink_hz``)."""

    stations: tuple
    start: np.datetime64
    end: np.datetime64
    doppler_step: float = 60.0
    range_step: float = 600.0
    min_elevation: float = np.radians(10.0)
    sigma_doppler: float = 1e-4          # m/s
    sigma_range: float = 1.0             # m
    range_bias_sigma: float = 0.0        # m, one draw per pass
    uplink_hz: float = 7.16e9
    band: str = "X"
    spacecraft: str = "SC"
    doppler: str = "doppler_2way"


def visible_epochs(traj, plan: TrackingPlan, setup) -> dict:
    """Per station: candidate epochs (UTC, every ``doppler_step``) and their pass ids (-1: below the mask)."""
    step = np.timedelta64(int(plan.doppler_step * NS_PER_S), "ns")
    epochs = np.arange(np.datetime64(plan.start, "ns"), np.datetime64(plan.end, "ns") + step, step)
    out, next_pass = {}, 0
    for st in plan.stations:
        up = elevation(traj, setup, st, plan.spacecraft, epochs) > plan.min_elevation
        run = np.cumsum(np.diff(np.concatenate([[False], up])) == 1)
        out[st] = (epochs, np.where(up, run - 1 + next_pass, -1))
        next_pass += int(run[-1]) if run.size else 0
    return out


def passes(traj, setup, net, spacecraft: str, start: np.datetime64, end: np.datetime64) -> list[tuple]:
    """Pass windows [(start, end) datetime64[ns]] of one network rule."""
    mask = np.radians(net.mask_deg)
    out = []
    day = np.timedelta64(NS_PER_DAY, "ns")
    k = 0
    while True:
        d0 = start + np.timedelta64(int((net.offset_days + k * net.every_days) * NS_PER_DAY), "ns")
        k += 1
        if d0 >= end:
            return out
        grid = np.arange(d0, min(d0 + day, end), np.timedelta64(GRID_S * NS_PER_S, "ns"))
        up = elevation(traj, setup, net.station, spacecraft, grid) > mask
        if not up.any():
            continue
        edges = np.flatnonzero(np.diff(np.concatenate([[0], up.astype(int), [0]])))
        runs = edges.reshape(-1, 2)
        a, b = runs[np.argmax(runs[:, 1] - runs[:, 0])]
        rise, set_ = grid[a], grid[b - 1]
        length = np.timedelta64(int(net.pass_s * NS_PER_S), "ns")
        span = set_ - rise
        if net.passes == 1:
            mid = rise + (span - min(length, span)) // 2
            out.append((mid, mid + min(length, span)))
            continue
        room = (span - net.passes * length) // (net.passes - 1) if span > net.passes * length else None
        if room is None:
            length = span // net.passes
            room = np.timedelta64(0, "ns")
        for j in range(net.passes):
            s = rise + j * (length + room)
            out.append((s, s + length))


def sample_epochs(window: tuple, step_s: float) -> np.ndarray:
    """Epochs step_s apart from window start + step_s to the window end (interval ends / receptions)."""
    step = np.timedelta64(int(round(step_s * NS_PER_S)), "ns")
    return np.arange(window[0] + step, window[1] + np.timedelta64(1, "ns"), step)
