"""Polygon-mesh topology for subdivision: flat corner arrays, edges and half-edges.

A polygon mesh with mixed face sizes is kept as flat NumPy arrays (no per-face Python
objects): ``corners`` holds the vertex indices of all faces one after the other,
``face_of[c]`` the face of corner ``c`` and ``nxt[c]``/``prv[c]`` the next/previous corner
of the same face.  Corner ``c`` is also the *half-edge* from ``corners[c]`` to
``corners[nxt[c]]``.  Inputs are validated here once (:func:`polygon_mesh`), with
:class:`~surfmod.errors.SurfmodError` naming the argument.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import checks
from ..errors import SurfmodError

#: Largest number of faces a subdivision call may create (about 2 GB of vertex data).
MAX_FACES = 20_000_000


@dataclass(frozen=True)
class Topology:
    """Connectivity of a polygon mesh (all arrays are int64 unless noted)."""

    n_vertices: int
    corners: np.ndarray  # (C,) vertex index of each face corner
    face_of: np.ndarray  # (C,) face of each corner
    starts: np.ndarray  # (F,) first corner of each face
    sizes: np.ndarray  # (F,) number of corners of each face
    nxt: np.ndarray  # (C,) next corner of the same face
    prv: np.ndarray  # (C,) previous corner of the same face
    edge_of: np.ndarray  # (C,) undirected edge of half-edge c -> nxt[c]
    edges: np.ndarray  # (E, 2) vertex pairs, smaller index first
    edge_faces: np.ndarray  # (E,) number of faces using each edge (1 = boundary)

    @property
    def n_faces(self) -> int:
        return len(self.starts)

    @property
    def n_edges(self) -> int:
        return len(self.edges)

    @property
    def boundary(self) -> np.ndarray:
        """Boolean (E,): edges used by one face only."""
        return self.edge_faces == 1

    def valence(self) -> np.ndarray:
        """Number of edges at each vertex."""
        return np.bincount(self.edges.ravel(), minlength=self.n_vertices)

    def faces_at(self) -> np.ndarray:
        """Number of faces at each vertex."""
        return np.bincount(self.corners, minlength=self.n_vertices)

    def twin(self) -> np.ndarray:
        """Half-edge ``b -> a`` for every half-edge ``a -> b`` (-1 on the boundary).

        Only meaningful for consistently oriented meshes (see :func:`require_oriented`).
        """
        v = self.n_vertices
        a, b = self.corners, self.corners[self.nxt]
        key = a * v + b
        order = np.argsort(key, kind="stable")
        skey = key[order]
        want = b * v + a
        pos = np.clip(np.searchsorted(skey, want), 0, len(skey) - 1)
        found = skey[pos] == want
        return np.where(found, order[pos], -1)

    def quads(self) -> np.ndarray:
        """``(F, 4)`` face array (all faces must be quads)."""
        return self.corners.reshape(-1, 4)


def build(n_vertices: int, corners: np.ndarray, sizes: np.ndarray) -> Topology:
    """Connectivity from trusted flat data (faces valid, no repeated vertices)."""
    corners = np.asarray(corners, dtype=np.int64)
    sizes = np.asarray(sizes, dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    face_of = np.repeat(np.arange(len(sizes), dtype=np.int64), sizes)
    local = np.arange(len(corners), dtype=np.int64) - starts[face_of]
    nxt = starts[face_of] + (local + 1) % sizes[face_of]
    prv = starts[face_of] + (local - 1) % sizes[face_of]
    a, b = corners, corners[nxt]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    keys, edge_of, counts = np.unique(lo * n_vertices + hi, return_inverse=True, return_counts=True)
    edges = np.stack([keys // n_vertices, keys % n_vertices], axis=1)
    return Topology(n_vertices, corners, face_of, starts, sizes, nxt, prv, edge_of.ravel(), edges, counts)


def polygon_mesh(vertices, faces, *, vertices_name="vertices", faces_name="faces", face_size=None):
    """Validate a polygon mesh; returns ``(vertices (V, 3) float, Topology)``.

    ``faces`` is an ``(F, k)`` integer array or a list of index lists (mixed polygons).
    ``face_size`` (3 or 4) restricts every face to that many corners.  Refused with
    :class:`SurfmodError`: empty input, NaN/inf coordinates, faces with fewer than three
    corners or repeated vertices, out-of-range indices, unused vertices, and non-manifold
    cages (an edge shared by more than two faces, or faces at a vertex forming several fans).
    """
    v = checks.finite_array(vertices, vertices_name, ndim=2, last=3)
    if len(v) == 0:
        raise SurfmodError(f"{vertices_name}: the cage is empty (no vertices)")
    corners, sizes = _flatten_faces(faces, faces_name)
    if face_size is not None and np.any(sizes != face_size):
        bad = int(np.argmax(sizes != face_size))
        raise SurfmodError(f"{faces_name}: face {bad} has {sizes[bad]} corners, expected {face_size}")
    if np.any(sizes < 3):
        bad = int(np.argmax(sizes < 3))
        raise SurfmodError(f"{faces_name}: face {bad} has {sizes[bad]} corners, a face needs at least 3")
    if corners.min() < 0 or corners.max() >= len(v):
        bad = int(np.argmax((corners < 0) | (corners >= len(v))))
        raise SurfmodError(
            f"{faces_name}: vertex index {corners[bad]} out of range 0..{len(v) - 1}"
        )
    # repeated vertices inside a face: sort (face, vertex) pairs and look for neighbours
    face_of = np.repeat(np.arange(len(sizes)), sizes)
    order = np.lexsort((corners, face_of))
    dup = (np.diff(face_of[order]) == 0) & (np.diff(corners[order]) == 0)
    if np.any(dup):
        bad = int(face_of[order][:-1][dup][0])
        raise SurfmodError(f"{faces_name}: face {bad} repeats vertex {int(corners[order][:-1][dup][0])}")
    used = np.bincount(corners, minlength=len(v))
    if np.any(used == 0):
        raise SurfmodError(f"{vertices_name}: vertex {int(np.argmax(used == 0))} is used by no face")
    topo = build(len(v), corners, sizes)
    if np.any(topo.edge_faces > 2):
        e = int(np.argmax(topo.edge_faces > 2))
        a, b = topo.edges[e]
        raise SurfmodError(
            f"{faces_name}: non-manifold cage, edge {a}-{b} is shared by {topo.edge_faces[e]} faces (at most 2 allowed)"
        )
    fans = vertex_fans(topo)
    if np.any(fans > 1):
        bad = int(np.argmax(fans > 1))
        raise SurfmodError(
            f"{faces_name}: non-manifold cage, the faces at vertex {bad} form {fans[bad]} separate fans"
        )
    return v, topo


def vertex_fans(topo: Topology) -> np.ndarray:
    """Number of edge-connected fans of faces around each vertex (1 on a manifold)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    order = np.argsort(topo.edge_of, kind="stable")
    e_sorted = topo.edge_of[order]
    first = np.flatnonzero((np.diff(e_sorted) == 0))  # pairs (order[i], order[i+1]) share an edge
    h1, h2 = order[first], order[first + 1]
    links = []
    for end in (0, 1):
        vert = topo.edges[topo.edge_of[h1], end]
        c1 = np.where(topo.corners[h1] == vert, h1, topo.nxt[h1])
        c2 = np.where(topo.corners[h2] == vert, h2, topo.nxt[h2])
        links.append((c1, c2))
    rows = np.concatenate([a for a, _ in links])
    cols = np.concatenate([b for _, b in links])
    n = len(topo.corners)
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    # components never span two vertices: count distinct labels per vertex
    pairs = np.unique(np.stack([topo.corners, label], 1), axis=0)
    return np.bincount(pairs[:, 0], minlength=topo.n_vertices)


def _flatten_faces(faces, name):
    if faces is None:
        raise SurfmodError(f"{name}: the cage is empty (no faces)")
    if isinstance(faces, np.ndarray) and faces.dtype != object:
        arr = faces
        if arr.size == 0:
            raise SurfmodError(f"{name}: the cage is empty (no faces)")
        if arr.ndim != 2:
            raise SurfmodError(f"{name}: expected an (F, k) array or a list of index lists, got shape {arr.shape}")
        if not np.issubdtype(arr.dtype, np.integer):
            if not (np.issubdtype(arr.dtype, np.floating) and np.all(np.isfinite(arr)) and np.all(arr == np.round(arr))):
                raise SurfmodError(f"{name}: vertex indices must be integers")
        return arr.astype(np.int64).ravel(), np.full(arr.shape[0], arr.shape[1], dtype=np.int64)
    try:
        items = list(faces)
    except TypeError:
        raise SurfmodError(f"{name}: expected an (F, k) array or a list of index lists") from None
    if not items:
        raise SurfmodError(f"{name}: the cage is empty (no faces)")
    try:
        lists = [np.asarray(f).ravel() for f in items]
        sizes = np.array([len(f) for f in lists], dtype=np.int64)
        flat = np.concatenate(lists) if lists else np.zeros(0)
    except (TypeError, ValueError):
        raise SurfmodError(f"{name}: expected lists of vertex indices") from None
    if flat.size == 0:
        raise SurfmodError(f"{name}: the cage is empty (no faces)")
    if not np.issubdtype(flat.dtype, np.integer):
        try:
            f = flat.astype(float)
        except (TypeError, ValueError):
            raise SurfmodError(f"{name}: vertex indices must be integers") from None
        if not (np.all(np.isfinite(f)) and np.all(f == np.round(f))):
            raise SurfmodError(f"{name}: vertex indices must be integers")
        flat = f
    return flat.astype(np.int64), sizes


def levels_arg(levels, n_corners: int, growth: int = 4, name: str = "levels", minimum: int = 0) -> int:
    """Validate ``levels`` and refuse ones whose face count would exceed :data:`MAX_FACES`.

    One step turns ``n_corners`` corners into as many faces; every later step multiplies
    the face count by ``growth`` (4 for Catmull–Clark quads and Loop triangles).
    """
    n = checks.count(levels, name, minimum=minimum)
    if n == 0:
        return 0
    # compare in logs so that absurd levels (1e6) do not overflow
    est_log = np.log(max(n_corners, 1)) + (n - 1) * np.log(growth)
    if est_log > np.log(MAX_FACES):
        est = n_corners * float(growth) ** min(n - 1, 200)
        raise SurfmodError(
            f"{name}: {n} levels would create about {est:.3g} faces, above the limit of {MAX_FACES:,}; "
            "use fewer levels"
        )
    return n


def require_oriented(topo: Topology, name: str = "faces") -> np.ndarray:
    """The twin array; refuses meshes whose neighbouring faces disagree in orientation."""
    v = topo.n_vertices
    key = topo.corners * v + topo.corners[topo.nxt]
    uniq, counts = np.unique(key, return_counts=True)
    if np.any(counts > 1):
        k = int(uniq[np.argmax(counts > 1)])
        raise SurfmodError(
            f"{name}: faces are not consistently oriented (half-edge {k // v}->{k % v} is used twice)"
        )
    return topo.twin()


def crease_flags(topo: Topology, creases, name: str = "creases") -> np.ndarray:
    """Boolean (E,) flags of the sharp crease edges given as vertex pairs."""
    flags = np.zeros(topo.n_edges, dtype=bool)
    if creases is None:
        return flags
    try:
        c = np.asarray(creases)
    except (TypeError, ValueError):
        raise SurfmodError(f"{name}: expected an (N, 2) array of vertex index pairs") from None
    if c.size == 0:
        return flags
    if c.ndim != 2 or c.shape[1] != 2 or not np.issubdtype(c.dtype, np.integer):
        raise SurfmodError(f"{name}: expected an (N, 2) integer array of vertex index pairs, got shape {c.shape}")
    if c.min() < 0 or c.max() >= topo.n_vertices:
        raise SurfmodError(f"{name}: vertex index out of range 0..{topo.n_vertices - 1}")
    v = topo.n_vertices
    keys = np.minimum(c[:, 0], c[:, 1]) * v + np.maximum(c[:, 0], c[:, 1])
    ekeys = topo.edges[:, 0] * v + topo.edges[:, 1]
    pos = np.clip(np.searchsorted(ekeys, keys), 0, len(ekeys) - 1)
    found = ekeys[pos] == keys
    if not np.all(found):
        a, b = c[int(np.argmax(~found))]
        raise SurfmodError(f"{name}: {a}-{b} is not an edge of the cage")
    flags[pos] = True
    return flags
