"""Catmull–Clark subdivision of polygon meshes (:func:`catmull_clark`; vectorized, boundaries
and sharp creases).  After one step the mesh is all quads; new vertices are numbered vertex
points first, then edge points (in the order of :attr:`Topology.edges`), then face points.
See :doc:`/guide/surfaces` (section "Subdivision and its limit surface").
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..meshing.polymesh import Mesh
from . import topology as tp


def catmull_clark(vertices, faces, levels: int = 1, *, creases=None) -> Mesh:
    """Catmull–Clark subdivision, ``levels`` times; returns an all-quad :class:`~surfmod.Mesh`.

    ``faces`` is an ``(F, k)`` index array or a list of index lists (mixed polygons);
    ``creases`` an optional ``(N, 2)`` list of vertex pairs (edges of the cage) that stay
    sharp.  Boundary edges follow the cubic B-spline curve rules.

    >>> import surfmod as sm
    >>> cube_v = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    >>> cube_f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    >>> m = sm.catmull_clark(cube_v, cube_f, levels=2)
    >>> m.vertices.shape, m.faces.shape
    ((98, 3), (96, 4))
    """
    v, topo = tp.polygon_mesh(vertices, faces)
    n = tp.levels_arg(levels, len(topo.corners))
    sharp = tp.crease_flags(topo, creases)
    if n == 0:
        if np.all(topo.sizes == topo.sizes[0]) and topo.sizes[0] in (3, 4):
            return Mesh(v, topo.corners.reshape(-1, topo.sizes[0]), {"levels": 0})
        raise SurfmodError("levels: 0 levels of a mixed-polygon cage cannot be returned as a Mesh; use levels >= 1")
    for _ in range(n):
        v, topo, sharp = step(v, topo, sharp)
    return Mesh(v, topo.quads(), {"levels": n, "scheme": "catmull-clark"})


def _vertex_sharpness(topo: tp.Topology, sharp_edges: np.ndarray):
    """Per vertex: number of sharp edges, and the sharp edges themselves."""
    e = topo.edges[sharp_edges]
    count = np.bincount(e.ravel(), minlength=topo.n_vertices)
    return count, e


def step(v: np.ndarray, topo: tp.Topology, crease: np.ndarray):
    """One Catmull–Clark step on trusted data: ``(vertices, topology, crease flags)``."""
    nv, ne, nf = topo.n_vertices, topo.n_edges, topo.n_faces
    corners, face_of = topo.corners, topo.face_of
    sharp = crease | topo.boundary

    # face points
    fsum = np.zeros((nf, 3))
    np.add.at(fsum, face_of, v[corners])
    fp = fsum / topo.sizes[:, None]

    # edge points
    a, b = topo.edges[:, 0], topo.edges[:, 1]
    mid = 0.5 * (v[a] + v[b])
    efs = np.zeros((ne, 3))
    np.add.at(efs, topo.edge_of, fp[face_of])
    smooth_ep = 0.25 * (v[a] + v[b]) + 0.25 * efs  # two faces on a smooth edge
    ep = np.where(sharp[:, None], mid, smooth_ep)

    # vertex points
    valence = topo.valence().astype(float)
    nfaces = topo.faces_at().astype(float)
    q = np.zeros((nv, 3))
    np.add.at(q, corners, fp[face_of])
    q /= nfaces[:, None]
    r = np.zeros((nv, 3))
    np.add.at(r, a, mid)
    np.add.at(r, b, mid)
    r /= valence[:, None]
    vp = (q + 2.0 * r + (valence - 3.0)[:, None] * v) / valence[:, None]

    n_sharp, se = _vertex_sharpness(topo, sharp)
    n_sharp[topo.faces_at() == 1] = 3  # a boundary vertex of a single face is a corner
    other = np.zeros((nv, 3))
    np.add.at(other, se[:, 0], v[se[:, 1]])
    np.add.at(other, se[:, 1], v[se[:, 0]])
    curve = (n_sharp == 2)[:, None]
    corner = (n_sharp > 2)[:, None]
    vp = np.where(curve, 0.75 * v + 0.125 * other, vp)
    vp = np.where(corner, v, vp)

    new_v = np.concatenate([vp, ep, fp])
    # one quad per corner: [v_j, e_j, f, e_(j-1)]
    quads = np.stack(
        [corners, nv + topo.edge_of, nv + ne + face_of, nv + topo.edge_of[topo.prv]], axis=1
    ).ravel()
    new_topo = tp.build(len(new_v), quads, np.full(len(corners), 4))
    # creases split into two halves (a, e) and (e, b)
    new_crease = np.zeros(new_topo.n_edges, dtype=bool)
    if np.any(crease):
        ids = np.flatnonzero(crease)
        halves = np.concatenate(
            [np.stack([topo.edges[ids, 0], nv + ids], 1), np.stack([topo.edges[ids, 1], nv + ids], 1)]
        )
        new_crease = tp.crease_flags(new_topo, halves)
    return new_v, new_topo, new_crease
