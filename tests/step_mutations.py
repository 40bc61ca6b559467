"""Damaged STEP files for the reliability tests, made from the real-parts corpus.

Each mutation is what a broken download, a bad disk, a careless text editor or a buggy
exporter does to a file: cut it short, delete lines, flip bytes, insert bytes that are
not UTF-8, or write NaN / huge coordinates.  ``mutate(data, kind, rng)`` is deterministic
for a seeded ``numpy.random.Generator``.
"""

from __future__ import annotations

import re

import numpy as np

KINDS = ("truncate", "delete_lines", "flip_bytes", "non_utf8", "nan_coordinates", "huge_coordinates")

_POINT = re.compile(rb"CARTESIAN_POINT\s*\(\s*'[^']*'\s*,\s*\(([^)]*)\)")
_NUMBER = re.compile(rb"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[Ee][-+]?\d+)?")


def _data_span(data: bytes) -> tuple[int, int]:
    """Byte range of the DATA section (mutations there get past the header check)."""
    start = data.find(b"DATA;")
    end = data.rfind(b"ENDSEC;")
    if start < 0 or end <= start:
        return 0, len(data)
    return start + 5, end


def _coordinates(data: bytes, rng, replacement: bytes, fraction: float) -> bytes:
    """Replace one coordinate in a random ``fraction`` of the CARTESIAN_POINTs."""
    out, last = [], 0
    for m in _POINT.finditer(data):
        if rng.random() >= fraction:
            continue
        numbers = list(_NUMBER.finditer(data, m.start(1), m.end(1)))
        if not numbers:
            continue
        n = numbers[rng.integers(len(numbers))]
        out.append(data[last : n.start()])
        out.append(replacement)
        last = n.end()
    out.append(data[last:])
    return b"".join(out)


def mutate(data: bytes, kind: str, rng: np.random.Generator) -> bytes:
    """One damaged copy of the STEP text ``data``."""
    lo, hi = _data_span(data)
    if kind == "truncate":
        return data[: int(rng.integers(lo, hi))]
    if kind == "delete_lines":
        lines = data.split(b"\n")
        first = data[:lo].count(b"\n") + 1
        last = max(first + 1, data[:hi].count(b"\n"))
        drop = set(rng.integers(first, last, size=int(rng.integers(1, 8))).tolist())
        return b"\n".join(line for i, line in enumerate(lines) if i not in drop)
    if kind == "flip_bytes":
        arr = bytearray(data)
        for pos in rng.integers(lo, hi, size=int(rng.integers(1, 20))):
            arr[pos] ^= 1 << int(rng.integers(0, 8))
        return bytes(arr)
    if kind == "non_utf8":
        arr = bytearray(data)
        for pos in sorted(rng.integers(lo, hi, size=int(rng.integers(1, 10))).tolist(), reverse=True):
            arr[pos:pos] = bytes(rng.choice([0x80, 0xC3, 0xFE, 0xFF, 0x00, 0xE9], size=int(rng.integers(1, 4))).tolist())
        return bytes(arr)
    if kind == "nan_coordinates":
        return _coordinates(data, rng, rng.choice([b"NaN", b"nan", b"inf", b"-INF", b"1.#QNAN"]), 0.05)
    if kind == "huge_coordinates":
        return _coordinates(data, rng, rng.choice([b"1.E300", b"-1.E300", b"1.E308", b"9.9E307"]), 0.05)
    raise ValueError(f"kind: unknown mutation {kind!r}")
