"""DSN TRK-2-23 media calibration files (.TRO troposphere, .ION ionosphere).

The files are CSP command cards (DSN 820-013, module TRK-2-23), e.g.::

    # FITSIG= .0012617
    ADJUST(ALL)BY NRMPOW(   0.0078,   0.0131, ...)             MODEL
    (WET NUPART)FROM(06/02/01,06:00:00.001)TO(06/02/01,18:00:00)DSN(C10). # 060204

A card adds a series in time to a media model (``DRY NUPART`` / ``WET NUPART``:
zenith troposphere, m; ``CHPART``: line-of-sight ionosphere range delay at
S-band, m) inside its time window, for a DSN complex (``C10``/``C40``/``C60``)
or a list of stations, and for ionosphere one spacecraft (``SCID``).

Series (TRK-2-23 "computation specifiers"; the normalization as in DSN 820-013
TRK-2-23 Rev. C as implemented by Tudat's ``PowerSeriesReferenceCorrection``
and ``FourierSeriesReferenceCorrection``; the TRK-2-23 product description
calls the ION cards "a normalized polynomial for each tracking pass"):

- ``NRMPOW(c0..cn)``: normalized power series, ``sum c_i x**i`` with
  ``x = 2 (t - FROM) / (TO - FROM) - 1`` (the window mapped onto [-1, 1]).
- ``CONST(c0)``: a constant.
- ``TRIG(P, a0, c1, s1, c2, s2, ...)``: Fourier series of period ``P`` (s),
  ``a0 + sum c_k cos(k w) + s_k sin(k w)``, ``w = 2 pi (t - FROM) / P``.

ADJUST cards are additive: the value at ``t`` is the sum over all cards whose
window holds ``t``; a time no card covers evaluates to NaN (never 0), so a
caller can tell "no calibration" from "zero calibration". Times are UTC
(``datetime64[ns]``). ``DELETE`` cards and the ``D``-series (DNRMPOW, ...) are
not supported and raise ParseError (or are reported). numpy/stdlib only.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from parsers.errors import ParseError, ParseReport, finite, handle, integer, read_text

MODELS = ("DRY NUPART", "WET NUPART", "CHPART")
SERIES = ("NRMPOW", "CONST", "TRIG")
# Which data types each ADJUST(...) data-type keyword applies to.
DATA_TYPES = {"ALL": ("range", "doppler"), "DOPRNG": ("range", "doppler"),
              "RANGE": ("range",), "DOPPLER": ("doppler",)}
_OPEN_END = np.datetime64("2262-04-11T00:00:00", "ns")
_OPEN_START = np.datetime64("1678-01-01T00:00:00", "ns")

_CARD = re.compile(
    r"^ADJUST\((?P<types>[^)]*)\)\s*BY\s*(?P<series>[A-Z]+)\s*\((?P<coefs>[^)]*)\)"
    r"\s*MODEL\s*\((?P<model>[^)]*)\)(?P<scope>.*)\.$")
_SCOPE = re.compile(r"\s*(?P<key>[A-Z]+)\s*\((?P<arg>[^)]*)\)")
_TIME = re.compile(r"^(\d{2})/(\d{2})/(\d{2}),(\d{1,2}):(\d{2})(?::(\d{2}(?:\.\d*)?))?$")


@dataclass(frozen=True)
class Card:
    """One ADJUST card: a series added to ``model`` over [start, end] for ``stations``."""

    model: str                 # 'DRY NUPART', 'WET NUPART' or 'CHPART'
    series: str                # 'NRMPOW', 'CONST' or 'TRIG'
    coefficients: tuple        # m (TRIG: period in s first)
    start: np.datetime64       # UTC
    end: np.datetime64         # UTC (open end: far future)
    network: str               # 'C10', 'C40', 'C60' or station list '14,15'
    data_types: tuple          # ('range', 'doppler') subset
    scid: int                  # spacecraft id, -1 when the card has none
    fitsig: float              # m, FITSIG comment before the card (NaN if absent)
    source: str                # file name
    line: int                  # 1-based line where the card starts

    @property
    def label(self) -> str:
        """'FILE:line MODEL SERIES' — where a value came from."""
        return f"{self.source}:{self.line} {self.model} {self.series}"


def complex_of(station) -> str:
    """DSN complex of a station (DSS 10-29 -> C10 Goldstone, 30-49 -> C40 Canberra, 50-69 -> C60 Madrid)."""
    s = str(station).strip().upper()
    if s in ("C10", "C40", "C60"):
        return s
    n = _dss_number(s)
    if n is None or not 10 <= n < 70:
        return ""
    return ("C10", "C40", "C60")[(n - 10) // 20]


def _dss_number(s: str):
    m = re.fullmatch(r"(?:DSS)?-?\s*(\d{1,3})", s.strip().upper())
    return int(m.group(1)) if m else None


def _covers(network: str, station) -> bool:
    s = str(station).strip().upper()
    if network in ("C10", "C40", "C60"):
        return complex_of(s) == network
    n = _dss_number(s)
    return n is not None and n in {int(x) for x in network.split(",") if x.strip()}


def _parse_time(text: str, path, line) -> np.datetime64:
    m = _TIME.match(text.replace(" ", ""))
    if not m:
        raise ParseError(path, f"bad CSP time {text!r} (want YY/MM/DD,HH:MM[:SS.fff])", line=line)
    yy, mo, dd, hh, mi, ss = m.groups()
    year = int(yy) + (2000 if int(yy) < 69 else 1900)   # CSP two-digit years: 69..99 -> 19xx
    try:
        base = np.datetime64(f"{year:04d}-{mo}-{dd}T{int(hh):02d}:{mi}", "ns")
    except ValueError:
        raise ParseError(path, f"invalid CSP date/time {text!r} (month, day or hour out of range)", line=line) from None
    return base + np.timedelta64(int(round(float(ss or 0.0) * 1e9)), "ns")


def _parse_card(text: str, fitsig: float, path, line: int) -> Card:
    m = _CARD.match(text)
    if not m:
        raise ParseError(path, f"not an ADJUST ... BY ... MODEL(...) card: {text[:60]!r}", line=line)
    types = m["types"].strip().upper()
    if types not in DATA_TYPES:
        raise ParseError(path, f"unknown data type ADJUST({types})", line=line)
    series = m["series"].upper()
    if series not in SERIES:
        raise ParseError(path, f"unsupported series BY {series}", line=line)
    model = " ".join(m["model"].split()).upper()
    if model not in MODELS:
        raise ParseError(path, f"unknown model MODEL({model})", line=line)
    coefs = tuple(finite(c, path, "coefficient", line=line) for c in m["coefs"].split(",") if c.strip())
    need = {"NRMPOW": 1, "CONST": 1, "TRIG": 2}[series]
    if len(coefs) < need or (series == "CONST" and len(coefs) != 1) or (series == "TRIG" and len(coefs) % 2):
        raise ParseError(path, f"{series} with {len(coefs)} coefficients", line=line)
    scope = {}
    rest = m["scope"]
    pos = 0
    # one anchored match per clause: finditer would retry from every position (quadratic on a long word)
    while sm := _SCOPE.match(rest, pos):
        scope[sm["key"]] = sm["arg"]
        pos = sm.end()
    if rest[pos:].strip():
        raise ParseError(path, f"unreadable scope {rest[pos:].strip()[:60]!r}", line=line)
    start = _parse_time(scope["FROM"], path, line) if "FROM" in scope else _OPEN_START
    end = _parse_time(scope["TO"], path, line) if "TO" in scope else _OPEN_END
    if series == "NRMPOW" and ("FROM" not in scope or "TO" not in scope):
        raise ParseError(path, "NRMPOW needs both FROM and TO to normalize time", line=line)
    if end <= start:
        raise ParseError(path, "TO is not after FROM", line=line)
    network = scope.get("DSN", "").replace(" ", "").upper()
    if not network:
        raise ParseError(path, "card has no DSN(...) complex or station scope", line=line)
    scid = integer(scope["SCID"], path, "SCID", 0, 1023, line=line) if "SCID" in scope else -1
    return Card(model, series, coefs, start, end, network, DATA_TYPES[types], scid, fitsig,
                Path(str(path)).name, line)


def parse_text(text: str, path="<text>", errors: str = "raise", report: ParseReport | None = None) -> list[Card]:
    """Cards of a TRK-2-23 text; a card that cannot be read raises (or is reported)."""
    cards, buf, first, fitsig = [], "", 0, np.nan
    reported = len(report) if report is not None else 0
    for n, raw in enumerate(text.splitlines(), 1):
        s = raw.strip()
        if s.startswith("#"):
            m = re.match(r"#\s*FITSIG\s*=\s*(\S*)", s)
            if m and not buf:
                try:
                    fitsig = finite(m.group(1), path, "FITSIG", line=n, record=len(cards))
                except ParseError as err:
                    handle(err, errors, report)
                    fitsig = np.nan
            continue
        s = s.split("#", 1)[0].strip()
        if not s:
            continue
        if not buf:
            first = n
        buf += s
        if buf.endswith(")."):
            try:
                cards.append(_parse_card(buf, fitsig, path, first))
            except ParseError as err:
                err.record = len(cards)
                handle(err, errors, report)
            buf, fitsig = "", np.nan
    if buf:
        handle(ParseError(path, "card not terminated by ').'", line=first, record=len(cards)), errors, report)
    if not cards and (report is None or len(report) == reported):
        raise ParseError(path, "no ADJUST cards")
    return cards


def read_trk223(*paths, errors: str = "raise", report: ParseReport | None = None) -> "CalibrationSet":
    """A CalibrationSet of the cards of one or more TRK-2-23 files (in the order given)."""
    cards = []
    for p in paths:
        cards += parse_text(read_text(p, "ascii"), p, errors, report)
    return CalibrationSet(cards)


def sniff(head: bytes) -> bool:
    """True when the first line that is not a comment starts an ADJUST card."""
    first = next((s for s in (ln.strip() for ln in head.decode("latin-1").splitlines()) if s and s[0] != "#"), "")
    return first.upper().startswith("ADJUST(")


def read(path, errors: str = "raise") -> "CalibrationSet":
    """The cards of one file (the reader interface of :mod:`parsers.formats`)."""
    return read_trk223(path, errors=errors)


def describe(path) -> list[str]:
    """Lines for ``odpipe inspect``: cards per model and complex or station list, their span, spacecraft
    ids, and what was unreadable."""
    report = ParseReport()
    cards = read_trk223(path, errors="report", report=report).cards
    lines = [f"cards: {len(cards)}"]
    for model in MODELS:
        mine = [c for c in cards if c.model == model]
        if not mine:
            continue
        nets = {}
        for c in mine:
            nets[c.network] = nets.get(c.network, 0) + 1
        closed = [t for c in mine for t in (c.start, c.end) if _OPEN_START < t < _OPEN_END]
        span = (f"{np.datetime64(min(closed), 's')} .. {np.datetime64(max(closed), 's')} UTC" if closed
                else "open")
        lines.append(f"{model}: {len(mine)} cards, " + ", ".join(f"{n} {k}" for n, k in sorted(nets.items()))
                     + f"; {span}")
    scids = sorted({c.scid for c in cards if c.scid >= 0})
    if scids:
        lines.append("spacecraft (SCID): " + ", ".join(map(str, scids)))
    return lines + [f"unreadable records: {len(report)}"] + [f"  {e}" for e in list(report)[:5]]


class CalibrationSet:
    """TRK-2-23 cards, evaluated vectorized at UTC times (``datetime64[ns]``)."""

    def __init__(self, cards):
        self.cards = list(cards)

    def __add__(self, other: "CalibrationSet") -> "CalibrationSet":
        return CalibrationSet(self.cards + other.cards)

    def __len__(self) -> int:
        return len(self.cards)

    def zenith_delay(self, complex_or_station, t, component: str = "dry"):
        """Zenith troposphere delay (m) at UTC times ``t``; NaN where no card covers."""
        model = {"dry": "DRY NUPART", "wet": "WET NUPART"}[component]
        return self.evaluate(model, complex_or_station, t)[0]

    def line_of_sight(self, station, spacecraft, t, kind: str = "range"):
        """Ionosphere line-of-sight range delay (m, S-band) at UTC ``t``; NaN where uncovered."""
        return self.evaluate("CHPART", station, t, spacecraft=spacecraft, kind=kind)[0]

    def evaluate(self, model: str, station, t, spacecraft=None, kind: str = "range"):
        """(value m, index of the last covering card or -1) of ``model`` at UTC times ``t``."""
        t = np.atleast_1d(np.asarray(t, dtype="datetime64[ns]"))
        order = np.argsort(t, kind="stable")
        ts = t[order]
        ti = ts.view("int64")
        value = np.zeros(t.size)
        used = np.full(t.size, -1, dtype=np.int64)
        try:
            scid = None if spacecraft is None else int(str(spacecraft).strip())
        except ValueError:
            scid = -2   # not a DSN spacecraft id: only cards without SCID apply
        for k, c in enumerate(self.cards):
            if c.model != model or kind not in c.data_types or not _covers(c.network, station):
                continue
            if scid is not None and c.scid not in (-1, scid):
                continue
            lo, hi = np.searchsorted(ts, c.start, side="left"), np.searchsorted(ts, c.end, side="right")
            if hi <= lo:
                continue
            value[lo:hi] += _series(c, ti[lo:hi])
            used[lo:hi] = k
        value[used < 0] = np.nan
        out_v, out_u = np.empty_like(value), np.empty_like(used)
        out_v[order], out_u[order] = value, used
        return out_v, out_u


def _series(c: Card, t_ns):
    """Card ``c``'s series at int64 ns times inside its window."""
    a = np.asarray(c.coefficients)
    if c.series == "CONST":
        return np.full(t_ns.shape, a[0])
    dt = (t_ns - c.start.astype("int64")) * 1e-9
    if c.series == "NRMPOW":
        span = (c.end - c.start) / np.timedelta64(1, "s")
        return np.polynomial.polynomial.polyval(2.0 * dt / span - 1.0, a)
    w = 2.0 * np.pi * dt / a[0]
    k = np.arange(1, (a.size - 2) // 2 + 1)
    return a[1] + np.cos(np.outer(w, k)) @ a[2::2] + np.sin(np.outer(w, k)) @ a[3::2]
