"""The path LinuxCNC's interpreter traces, compared with the polyline a job verified.

Written for the tests: it reads rs274's canonical commands (``STRAIGHT_TRAVERSE``,
``STRAIGHT_FEED``, ``ARC_FEED``) itself and measures exact distances to the arcs
(helices: Z linear in the angle), so a wrong centre, direction, sweep or Z of any
``G2``/``G3`` word shows as a distance, whatever surfmod's arc fitter believed.
"""

from __future__ import annotations

import math
import re

import numpy as np
from scipy.spatial import cKDTree

_CALL = re.compile(r"^\s*\d+\s+N\S*\s+([A-Z_]+)\((.*)\)\s*$")


def canonical(text: str):
    """``(ends (M, 3), arcs)``: the end point of every straight move and arc, in order,
    and each arc as ``(start (3,), end (3,), centre (2,), rotation)``."""
    ends, arcs, pos = [], [], None
    for line in text.splitlines():
        m = _CALL.match(line)
        if not m or m.group(1) not in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "ARC_FEED"):
            continue
        v = [float(x) for x in re.split(r"[,\s]+", m.group(2).strip()) if x]
        if m.group(1) == "ARC_FEED":
            end = np.array([v[0], v[1], v[5]])
            arcs.append((pos, end, np.array([v[2], v[3]]), int(v[4])))
        else:
            end = np.array(v[:3])
        ends.append(end)
        pos = end
    return np.array(ends), arcs


def _sweep(start, end, centre, rotation) -> tuple[float, float]:
    a0 = math.atan2(start[1] - centre[1], start[0] - centre[0])
    a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
    turns = abs(rotation) - 1
    if rotation > 0:
        sweep = (a1 - a0) % (2 * math.pi) or 2 * math.pi
        sweep += 2 * math.pi * turns
    else:
        sweep = -((a0 - a1) % (2 * math.pi) or 2 * math.pi) - 2 * math.pi * turns
    return a0, sweep


def arc_points(arc, n: int = 64) -> np.ndarray:
    """``n + 1`` points along an arc, its ends included."""
    start, end, centre, rotation = arc
    a0, sweep = _sweep(start, end, centre, rotation)
    r = math.hypot(start[0] - centre[0], start[1] - centre[1])
    t = np.linspace(0, 1, n + 1)
    return np.column_stack([centre[0] + r * np.cos(a0 + sweep * t), centre[1] + r * np.sin(a0 + sweep * t),
                            start[2] + (end[2] - start[2]) * t])


def _arc_distance(points: np.ndarray, arc) -> np.ndarray:
    """Distance of each point to the helix of ``arc`` (inf outside its sweep)."""
    start, end, centre, rotation = arc
    a0, sweep = _sweep(start, end, centre, rotation)
    r = math.hypot(start[0] - centre[0], start[1] - centre[1])
    rel = points[:, :2] - centre
    ang = np.arctan2(rel[:, 1], rel[:, 0]) - a0
    t = (ang % (2 * math.pi)) / sweep if sweep > 0 else -((-ang) % (2 * math.pi)) / sweep
    inside = (t >= -1e-9) & (t <= 1 + 1e-9)
    radial = np.hypot(rel[:, 0], rel[:, 1]) - r
    dz = points[:, 2] - (start[2] + (end[2] - start[2]) * np.clip(t, 0, 1))
    return np.where(inside, np.hypot(radial, dz), np.inf)


def off_path(points: np.ndarray, ends: np.ndarray, arcs) -> np.ndarray:
    """Distance of each of ``points`` to the traced path's end points or arcs (the
    nearer): a vertex of a polyline written as G1 must be an end point, one inside an
    arc must lie on that arc."""
    d, _ = cKDTree(ends).query(points)
    far = np.flatnonzero(d > 1e-9)
    for arc in arcs:
        if far.size:
            d[far] = np.minimum(d[far], _arc_distance(points[far], arc))
    return d


def polyline_distance(queries: np.ndarray, polyline: np.ndarray, k: int = 4) -> np.ndarray:
    """Distance of each query point to the polyline, through the segments beside its ``k``
    nearest vertices (exact where the polyline's segments are shorter than the spacing
    of those vertices, as along a sampled arc)."""
    _, idx = cKDTree(polyline).query(queries, k=k)
    best = np.full(len(queries), np.inf)
    for j in np.atleast_2d(idx.T):
        for a_i in (j - 1, j):
            a_i = np.clip(a_i, 0, len(polyline) - 2)
            a, b = polyline[a_i], polyline[a_i + 1]
            ab = b - a
            t = np.clip(((queries - a) * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-300), 0, 1)
            best = np.minimum(best, np.linalg.norm(queries - (a + t[:, None] * ab), axis=1))
    return best
