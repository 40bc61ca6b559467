"""Loop subdivision of triangle meshes (:func:`loop_subdivide`; vectorized, with boundary
rules, Loop's or Warren's ``beta``).  New vertices: vertex points first, then edge points
in the order of :attr:`Topology.edges`.
See :doc:`/guide/surfaces` (section "Subdivision and its limit surface").
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..meshing.polymesh import Mesh
from . import topology as tp


def loop_beta(valence, rule: str = "loop") -> np.ndarray:
    """The Loop vertex weight ``beta(n)`` (``rule`` ``"loop"`` or ``"warren"``).

    >>> from surfmod.subdiv.loop import loop_beta
    >>> float(loop_beta(6)) == 1 / 16, float(loop_beta(3, "warren"))
    (True, 0.1875)
    """
    n = np.maximum(np.asarray(valence, dtype=float), 1.0)
    if rule == "loop":
        return (5.0 / 8.0 - (3.0 / 8.0 + 0.25 * np.cos(2.0 * np.pi / n)) ** 2) / n
    if rule == "warren":
        return np.where(n == 3, 3.0 / 16.0, 3.0 / (8.0 * n))
    raise SurfmodError(f"beta: expected 'loop' or 'warren', got {rule!r}")


def loop_subdivide(vertices, triangles, levels: int = 1, *, beta: str = "loop") -> Mesh:
    """Loop subdivision of a triangle mesh, ``levels`` times; returns a triangle ``Mesh``.

    >>> import surfmod as sm
    >>> tet_v = [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)]
    >>> tet_f = [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]
    >>> m = sm.loop_subdivide(tet_v, tet_f, levels=2)
    >>> m.vertices.shape, m.faces.shape
    ((34, 3), (64, 3))
    """
    v, topo = tp.polygon_mesh(vertices, triangles, faces_name="triangles", face_size=3)
    if beta not in ("loop", "warren"):
        raise SurfmodError(f"beta: expected 'loop' or 'warren', got {beta!r}")
    n = tp.levels_arg(levels, 4 * topo.n_faces // 1)
    for _ in range(n):
        v, topo = step(v, topo, beta)
    return Mesh(v, topo.corners.reshape(-1, 3), {"levels": n, "scheme": "loop", "beta": beta})


def step(v: np.ndarray, topo: tp.Topology, beta: str = "loop"):
    """One Loop step on trusted data: ``(vertices, topology)``."""
    nv, ne = topo.n_vertices, topo.n_edges
    corners, nxt = topo.corners, topo.nxt
    bnd = topo.boundary
    a, b = topo.edges[:, 0], topo.edges[:, 1]

    opp = np.zeros((ne, 3))
    np.add.at(opp, topo.edge_of, v[corners[nxt[nxt]]])
    ep = np.where(bnd[:, None], 0.5 * (v[a] + v[b]), 0.375 * (v[a] + v[b]) + 0.125 * opp)

    valence = topo.valence()
    nsum = np.zeros((nv, 3))
    np.add.at(nsum, a, v[b])
    np.add.at(nsum, b, v[a])
    w = loop_beta(valence, beta)
    vp = (1.0 - valence * w)[:, None] * v + w[:, None] * nsum

    be = topo.edges[bnd]
    bsum = np.zeros((nv, 3))
    np.add.at(bsum, be[:, 0], v[be[:, 1]])
    np.add.at(bsum, be[:, 1], v[be[:, 0]])
    nb = np.bincount(be.ravel(), minlength=nv)
    vp = np.where((nb == 2)[:, None], 0.75 * v + 0.125 * bsum, vp)
    corner = (nb > 2) | (topo.faces_at() == 1)  # non-manifold boundary vertex or single triangle
    vp = np.where(corner[:, None], v, vp)

    tri = corners.reshape(-1, 3)
    e = nv + topo.edge_of.reshape(-1, 3)  # e[:, j] is on edge tri[:, j] -> tri[:, j+1]
    new = np.stack(
        [
            np.stack([tri[:, 0], e[:, 0], e[:, 2]], 1),
            np.stack([tri[:, 1], e[:, 1], e[:, 0]], 1),
            np.stack([tri[:, 2], e[:, 2], e[:, 1]], 1),
            e,
        ],
        axis=1,
    ).reshape(-1)
    new_v = np.concatenate([vp, ep])
    return new_v, tp.build(len(new_v), new, np.full(len(new) // 3, 3))
