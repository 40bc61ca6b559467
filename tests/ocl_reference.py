"""OpenCAMLib as the reference for drop-cutter and waterline, run in its own process (its
C++ objects must outlive the calls that use them, and a crash there must not take the
test run down).  Triangles go over as ``.npy`` in float64 and are built with
``ocl.Triangle`` point by point, so both sides see the same numbers."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

#: the tests that ask OpenCAMLib skip, with the reason, where the bench extra is not installed
needs_opencamlib = pytest.mark.skipif(importlib.util.find_spec("opencamlib") is None,
                                      reason="OpenCAMLib is the bench extra (pip install -e '.[bench]')")

_PRELUDE = """
import sys, time, numpy as np, opencamlib as ocl
tri = np.load(sys.argv[1])
surf = ocl.STLSurf()
for t in tri:
    surf.addTriangle(ocl.Triangle(*(ocl.Point(float(x), float(y), float(z)) for x, y, z in t)))
kind, R, r = sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
length = 1000.0
cutter = {"ball": lambda: ocl.BallCutter(2 * R, length), "flat": lambda: ocl.CylCutter(2 * R, length),
          "bull": lambda: ocl.BullCutter(2 * R, r, length)}[kind]()
"""


def _run(code: str, tmp: Path, tri, kind, R, r, *extra) -> float:
    tri_path = tmp / "ocl_tri.npy"
    np.save(tri_path, np.asarray(tri, dtype=float))
    script = tmp / "ocl_run.py"
    script.write_text(_PRELUDE + textwrap.dedent(code))
    done = subprocess.run([sys.executable, str(script), str(tri_path), kind, repr(R), repr(r), *map(str, extra)],
                          capture_output=True, text=True, timeout=1800)
    if done.returncode != 0:
        raise RuntimeError(f"OpenCAMLib failed: {done.stderr[-2000:]}")
    return float(next(ln for ln in done.stdout.splitlines() if ln.startswith("OCLTIME")).split()[1])


def drop(tmp: Path, tri, kind: str, R: float, r: float, xy: np.ndarray, floor: float):
    """OCL's BatchDropCutter tip heights at ``xy`` (``floor`` where nothing is touched),
    and its run time (s, one thread)."""
    np.save(tmp / "ocl_xy.npy", np.asarray(xy, dtype=float))
    code = f"""
    xy = np.load({str(tmp / 'ocl_xy.npy')!r})
    bdc = ocl.BatchDropCutter(); bdc.setSTL(surf); bdc.setCutter(cutter); bdc.setThreads(1)
    for x, y in xy:
        bdc.appendPoint(ocl.CLPoint(float(x), float(y), {float(floor)!r}))
    t0 = time.perf_counter(); bdc.run(); dt = time.perf_counter() - t0
    np.save({str(tmp / 'ocl_z.npy')!r}, np.array([p.z for p in bdc.getCLPoints()]))
    print("OCLTIME", dt, flush=True)
    """
    dt = _run(code, tmp, tri, kind, R, r)
    return np.load(tmp / "ocl_z.npy"), dt


def waterline(tmp: Path, tri, kind: str, R: float, r: float, z: float, sampling: float):
    """OCL's Waterline loops at tip height ``z`` (list of (N, 3)) and its run time (s, one thread)."""
    code = f"""
    wl = ocl.Waterline(); wl.setSTL(surf); wl.setCutter(cutter); wl.setZ({float(z)!r})
    wl.setSampling({float(sampling)!r}); wl.setThreads(1)
    t0 = time.perf_counter(); wl.run(); dt = time.perf_counter() - t0
    loops = [np.array([[p.x, p.y, p.z] for p in loop]) for loop in wl.getLoops()]
    np.savez({str(tmp / 'ocl_wl.npz')!r}, *loops)
    print("OCLTIME", dt, flush=True)
    """
    dt = _run(code, tmp, tri, kind, R, r)
    with np.load(tmp / "ocl_wl.npz") as f:
        loops = [f[k] for k in sorted(f.files, key=lambda k: int(k.split("_")[1]))]
    return loops, dt


def polyline_distance(points: np.ndarray, loops: list[np.ndarray]) -> np.ndarray:
    """Distance in (x, y) of each point to the nearest closed loop's chords."""
    a = np.vstack([lp[:, :2] for lp in loops])
    b = np.vstack([np.roll(lp[:, :2], -1, axis=0) for lp in loops])
    out = np.full(len(points), np.inf)
    for chunk in np.array_split(np.arange(len(points)), max(1, len(points) * len(a) // 20_000_000 + 1)):
        p = points[chunk, None, :2]
        ab = b - a
        t = np.clip(((p - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0, 1)
        d = np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)
        out[chunk] = d.min(axis=1)
    return out


__all__ = ["drop", "waterline", "polyline_distance", "time"]
