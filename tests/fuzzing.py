"""Mutations of a real file's bytes for fuzzing binary readers: bit flips, truncation, random bytes."""

from hypothesis import strategies as st


def mutated(data, seed: bytes) -> bytes:
    """One mutation of ``seed`` drawn from the hypothesis ``data`` strategy."""
    buf = bytearray(seed)
    kind = data.draw(st.sampled_from(["flip", "cut", "random"]))
    if kind == "flip":
        for pos in data.draw(st.lists(st.integers(0, len(buf) - 1), min_size=1, max_size=20)):
            buf[pos] ^= 1 << data.draw(st.integers(0, 7))
    elif kind == "cut":
        buf = buf[: data.draw(st.integers(0, len(buf)))]
    else:
        buf = bytearray(data.draw(st.binary(max_size=2000)))
    return bytes(buf)
