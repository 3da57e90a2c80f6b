"""CCSDS Orbit Ephemeris Message (OEM, KVN) reader.

Returns one :class:`OemSegment` per META block: its metadata, epochs as
datetime64[ns] in the file's own TIME_SYSTEM (named in ``meta``), states in
m and m/s (the file's km, km/s converted), and covariances in m², m²/s,
m²/s² when the segment has a covariance block. With ``errors="report"`` an
unreadable ephemeris line is left out and added to the report; other faults
(structure, covariance blocks) always raise.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from parsers.errors import ParseError, ParseReport, check_mode, finite, handle, read_text

_TRIL = np.tril_indices(6)
_SCALE = 1e3  # km -> m


@dataclass
class OemSegment:
    meta: dict
    epochs: np.ndarray
    states: np.ndarray
    cov_epochs: np.ndarray = field(default_factory=lambda: np.array([], dtype="datetime64[ns]"))
    covariances: np.ndarray = field(default_factory=lambda: np.zeros((0, 6, 6)))


def sniff(head: bytes) -> bool:
    return head.lstrip().startswith(b"CCSDS_OEM_VERS")


def read(path, errors: str = "raise", report: ParseReport | None = None) -> list[OemSegment]:
    """Read every segment of a KVN OEM; ParseError names the file and line."""
    check_mode(errors)
    path = Path(path)
    lines = read_text(path).splitlines()
    if not lines or not sniff(lines[0].encode()):
        raise ParseError(path, "not a KVN OEM (no CCSDS_OEM_VERS header)", line=1)
    segments, meta, rows, cov_rows, cov_epochs = [], None, [], [], []
    state = "header"

    def close(lineno):
        if meta is None:
            return
        if not rows:
            raise ParseError(path, "segment without ephemeris data lines", line=lineno)
        if len(cov_rows) != len(cov_epochs):
            raise ParseError(path, f"{len(cov_epochs)} covariance EPOCHs for {len(cov_rows)} matrices", line=lineno)
        epochs, states = _states(path, rows, errors, report)
        states = states * _SCALE
        covs = np.zeros((len(cov_rows), 6, 6))
        covs[:, _TRIL[0], _TRIL[1]] = np.reshape([vals for _, vals in cov_rows], (-1, 21))
        covs = covs + np.tril(covs, -1).transpose(0, 2, 1)
        segments.append(OemSegment(meta, epochs, states, np.array(cov_epochs, dtype="datetime64[ns]"),
                                   covs * _SCALE**2))

    cov_vals: list[float] = []
    for lineno, raw in enumerate(lines, start=1):
        text = raw.strip()
        if not text or text.startswith("COMMENT"):
            continue
        if text == "META_START":
            close(lineno)
            meta, rows, cov_rows, cov_epochs, state = {}, [], [], [], "meta"
        elif text == "META_STOP":
            state = "data"
        elif text == "COVARIANCE_START":
            state = "cov"
        elif text == "COVARIANCE_STOP":
            if cov_vals:
                raise ParseError(path, "incomplete covariance matrix", line=lineno)
            state = "data"
        elif state in ("header", "meta") or (state == "cov" and "=" in text):
            key, sep, value = text.partition("=")
            if not sep:
                raise ParseError(path, f"expected KEY = value, got {text!r}", line=lineno)
            key, value = key.strip(), value.strip()
            if state == "meta":
                meta[key] = value
            elif state == "cov" and key == "EPOCH":
                if cov_vals:
                    raise ParseError(path, "covariance EPOCH before the previous matrix was complete", line=lineno)
                cov_epochs.append(_epoch(path, lineno, value))
        elif state == "data":
            fields = text.split()
            if len(fields) not in (7, 10):
                raise ParseError(path, f"ephemeris line needs 7 or 10 fields, got {len(fields)}", line=lineno)
            rows.append((lineno, fields))
        elif state == "cov":
            cov_vals += _numbers(path, lineno, text.split())
            if len(cov_vals) > 21:
                raise ParseError(path, "covariance has more than 21 lower-triangle numbers", line=lineno)
            if len(cov_vals) == 21:
                cov_rows.append((lineno, np.array(cov_vals)))
                cov_vals = []
    close(len(lines))
    if not segments:
        raise ParseError(path, "no META_START block", line=len(lines))
    return segments


def _states(path, rows, errors, report):
    """Epochs and states (km, km/s) of a segment's ephemeris lines [(lineno, fields)]: converted as one block
    when every line is clean (the same values), else line by line, each fault raised or reported."""
    texts = [f[0] for _, f in rows]
    if all(_EPOCH.fullmatch(t) and 1678 <= int(t[:4]) <= 2261 for t in texts):
        try:
            epochs = np.array([t.rstrip("Z") for t in texts], dtype="datetime64[ns]")
            states = np.array([f[1:7] for _, f in rows], dtype=float)
            if np.isfinite(states).all():
                return epochs, states
        except ValueError:
            pass
    good = [(e, x) for e, x in (_state(path, n, r, errors, report) for n, r in rows) if e is not None]
    return np.array([e for e, _ in good], dtype="datetime64[ns]"), np.array([x for _, x in good]).reshape(-1, 6)


def _state(path, lineno, fields, errors, report):
    """(epoch, 6 numbers km, km/s) of an ephemeris line, or (None, None) when reported."""
    try:
        return _epoch(path, lineno, fields[0]), [_number(path, lineno, v) for v in fields[1:7]]
    except ParseError as err:
        handle(err, errors, report)
        return None, None


_EPOCH = re.compile(r"\d{4}-(\d{2}-\d{2}|\d{3})T\d{2}:\d{2}:\d{2}(\.\d{1,9})?Z?", re.ASCII)


def _epoch(path, lineno, text):
    if not _EPOCH.fullmatch(text):
        raise ParseError(path, f"bad epoch {text[:40]!r} (want YYYY-MM-DDThh:mm:ss[.f])", line=lineno)
    if not 1678 <= int(text[:4]) <= 2261:  # datetime64[ns] would wrap round silently
        raise ParseError(path, f"epoch {text[:40]!r} is outside 1678-2261", line=lineno)
    try:
        return np.datetime64(text.rstrip("Z"), "ns")
    except ValueError:
        raise ParseError(path, f"bad epoch {text[:40]!r}", line=lineno) from None


def _numbers(path, lineno, texts) -> list[float]:
    """The numbers of one line: converted at once, or one by one to name a bad one."""
    try:
        values = [float(t) for t in texts]
        if all(map(math.isfinite, values)):
            return values
    except ValueError:
        pass
    return [_number(path, lineno, t) for t in texts]


def _number(path, lineno, text):
    return finite(text, path, "number", line=lineno)
