"""Seeded mutation fuzzing of every reader: only ParseError may come out, and no input may hang.

``mutate(seed, rng)`` makes one hostile variant of a file's bytes (bit flips, cuts, random
bytes, spliced or deleted chunks, and for text: numbers replaced by absurd ones, tokens,
bad bytes, huge fields, repeated or dropped lines). ``READERS`` names each reader with the
seeds it is fuzzed from: real files of ``/work/shared/data`` (cut to a few kB so that
hundreds of inputs run in seconds) or the project's own writers' output. ``run(...)``
feeds ``n`` mutations to a reader in both error modes under a per-input time limit and
returns the counts; any other exception, or an input that takes longer than the limit,
raises :class:`Crash` naming the reader, input number and the exception.
"""

from __future__ import annotations

import random
import re
import signal
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from parsers import ParseError, ParseReport, ionex, maneuvers, odf, oem, tdm, trk223, trk234, utdf

ROOT = Path(__file__).resolve().parents[1]

# Tokens a careless or hostile writer puts where a value belongs.
TOKENS = [b"1e400", b"-1e400", b"nan", b"NaN", b"inf", b"-Infinity", b"9" * 5000, b"-" + b"7" * 400, b"0", b"-0",
          b".", b"", b"+", b"e", b"E+", b"0x1F", b"1_000", b"9999", b"99999999999999999999", b"\xff\xfe",
          b"\x00", b"\xc3\x28", b"A" * 200_000, b'"' + b"x" * 1000, b",", b"=", b'"', b"'", b"(", b")", b"#",
          b"\n", b"\r\n", b"\r", b"\t", b" " * 80, b"[[maneuver]]", b"\xef\xbb\xbf", b"<", b"&amp;", b"&#0;",
          b"T", b":", b"Z", b"0000-01-01T00:00:00", b"2012-13-45T25:61:61", b"0000-001T00:00:00", b"00/00/00",
          b"99/99/99,99:99:99", b"12-000", b"12-367", b"-12-100", b"1e18", b"dv = 5", b"epoch = 0000-01-01",
          b"START OF TEC MAP", b"END OF TEC MAP", b"EXPONENT", b"META_START", b"DATA_STOP", b"NJPL2I00C125"]
_NUMBER = re.compile(rb"[-+]?\d+(\.\d*)?([eE][-+]?\d+)?")


def mutate(seed: bytes, rng: random.Random) -> bytes:
    """One to three mutations of ``seed``."""
    buf = bytearray(seed)
    for _ in range(rng.choice((1, 1, 1, 2, 3))):
        buf = _ONE[rng.randrange(len(_ONE))](buf, rng)
    return bytes(buf)


def _flip(buf, rng):
    for _ in range(rng.randint(1, 20)):
        if buf:
            buf[rng.randrange(len(buf))] ^= 1 << rng.randrange(8)
    return buf


def _cut(buf, rng):
    return buf[:rng.randint(0, len(buf))]


def _random(buf, rng):
    return bytearray(rng.randbytes(rng.randint(0, 2000)))


def _splice(buf, rng):
    """Repeat a chunk (duplicated records or lines)."""
    if not buf:
        return buf
    a = rng.randrange(len(buf))
    b = min(len(buf), a + rng.randint(1, 400))
    at = rng.randint(0, len(buf))
    return buf[:at] + buf[a:b] * rng.randint(1, 3) + buf[at:]


def _delete(buf, rng):
    if not buf:
        return buf
    a = rng.randrange(len(buf))
    return buf[:a] + buf[a + rng.randint(1, 200):]


def _token(buf, rng):
    """Insert a token, or write it over a few bytes."""
    at = rng.randint(0, len(buf))
    return buf[:at] + rng.choice(TOKENS) + buf[at + rng.choice((0, 0, 1, 3, 8)):]


def _number(buf, rng):
    """Replace one number of a text file with an absurd token."""
    found = [m.span() for m, _ in zip(_NUMBER.finditer(buf), range(5000))]
    if not found:
        return _token(buf, rng)
    a, b = rng.choice(found)
    return buf[:a] + rng.choice(TOKENS[:22] + [b"0000", b"00", b"-1", b"366", b"1e-400"]) + buf[b:]


def _lines(buf, rng):
    """Repeat, drop or swap whole lines."""
    lines = bytes(buf).split(b"\n")
    if len(lines) < 2:
        return buf
    i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
    kind = rng.randrange(3)
    if kind == 0:
        lines.insert(j, lines[i])
    elif kind == 1:
        del lines[i]
    else:
        lines[i], lines[j] = lines[j], lines[i]
    return bytearray(b"\n".join(lines))


_ONE = (_flip, _cut, _random, _splice, _delete, _token, _number, _number, _lines, _lines)


# ---------------------------------------------------------------- readers and their seeds

def _head(path: Path, size: int) -> bytes:
    """The first ``size`` bytes of a text file, ending at a line break."""
    raw = path.read_bytes()[:size]
    return raw[:raw.rfind(b"\n") + 1] if len(raw) == size else raw


def _odf_seeds(data: Path) -> list[bytes]:
    """100 records of MESSENGER orbit data, one ramp group and the EOF group, headers renumbered."""
    buf = (data / "messenger" / "odf07155.odf").read_bytes()
    words = np.frombuffer(buf[:36 * 100] + buf[36 * 2233:36 * 2240] + buf[36 * 2405:36 * 2407], ">i4")
    words = words.reshape(-1, 9).copy()
    header = ~words[:, 4:].any(axis=1) & np.isin(words[:, 0], odf.GROUP_KEYS)
    words[header, 3] = np.flatnonzero(header)  # a group header states its own packet number
    return [words.tobytes()]


def _utdf_seeds(data: Path) -> list[bytes]:
    return [(data / "utdf" / "LSUTDF_367501_119_2019_044_1555.trk").read_bytes()[:75 * 30],
            (data / "utdf" / "doppler.utdf").read_bytes(), (ROOT / "fixtures/utdf/astro_utdf_cases.utdf").read_bytes()]


def _trk234_seeds(data: Path) -> list[bytes]:
    return [(ROOT / "fixtures/trk234/sample.tnf").read_bytes()]


def _tdm_kvn_seeds(data: Path) -> list[bytes]:
    return [(data / "tdm/kvn" / n).read_bytes() for n in ("TDMExample8.txt", "TDMExampleAllKeywordsSingleDiff.txt",
                                                          "TDMExample2.txt")]


def _tdm_xml_seeds(data: Path) -> list[bytes]:
    return [(data / "tdm/xml" / n).read_bytes() for n in ("TDMExample8.xml", "TDMExample2.xml")]


def _trk223_seeds(data: Path) -> list[bytes]:
    return [_head(data / "cassini" / n, 3000) for n in ("S18TIGE2006_032_2006_059.TRO", "S18TIGE2006_032_2006_059.ION")]


def _ionex_seeds(data: Path) -> list[bytes]:
    return [(data / "ionex" / "jammed-fields.14i").read_bytes()]


def _mas_seeds(data: Path) -> list[bytes]:
    return [_head(data / "grail" / "mas00_2012_04_06_a_04.asc", 3000)]


def plan() -> pd.DataFrame:
    """Two planned maneuvers (one impulsive, one finite) for the plan writer's seeds."""
    nan = np.nan
    return pd.DataFrame({
        "name": ["TCM-1", "LOI"], "epoch": pd.to_datetime(["2012-04-06T12:00:00.25", "2012-04-07T03:30:00"], format="ISO8601"),
        "kind": ["impulsive", "finite"], "frame": ["RTN", "VNB"], "dv1": [0.1, nan], "dv2": [-0.02, nan],
        "dv3": [0.003, nan], "duration": [nan, 120.0], "thrust": [nan, 22.0], "dir1": [nan, 1.0],
        "dir2": [nan, 0.0], "dir3": [nan, 0.0], "mass": [nan, 300.0], "sigma_dv": [0.001, 0.01],
        "sigma_time": [nan, 1.0]})


def _plan_seeds(data: Path) -> list[bytes]:
    with tempfile.TemporaryDirectory() as tmp:
        out = []
        for name in ("plan.csv", "plan.toml"):
            maneuvers.write_plan(plan(), Path(tmp) / name)
            out.append((Path(tmp) / name).read_bytes())
    return out


def _oem_seeds(data: Path) -> list[bytes]:
    from odpipe.products.segments import EphemerisSegment
    from odpipe.products.oem import format_oem
    t = np.arange(4) * 60.0 + 3.9e8
    states = np.column_stack([7e6 + t * 0, t * 0 + 1e3, t * 0, t * 0, t * 0 + 7.5e3, t * 0 + 1.0])
    cov = np.broadcast_to(np.diag([1e2, 1e2, 1e2, 1e-2, 1e-2, 1e-2]), (4, 6, 6)).copy()
    text = format_oem([EphemerisSegment(t, states, "earth", cov)], "SAT", "2099-001A", creation_date="2026-01-01T00:00:00")
    return [text.encode()]


def _tracking(mod) -> Callable:
    return lambda path, errors: mod.read(path, errors=errors).report


def _odf(path, errors):
    d = odf.read(path, errors=errors)
    assert len(d.table) <= path.stat().st_size // odf.RECORD, "more rows than records"
    return d.report


def _utdf(path, errors):
    """UTDF, and every record it keeps turns back into its own bytes."""
    d = utdf.read(path, errors=errors)
    buf = path.read_bytes()
    assert utdf.encode(d.meta["records"]) == b"".join(buf[i * 75:(i + 1) * 75] for i in d.meta["records"].index)
    return d.report


def _trk234(path, errors):
    d = trk234.read(path, errors=errors)
    assert sum(d.meta["sfdu_counts"].values()) + len(d.report) <= max(1, path.stat().st_size // 4)
    return d.report


def _reported(read) -> Callable:
    """``read(path, errors)`` of a reader that fills a ParseReport it is given; returns the report."""
    def call(path, errors):
        report = ParseReport()
        read(path, errors=errors, report=report)
        return report
    return call


@dataclass(frozen=True)
class Reader:
    """A reader under fuzzing: ``read(path, errors) -> ParseReport`` and its seeds (from the shared data folder)."""

    read: Callable
    seeds: Callable[[Path], list[bytes]]
    suffix: str


READERS: dict[str, Reader] = {
    "odf": Reader(_odf, _odf_seeds, ".odf"),
    "utdf": Reader(_utdf, _utdf_seeds, ".utdf"),
    "trk234": Reader(_trk234, _trk234_seeds, ".tnf"),
    "tdm_kvn": Reader(_tracking(tdm), _tdm_kvn_seeds, ".tdm"),
    "tdm_xml": Reader(_tracking(tdm), _tdm_xml_seeds, ".xml"),
    "trk223": Reader(_reported(trk223.read_trk223), _trk223_seeds, ".tro"),
    "ionex": Reader(_reported(ionex.read_ionex), _ionex_seeds, ".19i"),
    "maneuver_log": Reader(_reported(maneuvers.read_mas), _mas_seeds, ".asc"),
    "maneuver_plan": Reader(_reported(maneuvers.read_plan), _plan_seeds, ".csv"),
    "oem": Reader(_reported(oem.read), _oem_seeds, ".oem"),
}


# ---------------------------------------------------------------- the loop

class Crash(AssertionError):
    """A reader raised something other than ParseError, or hung."""


class _Hang(BaseException):
    pass


def _alarm(signum, frame):
    raise _Hang


@dataclass
class Tally:
    """Inputs fed to one reader and what came out."""

    inputs: int = 0
    parse_errors: int = 0   # inputs refused with ParseError in errors="raise" mode
    refused: int = 0        # of those, refused whole in errors="report" mode too (file-level faults)
    reported: int = 0       # of those, read in errors="report" mode with the bad records reported
    seconds: float = 0.0    # CPU time of this process


def run(name: str, data: Path, n: int, seed: int = 0, limit_s: float = 5.0, folder: Path | None = None) -> Tally:
    """Feed ``n`` mutations of ``name``'s seeds to it; :class:`Crash` on the first non-ParseError or hang."""
    import time
    reader = READERS[name]
    seeds = reader.seeds(data)
    rng = random.Random(f"{name}:{seed}")
    tally = Tally()
    old = signal.signal(signal.SIGALRM, _alarm)
    with tempfile.TemporaryDirectory(dir=folder) as tmp:
        path = Path(tmp) / f"fuzz{reader.suffix}"
        t0 = time.process_time()
        try:
            for i in range(n):
                blob = mutate(seeds[i % len(seeds)], rng)
                path.write_bytes(blob)
                tally.inputs += 1
                if _one(reader, path, "raise", name, i, blob, limit_s) is None:
                    tally.parse_errors += 1
                    # (a file read whole in "raise" mode reads the same in "report" mode)
                    report = _one(reader, path, "report", name, i, blob, limit_s)
                    tally.refused += report is None
                    tally.reported += report is not None and len(report) > 0
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, old)
        tally.seconds = time.process_time() - t0
    return tally


def _one(reader: Reader, path: Path, errors: str, name: str, i: int, blob: bytes, limit_s: float):
    """The reader's ParseReport, or None when it raised ParseError; :class:`Crash` otherwise."""
    signal.setitimer(signal.ITIMER_REAL, limit_s)
    try:
        return reader.read(path, errors)
    except ParseError:
        return None
    except _Hang:
        raise Crash(f"{name} input {i} ({errors}): no answer within {limit_s} s; input {blob[:120]!r}...") from None
    except Exception as exc:
        raise Crash(f"{name} input {i} ({errors}): {type(exc).__name__}: {str(exc)[:300]}; "
                    f"input {blob[:120]!r}...") from exc
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
