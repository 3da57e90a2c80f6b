"""TRK-2-34 SFDU framing: split a byte string into typed record blocks and join them back.

A file is a sequence of SFDUs, each ``20 + sfdu_length`` bytes long. Framing walks the
length chain; a run of SFDUs that repeat the same label and format is taken at once
(vectorized), so a homogeneous file of 10^6 records costs a few dozen steps. Each run is
decoded with :func:`parsers.trk234.layout.dtype` straight from the buffer. A corrupt SFDU
raises :class:`parsers.ParseError` with its byte offset, or in ``errors="report"`` mode is
reported and skipped (re-synchronising on the next ``NJPL`` label when its length is bad).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from parsers.errors import ParseError, ParseReport, handle
from parsers.trk234 import layout

SYNC = b"NJPL"
_MAX_RUN = 1 << 16


@dataclass
class Block:
    """SFDUs of one format (and one repeat count): packed ``records`` and their file ``index``."""

    format_code: int
    records: np.ndarray
    index: np.ndarray

    @property
    def n_obs(self) -> int:
        return self.records.dtype["obs"].shape[0] if "obs" in self.records.dtype.names else 0


def _expected_shape(fc: int, total: int) -> int | None:
    """Repeat count implied by an SFDU of ``total`` bytes and format ``fc``; None if impossible."""
    if fc not in layout.TRACKING:
        return None
    fixed = layout.fixed_bytes(fc)
    group = layout.group_bytes(fc)
    if not group:
        return 0 if total == fixed else None
    rest = total - fixed - layout.TRAILER_BYTES
    return rest // group if rest >= 0 and rest % group == 0 else None


def _check(buf: bytes, pos: int) -> tuple[int, int, int | None, str | None]:
    """(total bytes, format code, repeat count, reason) of the SFDU at ``pos``; reason None if good."""
    n = len(buf)
    if n - pos < layout.HEADER_BYTES:
        return 0, -1, None, f"truncated SFDU header ({n - pos} bytes left)"
    if buf[pos:pos + 4] != SYNC:
        return 0, -1, None, f"no SFDU label: control authority {bytes(buf[pos:pos + 4])!r}, expected b'NJPL'"
    total = layout.LABEL_BYTES + int.from_bytes(buf[pos + 12:pos + 20], "big")
    fc = buf[pos + 31]
    ddid = bytes(buf[pos + 8:pos + 12])
    if pos + total > n:
        return total, fc, None, f"SFDU of {total} bytes runs past the end of the file"
    if fc not in layout.TRACKING:
        return total, fc, None, f"unknown format code {fc}"
    if ddid != layout.CLASS_OF_FORMAT[fc].encode():
        return total, fc, None, f"data description id {ddid!r} does not match format code {fc}"
    n_obs = _expected_shape(fc, total)
    if n_obs is None:
        return total, fc, None, f"SFDU length {total} bytes does not fit format code {fc}"
    if fc in layout.REPEATED and int.from_bytes(buf[pos + 188:pos + 190], "big") != n_obs:
        return total, fc, None, f"number of observations disagrees with the SFDU length {total}"
    return total, fc, n_obs, None


_KEY = np.r_[np.arange(20), np.arange(28, 32)]
_KEY_REPEATED = np.r_[_KEY, np.arange(188, 190)]


def _run_length(buf: bytes, u8: np.ndarray, pos: int, total: int, repeated: bool) -> int:
    """How many SFDUs from ``pos`` on repeat the first one's label, length, format (and count)."""
    cols = _KEY_REPEATED if repeated else _KEY
    head = buf[pos:pos + 32]
    count = 1
    while count < 8:  # short runs (interleaved files) without numpy overhead
        at = pos + count * total
        if at + total > len(buf) or buf[at:at + 32] != head or (
                repeated and buf[at + 188:at + 190] != buf[pos + 188:pos + 190]):
            return count
        count += 1
    key = u8[pos + cols]
    step = 64
    while True:
        m = min(step, (len(u8) - pos) // total - count)
        if m <= 0:
            return count
        starts = pos + total * np.arange(count, count + m)
        same = (u8[starts[:, None] + cols] == key).all(axis=1)
        if not same.all():
            return count + int(np.argmin(same))
        count += m
        step = min(step * 4, _MAX_RUN)


def split(buf: bytes, path, errors: str = "raise", report: ParseReport | None = None) -> list[Block]:
    """Blocks of decoded SFDUs in ``buf``; every record keeps its index in the file."""
    u8 = np.frombuffer(buf, dtype=np.uint8)
    runs: dict[tuple[int, int], list[tuple[np.ndarray, np.ndarray]]] = {}
    pos, record = 0, 0
    while pos < len(buf):
        total, fc, n_obs, reason = _check(buf, pos)
        if reason is not None:
            handle(ParseError(path, reason, offset=pos, record=record), errors, report)
            framed = buf[pos:pos + 4] == SYNC and layout.HEADER_BYTES <= total and pos + total <= len(buf)
            nxt = pos + total if framed else buf.find(SYNC, pos + 1)
            pos = nxt if nxt > pos else len(buf)
            record += 1
            continue
        count = _run_length(buf, u8, pos, total, fc in layout.REPEATED)
        recs = np.frombuffer(buf, dtype=layout.dtype(fc, n_obs), count=count, offset=pos)
        runs.setdefault((fc, n_obs), []).append((recs, np.arange(record, record + count), pos + total * np.arange(count)))
        pos += total * count
        record += count
    blocks = []
    for (fc, n_obs), parts in sorted(runs.items()):
        recs = _stack([r for r, _, _ in parts], layout.dtype(fc, n_obs))
        index = np.concatenate([i for _, i, _ in parts])
        offsets = np.concatenate([o for _, _, o in parts])
        ok = _valid_time(recs)
        for k in np.flatnonzero(~ok):
            r = recs[k]
            reason = f"time tag year {r['year']} day {r['doy']} second {r['sec']!r} is not a valid UTC time"
            handle(ParseError(path, reason, offset=int(offsets[k]), record=int(index[k])), errors, report)
        if ok.all():
            blocks.append(Block(fc, recs, index))
        elif ok.any():
            blocks.append(Block(fc, recs[ok], index[ok]))
    return blocks


def _valid_time(recs: np.ndarray) -> np.ndarray:
    """Time tags a reader can trust: years 1958-2200, day 1-366, 0 <= seconds < 86401."""
    sec = recs["sec"].astype(np.float64)
    with np.errstate(invalid="ignore"):
        return ((recs["year"] >= 1958) & (recs["year"] <= 2200) & (recs["doy"] >= 1) & (recs["doy"] <= 366)
                & (sec >= 0) & (sec < 86401))


def _stack(pieces: list[np.ndarray], dt: np.dtype) -> np.ndarray:
    """Concatenate packed record arrays byte-wise, keeping the big-endian dtype (np.concatenate would not)."""
    return np.concatenate([p.view(np.uint8) for p in pieces]).view(dt)


def join(blocks: list[Block]) -> bytes:
    """The file bytes of ``blocks``, SFDUs ordered by their ``index``."""
    if not blocks:
        return b""
    sizes = np.concatenate([np.full(len(b.records), b.records.dtype.itemsize, np.int64) for b in blocks])
    index = np.concatenate([np.asarray(b.index, np.int64) for b in blocks])
    order = np.argsort(index, kind="stable")
    starts = np.empty_like(sizes)
    starts[order] = np.concatenate([[0], np.cumsum(sizes[order])[:-1]])
    out = np.empty(int(sizes.sum()), dtype=np.uint8)
    first = 0
    for b in blocks:
        n, width = len(b.records), b.records.dtype.itemsize
        packed = np.ascontiguousarray(b.records.astype(layout.dtype(b.format_code, b.n_obs), copy=False))
        raw = packed.view(np.uint8).reshape(n, width)
        where = starts[first:first + n]
        first += n
        contiguous = n and np.all(np.diff(where) == width)
        if contiguous:
            out[where[0]:where[0] + n * width] = raw.ravel()
            continue
        for lo in range(0, n, 8192):
            out[where[lo:lo + 8192, None] + np.arange(width)] = raw[lo:lo + 8192]
    return out.tobytes()
