"""Subdivision speed: surfmod's vectorized Loop and Catmull–Clark vs trimesh's Loop.

Loop: an icosphere (642 vertices) refined 1–4 levels with Loop's original weights (the
rule trimesh implements), timed against ``trimesh.remesh.subdivide_loop``; the vertex
sets of both results are compared (distance to the nearest vertex of the other).  Catmull–Clark: a cube cage
refined 1–6 levels, and the limit surface of the same cage as B-spline patches.

``python -m benchmarks subdiv``
"""

from __future__ import annotations

import time

import numpy as np
import trimesh
from trimesh.remesh import subdivide_loop

import surfmod as sm

from .tables import Table, note


def _time(fn, repeat: int = 3):
    best, out = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def _set_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance from a point of ``a`` to the nearest point of ``b`` (and back)."""
    from scipy.spatial import cKDTree

    return float(max(cKDTree(b).query(a)[0].max(), cKDTree(a).query(b)[0].max()))


def loop_rows():
    ico = trimesh.creation.icosphere(subdivisions=3)
    v, f = np.asarray(ico.vertices), np.asarray(ico.faces)
    for levels in range(1, 5):
        t_ours, ours = _time(lambda: sm.loop_subdivide(v, f, levels))
        t_tm, (tv, _) = _time(lambda: subdivide_loop(v, f, iterations=levels), 1 if levels > 3 else 3)
        dev = _set_distance(ours.vertices, np.asarray(tv))
        yield levels, len(ours.faces), t_ours, t_tm, dev


def catmull_clark_rows():
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    quads = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    for levels in range(1, 7):
        t, m = _time(lambda: sm.catmull_clark(v, quads, levels))
        yield levels, len(m.faces), t
    t, limit = _time(lambda: sm.limit_surface(v, quads), 1)
    yield "limit", len(limit.patches), t


def main() -> None:
    table = Table(("Loop", 14), ("triangles", 10), ("surfmod", 9), ("trimesh", 9), ("speed-up", 9), ("max |Δv|", 10),
                  left_first=True)
    table.header()
    for levels, nf, t, t_tm, dev in loop_rows():
        table.row(f"level {levels}", f"{nf}", f"{t:.4f}s", f"{t_tm:.4f}s", f"{t_tm / t:.1f}x", f"{dev:.1e}")
    note("icosphere with 642 vertices; max |Δv| compares the two vertex sets.")
    note()
    table = Table(("Catmull–Clark", 14), ("faces", 10), ("surfmod", 9), left_first=True)
    table.header()
    for levels, nf, t in catmull_clark_rows():
        label = "limit patches" if levels == "limit" else f"level {levels}"
        table.row(label, f"{nf}", f"{t:.4f}s")
    note("cube cage (8 vertices, 6 quads); 'limit patches' = sm.limit_surface, bicubic B-spline patches.")


if __name__ == "__main__":
    main()
