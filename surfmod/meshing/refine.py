"""Refining one face of a BRepMesh triangulation inside the face, its boundary kept, so the
shape's mesh stays watertight: cheaper than asking BRepMesh again for the whole shape.
See :doc:`/guide/meshing` (section "Meshing B-rep parts").
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

#: Refinement rounds per face before handing the face back to a finer BRepMesh pass.
ROUNDS = 6

# corner order of each triangle's edges: edge j joins corners j and j + 1 (mod 3)
_EDGE_CORNERS = np.array([[0, 1], [1, 2], [2, 0]])


def edge_table(tri: np.ndarray):
    """``(edge id per triangle side (T, 3), vertex pairs of each edge (E, 2), sides per edge (E,))``."""
    sides = np.sort(tri[:, _EDGE_CORNERS], axis=2).reshape(-1, 2).astype(np.int64)
    # one integer key per vertex pair: a 1-D unique, several times faster than axis=0
    base = int(sides.max(initial=0)) + 1
    keys, inverse, counts = np.unique(sides[:, 0] * base + sides[:, 1], return_inverse=True, return_counts=True)
    pairs = np.stack([keys // base, keys % base], axis=1)
    return inverse.reshape(len(tri), 3), pairs, counts


def _rotate(a: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Rows of ``a`` (T, 3) cyclically rotated left by ``r`` (T,): orientation is kept."""
    return a[np.arange(len(a))[:, None], (np.arange(3)[None, :] + r[:, None]) % 3]


def split_round(nodes, uv, tri, bad, evaluate):
    """One conforming refinement round of the triangles flagged ``bad``.

    ``evaluate(uv (M, 2)) -> (M, 3)`` gives surface points.  Returns ``(nodes, uv,
    triangles, new)`` with ``new`` flagging the triangles created in this round
    (the others are unchanged, in their previous order).

    >>> nodes = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    >>> tri = np.array([[0, 1, 2], [0, 2, 3]])
    >>> n, _, t, kept = split_round(nodes, nodes[:, :2], tri, np.array([True, False]),
    ...                            lambda q: np.c_[q, np.zeros(len(q))])
    >>> len(n), len(t), kept.tolist(), n[-1].tolist()
    (5, 4, [], [0.5, 0.5, 0.0])
    """
    side_edge, pairs, counts = edge_table(tri)
    interior = counts[side_edge] == 2
    ends = nodes[tri[:, _EDGE_CORNERS]]
    length = np.where(interior, np.linalg.norm(ends[:, :, 0] - ends[:, :, 1], axis=2), -1.0)
    longest = length.argmax(axis=1)
    splits = np.zeros(len(pairs), dtype=bool)
    by_edge = np.nonzero(bad & interior.any(axis=1))[0]
    splits[side_edge[by_edge, longest[by_edge]]] = True
    centroid = np.nonzero(bad & ~interior.any(axis=1))[0]

    # new nodes: edge midpoints then centroids, all on the surface at their (u, v)
    split_ids = np.nonzero(splits)[0]
    mid_uv = 0.5 * (uv[pairs[split_ids, 0]] + uv[pairs[split_ids, 1]])
    cen_uv = uv[tri[centroid]].mean(axis=1)
    new_uv = np.concatenate([mid_uv, cen_uv])
    new_nodes = evaluate(new_uv) if len(new_uv) else np.zeros((0, 3))
    mid_of_edge = np.full(len(pairs), -1)
    mid_of_edge[split_ids] = len(nodes) + np.arange(len(split_ids))
    cen_node = len(nodes) + len(split_ids) + np.arange(len(centroid))

    mids = mid_of_edge[side_edge]  # (T, 3): midpoint node of each side or -1
    k = (mids >= 0).sum(axis=1)
    keep = (k == 0)
    keep[centroid] = False
    children = []
    one = np.nonzero(k == 1)[0]  # bisect from the corner opposite the split side
    if one.size:
        r = (mids[one] >= 0).argmax(axis=1)
        v, m = _rotate(tri[one], r), _rotate(mids[one], r)
        children += [np.c_[v[:, 0], m[:, 0], v[:, 2]], np.c_[m[:, 0], v[:, 1], v[:, 2]]]
    two = np.nonzero(k == 2)[0]  # sides 0 and 1 split after rotation, side 2 (v2, v0) kept
    if two.size:
        r = ((mids[two] < 0).argmax(axis=1) + 1) % 3
        v, m = _rotate(tri[two], r), _rotate(mids[two], r)
        children += [np.c_[m[:, 0], v[:, 1], m[:, 1]], np.c_[v[:, 0], m[:, 0], m[:, 1]],
                     np.c_[v[:, 0], m[:, 1], v[:, 2]]]
    three = np.nonzero(k == 3)[0]
    if three.size:
        v, m = tri[three], mids[three]
        children += [np.c_[v[:, 0], m[:, 0], m[:, 2]], np.c_[m[:, 0], v[:, 1], m[:, 1]],
                     np.c_[m[:, 2], m[:, 1], v[:, 2]], np.c_[m[:, 0], m[:, 1], m[:, 2]]]
    if centroid.size:
        v, c = tri[centroid], cen_node
        children += [np.c_[v[:, 0], v[:, 1], c], np.c_[v[:, 1], v[:, 2], c], np.c_[v[:, 2], v[:, 0], c]]
    born = np.concatenate(children) if children else np.zeros((0, 3), dtype=tri.dtype)
    kept = np.nonzero(keep)[0]
    return np.concatenate([nodes, new_nodes]), np.concatenate([uv, new_uv]), np.concatenate([tri[kept], born]), kept


def refine_face(fm, tolerance: float, node_deviation: float, measure, evaluate, rounds: int = ROUNDS,
                measured: np.ndarray | None = None):
    """Refine the triangles of a :class:`~surfmod.meshing.facemesh.FaceMesh` (with (u, v) nodes)
    whose measured deviation exceeds ``tolerance + node_deviation`` (the face's share of
    the model's own error), boundary edges kept.

    ``measure(fm) -> per-triangle deviations`` measures a face mesh (``measured``: its
    result on ``fm`` when the caller has it already); ``evaluate(uv)`` gives surface
    points.  Returns ``(refined FaceMesh, per-triangle deviations)``, or
    ``None`` when ``rounds`` rounds do not bring every triangle within the bound (the
    deviation then sits on the boundary, which only a finer BRepMesh pass changes).
    """
    limit = tolerance + node_deviation
    nodes, uv, tri = fm.nodes, fm.uv, fm.triangles
    dev = measure(fm) if measured is None else measured
    for _ in range(rounds):
        bad = dev > limit
        if not bad.any():
            return replace(fm, nodes=nodes, uv=uv, triangles=tri), dev
        nodes, uv, tri, kept = split_round(nodes, uv, tri, bad, evaluate)
        born = replace(fm, nodes=nodes, uv=uv, triangles=tri[len(kept):])
        dev = np.concatenate([dev[kept], measure(born)])
    if (dev > limit).any():
        return None
    return replace(fm, nodes=nodes, uv=uv, triangles=tri), dev
