"""Closed-form limit masks (:func:`catmull_clark_limit`, :func:`loop_limit`): where a
subdivision vertex ends up after infinitely many steps, and its tangents; the normal is
given (not NaN) only at smooth interior vertices.
See :doc:`/guide/surfaces` (section "Subdivision and its limit surface").
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import topology as tp
from .catmull_clark import step
from .loop import loop_beta


class LimitPoints(NamedTuple):
    """Limit positions ``(V, 3)``, unit normals ``(V, 3)`` and the two tangent vectors
    ``(V, 2, 3)`` of every cage vertex (NaN normals/tangents where the limit surface has
    no tangent plane given by the mask: boundary, crease and corner vertices).

    >>> import surfmod as sm, numpy as np
    >>> v = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    >>> quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    >>> lp = sm.catmull_clark_limit(v, quads)
    >>> lp.positions.shape, bool(np.allclose(np.abs(lp.positions), np.abs(lp.positions[0])))   # symmetric
    ((8, 3), True)
    """

    positions: np.ndarray
    normals: np.ndarray
    tangents: np.ndarray


def ring_index(topo: tp.Topology, twin: np.ndarray, interior: np.ndarray) -> np.ndarray:
    """Position ``i`` of every outgoing half-edge in the cyclic order around its vertex
    (``-1`` at vertices not in ``interior``).  Loops over the valence, not the vertices."""
    corners, prv = topo.corners, topo.prv
    c = len(corners)
    start = np.full(topo.n_vertices, -1, dtype=np.int64)
    start[corners[::-1]] = np.arange(c - 1, -1, -1)
    nfaces = topo.faces_at()
    idx = np.full(c, -1, dtype=np.int64)
    cur = start.copy()
    live = interior.copy()
    for i in range(int(nfaces.max())):
        live &= i < nfaces
        if not live.any():
            break
        idx[cur[live]] = i
        cur[live] = twin[prv[cur[live]]]
    return idx


def _interior_vertices(topo, sharp_edges):
    nsharp = np.bincount(topo.edges[sharp_edges].ravel(), minlength=topo.n_vertices)
    nsharp[topo.faces_at() == 1] = 3  # a boundary vertex of a single face is a corner
    bnd = np.bincount(topo.edges[topo.boundary].ravel(), minlength=topo.n_vertices) > 0
    return nsharp, ~bnd


def _curve_rules(v, topo, sharp_edges, pos, nsharp, tangents):
    se = topo.edges[sharp_edges]
    other = np.zeros_like(v)
    np.add.at(other, se[:, 0], v[se[:, 1]])
    np.add.at(other, se[:, 1], v[se[:, 0]])
    curve = nsharp == 2
    pos = np.where(curve[:, None], (other + 4.0 * v) / 6.0, pos)
    pos = np.where((nsharp > 2)[:, None], v, pos)
    tangents[nsharp >= 2] = np.nan
    # tangent of the B-spline curve, b - a, in the first slot at curve vertices
    if np.any(curve):
        diff = np.zeros_like(v)
        ends = np.zeros(topo.n_vertices, dtype=np.int64)
        # orient each curve vertex's two sharp edges: b - a = (second other) - (first other)
        first = np.full(topo.n_vertices, -1, dtype=np.int64)
        for col, oth in ((0, 1), (1, 0)):
            vv, oo = se[:, col], se[:, oth]
            unset = first[vv] < 0
            first[vv[unset]] = oo[unset]
        for col, oth in ((0, 1), (1, 0)):
            vv, oo = se[:, col], se[:, oth]
            sel = oo != first[vv]
            np.add.at(diff, vv[sel], v[oo[sel]] - v[first[vv[sel]]])
            np.add.at(ends, vv[sel], 1)
        ok = curve & (ends == 1)
        tangents[ok, 0] = diff[ok]
    return pos


def _normals(t):
    n = np.cross(t[:, 0], t[:, 1])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return n / norm


def catmull_clark_limit(vertices, faces, *, creases=None) -> LimitPoints:
    """Limit positions, normals and tangents of the cage vertices under Catmull–Clark.

    Cages with non-quad faces are subdivided once first (the vertex points keep their
    vertex's limit).  Tangents need consistently oriented faces around the vertex.

    >>> import surfmod as sm
    >>> cube_v = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    >>> cube_f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    >>> lim = sm.catmull_clark_limit(cube_v, cube_f)
    >>> lim.positions[0].round(6), lim.normals[0].round(6)
    (array([0.25, 0.25, 0.25]), array([-0.57735, -0.57735, -0.57735]))
    """
    v, topo = tp.polygon_mesh(vertices, faces)
    sharp = tp.crease_flags(topo, creases)
    n_orig = len(v)
    if np.any(topo.sizes != 4):
        v, topo, sharp = step(v, topo, sharp)
    out = cc_limit(v, topo, sharp)
    return LimitPoints(*(a[:n_orig] for a in out))


def cc_limit(v, topo, crease):
    sharp = crease | topo.boundary
    nsharp, interior = _interior_vertices(topo, sharp)
    corners, nxt = topo.corners, topo.nxt
    n = topo.valence().astype(float)
    esum = np.zeros_like(v)
    np.add.at(esum, topo.edges[:, 0], v[topo.edges[:, 1]])
    np.add.at(esum, topo.edges[:, 1], v[topo.edges[:, 0]])
    dsum = np.zeros_like(v)
    np.add.at(dsum, corners, v[corners[nxt[nxt]]])
    pos = (n[:, None] ** 2 * v + 4.0 * esum + dsum) / (n * (n + 5.0))[:, None]

    tangents = np.full((len(v), 2, 3), np.nan)
    key = corners * len(v) + corners[nxt]
    oriented = len(np.unique(key)) == len(key)
    if oriented:
        twin = topo.twin()
        smooth = interior & (nsharp < 2)
        idx = ring_index(topo, twin, smooth)
        h = np.flatnonzero(idx >= 0)
        vh = corners[h]
        nn = n[vh]
        th = 2.0 * np.pi * idx[h] / nn
        th1 = 2.0 * np.pi * (idx[h] + 1) / nn
        c2 = np.cos(2.0 * np.pi / nn)
        a_n = 1.0 + c2 + np.cos(np.pi / nn) * np.sqrt(2.0 * (9.0 + c2))
        e = v[corners[nxt[h]]]
        d = v[corners[nxt[nxt[h]]]]
        t = np.zeros((len(v), 2, 3))
        np.add.at(t[:, 0], vh, (a_n * np.cos(th))[:, None] * e + (np.cos(th) + np.cos(th1))[:, None] * d)
        np.add.at(t[:, 1], vh, (a_n * np.sin(th))[:, None] * e + (np.sin(th) + np.sin(th1))[:, None] * d)
        tangents[smooth] = t[smooth]
    pos = _curve_rules(v, topo, sharp, pos, nsharp, tangents)
    return pos, _normals(tangents), tangents


def loop_limit(vertices, triangles, *, beta: str = "loop") -> LimitPoints:
    """Limit positions, normals and tangents of the vertices of a triangle mesh under Loop.

    >>> import surfmod as sm
    >>> tet_v = [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)]
    >>> tet_f = [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]
    >>> sm.loop_limit(tet_v, tet_f).normals[0].round(6)
    array([0.57735, 0.57735, 0.57735])
    """
    v, topo = tp.polygon_mesh(vertices, triangles, faces_name="triangles", face_size=3)
    loop_beta(3, beta)  # validates the name
    sharp = topo.boundary
    nsharp, interior = _interior_vertices(topo, sharp)
    n = topo.valence().astype(float)
    esum = np.zeros_like(v)
    np.add.at(esum, topo.edges[:, 0], v[topo.edges[:, 1]])
    np.add.at(esum, topo.edges[:, 1], v[topo.edges[:, 0]])
    chi = 1.0 / (3.0 / (8.0 * loop_beta(n, beta)) + n)
    pos = (1.0 - n * chi)[:, None] * v + chi[:, None] * esum

    tangents = np.full((len(v), 2, 3), np.nan)
    corners, nxt = topo.corners, topo.nxt
    key = corners * len(v) + corners[nxt]
    if len(np.unique(key)) == len(key):
        idx = ring_index(topo, topo.twin(), interior)
        h = np.flatnonzero(idx >= 0)
        vh = corners[h]
        th = 2.0 * np.pi * idx[h] / n[vh]
        e = v[corners[nxt[h]]]
        t = np.zeros((len(v), 2, 3))
        np.add.at(t[:, 0], vh, np.cos(th)[:, None] * e)
        np.add.at(t[:, 1], vh, np.sin(th)[:, None] * e)
        tangents[interior] = t[interior]
    pos = _curve_rules(v, topo, sharp, pos, nsharp, tangents)
    return LimitPoints(pos, _normals(tangents), tangents)
