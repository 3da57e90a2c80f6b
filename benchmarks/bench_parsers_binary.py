"""Read 10^6 ODF and 10^6 UTDF records (real records tiled) and print the times (best and median of 3).

Usage: .venv/bin/python benchmarks/bench_parsers_binary.py [n_records] [data folder]
"""

from __future__ import annotations

import struct
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from parsers import odf, utdf

DATA = Path(sys.argv[2]) if len(sys.argv) > 2 else Path(__file__).resolve().parents[2] / "shared" / "data"
N = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000


def header(key: int, secondary: int, length: int, packet: int) -> bytes:
    return struct.pack(">iIII", key, secondary, length, packet) + bytes(20)


def tiled_odf(n: int) -> bytes:
    """Label, identifier and orbit data groups of the Cassini ODF with its data records tiled to n,
    then its ramp group and an EOF group with consistent packet numbers."""
    buf = (DATA / "cassini/S18TIGM2006_058_0005X25MV1.ODF").read_bytes()
    recs = np.frombuffer(buf, np.uint8).reshape(-1, 36)
    data = recs[5:79908]
    ramps = recs[79909:79945]
    body = np.resize(data, (n, 36)).tobytes()
    ramp_at = 5 + n
    eof_at = ramp_at + 1 + len(ramps)
    return (buf[:5 * 36] + body + header(2030, 25, 1, ramp_at) + ramps.tobytes()
            + header(-1, 0, 0, eof_at))


def tiled_utdf(n: int) -> bytes:
    recs = np.frombuffer((DATA / "utdf/LSUTDF_367501_119_2019_044_1555.trk").read_bytes(), np.uint8)
    return np.resize(recs.reshape(-1, 75), (n, 75)).tobytes()


def timed(label: str, fn, n: int, repeats: int = 3):
    """Run ``fn`` ``repeats`` times; print the best and the median wall time (a shared machine is noisy)."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    best, median = min(times), sorted(times)[len(times) // 2]
    print(f"{label:<34s} best {best:6.2f} s  median {median:6.2f} s  {n / best / 1e6:6.2f} M records/s")
    return out


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "big.odf"
        p.write_bytes(tiled_odf(N))
        d = timed(f"ODF read ({N} data records)", lambda: odf.read(p), N)
        print(f"  rows {len(d.table)}, ramps {len(d.ramps)}, report {len(d.report)}")
        q = Path(tmp) / "big.utdf"
        q.write_bytes(tiled_utdf(N))
        u = timed(f"UTDF read ({N} records)", lambda: utdf.read(q), N)
        print(f"  rows {len(u.table)}, report {len(u.report)}")
        timed(f"UTDF write ({N} records)", lambda: utdf.write(Path(tmp) / "out.utdf", u.meta["records"]), N)
        assert (Path(tmp) / "out.utdf").read_bytes() == q.read_bytes()


if __name__ == "__main__":
    main()
