"""Cost of reading STEP files in the isolated reader process (``sm.import_step``) against
OCCT's ``STEPControl_Reader`` in the calling process, over the real-parts corpus.

The first isolated read pays the worker's start (interpreter plus OCCT import); after that
each read adds the coordinate check, the BinTools round trip and the pipe transfer.

``python -m benchmarks step``
"""

from __future__ import annotations

import time
from pathlib import Path

import surfmod as sm
from surfmod import inputs
from surfmod.occ.step import read_step

from .tables import Table, note

CORPUS = Path(__file__).resolve().parent.parent / "tests" / "data" / "step"


def main() -> None:
    files = sorted(p for p in CORPUS.glob("*") if p.suffix.lower() in (".step", ".stp"))
    if not files:
        print(f"no corpus at {CORPUS}")
        return
    inputs.stop_worker()
    t = time.perf_counter()
    sm.import_step(files[0])
    start = time.perf_counter() - t
    table = Table(("file", 44), ("MB", 6), ("in-process", 11), ("isolated", 9), ("overhead", 9), left_first=True)
    table.header()
    total_direct = total_isolated = 0.0
    for f in files:
        t = time.perf_counter()
        read_step(str(f))
        direct = time.perf_counter() - t
        t = time.perf_counter()
        sm.import_step(f)
        iso = time.perf_counter() - t
        total_direct += direct
        total_isolated += iso
        table.row(f.name[:44], f"{f.stat().st_size / 1e6:.2f}", f"{direct:.3f}s", f"{iso:.3f}s", f"{iso / direct:.2f}x")
    table.rule()
    table.row("corpus", "", f"{total_direct:.3f}s", f"{total_isolated:.3f}s", f"{total_isolated / total_direct:.2f}x")
    note(f"worker start (first read, once per process): {start:.2f}s")


if __name__ == "__main__":
    main()
