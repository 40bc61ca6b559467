"""The verifier's walls: the stock as dexels along x and along y, swept by each tool along
every feed move, and the material they keep on the part's steep faces (see
:mod:`surfmod.cam.verify`).

Dexels are kept only in a band round what the height field sees steep (:func:`steep_band`,
:func:`band`); the sweep's work is counted before any move is swept (:func:`sweep_work`).
See :doc:`/guide/cam` (section "Every program verified before it leaves").
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy import ndimage
from scipy.spatial import cKDTree

#: material intervals a dexel holds; a cut that would split a full dexel leaves it whole
#: (more material, never less: the verdict can only be stricter) and is counted
SEGMENTS = 8
#: the least slope (degrees) of the part under a stock point the dexels judge (the height
#: field judges below ``verify.WALL_SLOPE``: the two overlap)
DEXEL_SLOPE = 70.0
#: part points the local plane through the foot of a stock point is fitted to
PLANE_POINTS = 8
#: a normal facing down by more than this share is under an overhang
OVERHANG = 0.02


@njit(cache=True)
def _cut(seg, cnt, j, k, a, b):
    """Remove ``[a, b]`` from dexel ``(j, k)``'s intervals; True when a split did not fit."""
    n = cnt[j, k]
    full = False
    i = 0
    while i < n:
        s, e = seg[j, k, i, 0], seg[j, k, i, 1]
        if e <= a or s >= b:
            i += 1
        elif s >= a and e <= b:  # wholly inside: the last interval takes its place
            n -= 1
            seg[j, k, i, 0], seg[j, k, i, 1] = seg[j, k, n, 0], seg[j, k, n, 1]
        elif s < a and e > b:
            if n == seg.shape[2]:
                full = True
            else:
                seg[j, k, i, 1] = a
                seg[j, k, n, 0], seg[j, k, n, 1] = b, e
                n += 1
            i += 1
        else:
            if s < a:
                seg[j, k, i, 1] = a
            else:
                seg[j, k, i, 0] = b
            i += 1
    cnt[j, k] = n
    return full


@njit(cache=True)
def _capsule_chord(ax, ay, bx, by, radius, line):
    """The chord ``[lo, hi]`` of the capsule of ``radius`` round the segment A-B (in the
    dexels' plane: along, across) on the line ``across = line``; ``lo > hi`` when missed."""
    lo, hi = np.inf, -np.inf
    for px, py in ((ax, ay), (bx, by)):
        d = line - py
        if abs(d) < radius:
            w = math.sqrt(radius * radius - d * d)
            lo, hi = min(lo, px - w), max(hi, px + w)
    dx, dy = bx - ax, by - ay
    length = math.sqrt(dx * dx + dy * dy)
    if length == 0.0:
        return lo, hi
    # the strip of half-width R along the segment, between the normals at its ends
    s0, s1 = -np.inf, np.inf
    cross = dx * (line - ay)
    if dy != 0.0:
        u, v = ax + (cross - radius * length) / dy, ax + (cross + radius * length) / dy
        s0, s1 = max(s0, min(u, v)), min(s1, max(u, v))
    elif abs(cross) > radius * length:
        return lo, hi
    along = dy * (line - ay)
    if dx != 0.0:
        u, v = ax - along / dx, ax + (length * length - along) / dx
        s0, s1 = max(s0, min(u, v)), min(s1, max(u, v))
    elif not 0.0 <= along <= length * length:
        return lo, hi
    if s0 <= s1:
        lo, hi = min(lo, s0), max(hi, s1)
    return lo, hi


@njit(cache=True)
def sweep_dexels(seg, cnt, kbot, ktop, l0, z0, cell, starts, ends, rapid, radii, corners, step):
    """Run the feed moves (``starts``/``ends`` as (along, across, z)) through the dexels
    ``seg`` (n_across, n_levels, SEGMENTS, 2) with ``cnt`` intervals each, in order (see
    the module); a line's dexels outside its levels ``kbot[j]..ktop[j]`` are not kept.
    Returns how many cuts found a dexel full."""
    nl, nz = cnt.shape
    full = 0
    for m in range(starts.shape[0]):
        if rapid[m]:
            continue
        ax, ay, az = starts[m, 0], starts[m, 1], starts[m, 2]
        bx, by, bz = ends[m, 0], ends[m, 1], ends[m, 2]
        radius, corner = radii[m], corners[m]
        column = max(az, bz) + corner  # above it the capsule is exact
        kc = max(int(math.ceil((column - z0) / cell - 0.5)), 0)
        j0 = max(int(math.ceil((min(ay, by) - radius - l0) / cell)), 0)
        j1 = min(int(math.floor((max(ay, by) + radius - l0) / cell)), nl - 1)
        for j in range(j0, j1 + 1):
            lo, hi = _capsule_chord(ax, ay, bx, by, radius, l0 + j * cell)
            if lo < hi:
                for k in range(max(kc, kbot[j]), min(ktop[j] + 1, nz)):
                    if cnt[j, k]:
                        full += _cut(seg, cnt, j, k, lo, hi)
        # the band below the column: stamps along the move
        k0 = max(int(math.ceil((min(az, bz) - z0) / cell - 0.5)), 0)
        if k0 >= min(kc, nz):
            continue
        length = math.sqrt((bx - ax) ** 2 + (by - ay) ** 2 + (bz - az) ** 2)
        pieces = max(1, int(math.ceil(length / step)))
        for s in range(pieces + 1):
            t = s / pieces
            cx, cy, cz = ax + t * (bx - ax), ay + t * (by - ay), az + t * (bz - az)
            ks = max(int(math.ceil((cz - z0) / cell - 0.5)), k0)
            for k in range(ks, min(kc, nz)):
                h = z0 + (k + 0.5) * cell - cz
                if h >= corner:
                    r = radius
                else:
                    r = radius - corner + math.sqrt(max(corner * corner - (corner - h) ** 2, 0.0))
                jj0 = max(int(math.ceil((cy - r - l0) / cell)), 0)
                jj1 = min(int(math.floor((cy + r - l0) / cell)), nl - 1)
                for j in range(jj0, jj1 + 1):
                    d = l0 + j * cell - cy
                    if cnt[j, k] and abs(d) < r:
                        w = math.sqrt(r * r - d * d)
                        full += _cut(seg, cnt, j, k, cx - w, cx + w)
    return full


@njit(cache=True)
def band(lines_at, zlo, zhi, z0, cell, nl, nz):
    """The dexels kept: on the lines within one of ``lines_at`` (in line units), the
    levels from ``zlo`` to ``zhi`` and one more each way (one entry per steep node)."""
    keep = np.zeros((nl, nz), np.bool_)
    for n in range(lines_at.shape[0]):
        k0 = max(int(math.floor((zlo[n] - z0) / cell - 0.5)) - 1, 0)
        k1 = min(int(math.ceil((zhi[n] - z0) / cell - 0.5)) + 1, nz - 1)
        c = int(math.floor(lines_at[n]))
        for j in range(max(c - 1, 0), min(c + 2, nl)):
            for k in range(k0, k1 + 1):
                keep[j, k] = True
    return keep


def steep_band(height: np.ndarray, origin, grid: float, table: float, slope: float):
    """The part's steep places as the height field sees them: ``(x, y, zlo, zhi)`` of every
    node of ``height`` (the part's top on a grid ``grid`` apart; -inf off the part, where
    the ``table`` stands) whose 3 x 3 neighbourhood rises by more than ``slope`` (degrees)
    over two cells, with the neighbourhood's lowest and highest part."""
    filled = np.where(np.isfinite(height), height, table)
    zlo = ndimage.minimum_filter(filled, size=3, mode="nearest")
    zhi = ndimage.maximum_filter(filled, size=3, mode="nearest")
    i, j = np.nonzero(zhi - zlo > 2.0 * grid * math.tan(math.radians(slope)))
    return origin[0] + i * grid, origin[1] + j * grid, zlo[i, j], zhi[i, j]


def sweep_work(starts, ends, rapid, radii, corners, l0: float, cell: float, step: float, kbot, ktop) -> float:
    """The dexel cuts one axis's sweep makes, at most, counted before it starts: per feed
    move the kept dexels of the lines its capsule crosses, and, where it crosses any, its
    stamps times the lines of a disc times the levels of the band below its column."""
    feed = ~np.asarray(rapid)
    a, b = starts[feed], ends[feed]
    r, c = radii[feed], corners[feed]
    nl = len(kbot)
    span = np.r_[0, np.cumsum(np.maximum(np.asarray(ktop) - np.asarray(kbot) + 1, 0))]
    j0 = np.clip(np.ceil((np.minimum(a[:, 1], b[:, 1]) - r - l0) / cell), 0, nl).astype(np.int64)
    j1 = np.clip(np.floor((np.maximum(a[:, 1], b[:, 1]) + r - l0) / cell) + 1, 0, nl).astype(np.int64)
    column = (span[np.maximum(j1, j0)] - span[j0]).astype(float)
    levels = np.abs(b[:, 2] - a[:, 2]) / cell + c / cell + 1
    stamps = np.linalg.norm(b - a, axis=1) / step + 1
    return float(column.sum() + np.sum(np.where(column > 0, stamps * (2 * r / cell + 1) * levels, 0.0)))


def wall_points(seg, cnt, a0: float, a1: float, l0: float, z0: float, cell: float, swap: bool) -> np.ndarray:
    """The ends of the dexels' intervals as points (x, y, z), the stock box's own faces
    (``a0``, ``a1`` along the dexels) left out: no tool touched them."""
    j, k, i = np.nonzero(np.arange(seg.shape[2])[None, None, :] < cnt[:, :, None])
    ends = seg[j, k, i].ravel()
    keep = (ends > a0 + 1e-9) & (ends < a1 - 1e-9)
    across = np.repeat(l0 + j * cell, 2)[keep]
    level = np.repeat(z0 + (k + 0.5) * cell, 2)[keep]
    along = ends[keep]
    return np.column_stack([across, along, level] if swap else [along, across, level])


def feet(tree: cKDTree, part_points: np.ndarray, q: np.ndarray, voxel: float = 0.0, far: float = np.inf):
    """For stock points ``q``: their distance to the part along its normal, the normal
    (pointing to ``q``) and the foot on the part, from the plane through the
    ``PLANE_POINTS`` nearest part points (never more than the nearest one's distance).

    A point farther than ``far`` from the part takes instead the ``PLANE_POINTS`` round the
    nearest of the part's points kept one per ``voxel`` cube: a point on a bore's axis is
    as far from a whole ring of points, all of which the tree visits (0.37 ms a query on
    NIST CTC-02 against 1.4 us beside a wall).  Its nearest then lies at most a voxel's
    diagonal farther than the exact one: the depth is judged more strictly, never less.

    Among equal distances (points on a grid) the tree and the coarse copy take the
    points in the order given: the verifier gives them in
    :class:`~surfmod.cam.verify.PartPoints`' order, a function of the points alone."""
    idx = np.empty((len(q), PLANE_POINTS), np.int64)
    dist = np.empty((len(q), PLANE_POINTS))
    away = np.zeros(len(q), bool)
    if voxel > 0 and np.isfinite(far) and len(q):
        # the first point in each voxel, the voxels numbered in the order of (i, j, k): one
        # integer each sorts several times faster than rows
        cube = np.floor(part_points / voxel).astype(np.int64)
        cube -= cube.min(axis=0)
        span = cube.max(axis=0) + 1
        if float(np.prod(span.astype(float))) < 2.0 ** 62:
            _, first = np.unique((cube[:, 0] * span[1] + cube[:, 1]) * span[2] + cube[:, 2], return_index=True)
        else:
            _, first = np.unique(cube, axis=0, return_index=True)
        d, k = cKDTree(part_points[first]).query(q)
        away = d > far
        # the patch round the nearest kept point: the tree's query at a point of it is local
        _, patch = tree.query(part_points[first[k[away]]], k=PLANE_POINTS)
        gap = np.linalg.norm(part_points[patch] - q[away, None, :], axis=2)
        order = np.argsort(gap, axis=1)
        idx[away], dist[away] = np.take_along_axis(patch, order, axis=1), np.take_along_axis(gap, order, axis=1)
    dist[~away], idx[~away] = tree.query(q[~away], k=PLANE_POINTS)
    near = part_points[idx]  # (M, k, 3)
    centre = near.mean(axis=1)
    d = near - centre[:, None, :]
    _, vecs = np.linalg.eigh(np.einsum("mki,mkj->mij", d, d))
    normal = vecs[:, :, 0]  # the least spread: across the surface
    off = np.einsum("mi,mi->m", q - centre, normal)
    normal *= np.where(off < 0, -1.0, 1.0)[:, None]
    off = np.abs(off)
    nearest = dist[:, 0]
    # a poor fit (an edge, a corner) is never believed beyond the nearest point
    use_plane = off < nearest
    depth = np.where(use_plane, off, nearest)
    chord = q - part_points[idx[:, 0]]
    toward = np.where(use_plane[:, None], normal, chord / np.maximum(nearest, 1e-300)[:, None])
    return depth, toward, q - depth[:, None] * toward


def tangent_tips(foot: np.ndarray, normal: np.ndarray, radius: float, corner: float) -> np.ndarray:
    """The tip of the tool (axis up) touching the part at ``foot`` with the normal
    ``normal``: its corner's centre ``corner`` along the normal, its axis ``R - c`` further
    across (the normal's horizontal direction)."""
    flat = np.hypot(normal[:, 0], normal[:, 1])
    across = normal[:, :2] / np.maximum(flat, 1e-300)[:, None]
    centre = foot + corner * normal
    tips = centre.copy()
    tips[:, :2] += (radius - corner) * across
    tips[:, 2] -= corner
    return tips


def steep_normals(normal: np.ndarray) -> np.ndarray:
    """Whether each normal lies on a face at least ``DEXEL_SLOPE`` steep and not under an
    overhang."""
    return (np.abs(normal[:, 2]) <= math.cos(math.radians(DEXEL_SLOPE))) & (normal[:, 2] >= -OVERHANG)

