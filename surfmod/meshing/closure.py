"""The judge of a written STL, independent of how it was meshed: the file read back (float32,
vertices joined where equal, as admesh and slicers join them), and every solid's triangles
closed, 2-manifold, consistently and outward oriented, without a degenerate facet.
See :doc:`/guide/meshing` (section "The STL read back before exit 0").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import KernelError, SurfmodError
from ..inputs import consistent_turns

#: binary STL: 80-byte header, uint32 count, then 50-byte records (io/stl.py writes them)
STL_RECORD = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])


def read_stl(path) -> np.ndarray:
    """The facets of an STL file (binary or ASCII) as float32 corners ``(T, 3, 3)``.

    >>> import os, tempfile
    >>> p = os.path.join(tempfile.mkdtemp(), "t.stl")
    >>> _ = open(p, "w").write("solid t\\n facet normal 0 0 1\\n  outer loop\\n   vertex 0 0 0\\n"
    ...                        "   vertex 1 0 0\\n   vertex 0 1 0\\n  endloop\\n endfacet\\nendsolid t\\n")
    >>> read_stl(p).tolist()
    [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]
    """
    with open(path, "rb") as fh:
        data = fh.read()
    if len(data) >= 84:
        (count,) = np.frombuffer(data, "<u4", 1, 80)
        if 84 + int(count) * STL_RECORD.itemsize == len(data):
            return np.frombuffer(data, STL_RECORD, int(count), 84)["v"].copy()
    words = data.split()
    at = [i for i, w in enumerate(words) if w == b"vertex"]
    if not data.lstrip().startswith(b"solid") or not at:
        raise SurfmodError(f"path: {path} is neither a binary nor an ASCII STL")
    try:
        corners = np.array([[float(words[i + k]) for k in (1, 2, 3)] for i in at], dtype=np.float32)
    except (ValueError, IndexError):
        raise SurfmodError(f"path: {path} has a vertex line that is not three numbers") from None
    if len(corners) % 3:
        raise SurfmodError(f"path: {path} has {len(corners)} vertex lines, not three per facet")
    return corners.reshape(-1, 3, 3)


@dataclass(frozen=True)
class Closure:
    """What one group of facets (a solid) is, read back: counts of ``open``,
    ``non_manifold`` and ``inconsistent`` edges and ``degenerate`` facets, the enclosed
    ``volume``, and ``faces``: the B-rep faces whose facets touch a bad edge (or are
    degenerate), sorted."""

    open: int
    non_manifold: int
    inconsistent: int
    degenerate: int
    volume: float
    faces: tuple

    @property
    def sound(self) -> bool:
        """Closed, 2-manifold, consistently outward, no degenerate facet."""
        return not (self.open or self.non_manifold or self.inconsistent or self.degenerate) and self.volume > 0

    def describe(self) -> str:
        """The problems in words (empty when sound)."""
        said = [f"{n} {what}" for n, what in ((self.open, "open edge(s)"), (self.non_manifold, "non-manifold edge(s)"),
                                             (self.inconsistent, "edge(s) joining facets of opposite orientation"),
                                             (self.degenerate, "degenerate facet(s)")) if n]
        if self.volume <= 0:
            said.append(f"enclosed volume {self.volume:.6g} (inside out or not closed)")
        if self.faces:
            shown = ", ".join(map(str, self.faces[:10])) + (" ..." if len(self.faces) > 10 else "")
            said.append(f"along face(s) {shown}")
        return "; ".join(said)


def edge_uses(tri: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The edges of triangles ``tri`` (``(T, 3)`` vertex indices), taken as the directed
    edges 0-1, 1-2, 2-0 of every triangle in turn: ``(inverse, counts, forward)``, the
    undirected edge of each directed one (``(3 T,)``) and per undirected edge how many
    triangles use it and how many of them run it from its lower vertex to its higher.

    >>> edge_uses(np.array([[0, 1, 2], [0, 2, 3]]))[1:]
    (array([1, 2, 1, 1, 1]), array([1., 1., 0., 1., 1.]))
    """
    directed = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    _, inverse, counts = np.unique(np.sort(directed, axis=1), axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    return inverse, counts, np.bincount(inverse, weights=directed[:, 0] < directed[:, 1], minlength=len(counts))


def closure(corners: np.ndarray, faces: np.ndarray | None = None) -> Closure:
    """Judge facets ``(T, 3, 3)`` as one closed solid; ``faces`` (``T`` ints) names the
    B-rep face of each facet.

    >>> box = np.array([[[0, 0, 0], [0, 1, 0], [1, 0, 0]], [[0, 0, 0], [1, 0, 0], [0, 0, 1]],
    ...                 [[0, 0, 0], [0, 0, 1], [0, 1, 0]], [[1, 0, 0], [0, 1, 0], [0, 0, 1]]], np.float32)
    >>> c = closure(box)   # a tetrahedron, outward
    >>> c.sound, c.volume
    (True, 0.16666666666666666)
    >>> closure(box[:3]).describe()
    '3 open edge(s); enclosed volume 0 (inside out or not closed)'
    >>> closure(box[:, ::-1]).describe()
    'enclosed volume -0.166667 (inside out or not closed)'
    """
    corners = np.asarray(corners, np.float32)
    flat = corners.reshape(-1, 3)
    _, index = np.unique(flat, axis=0, return_inverse=True)
    tri = index.reshape(-1, 3)
    degenerate = (tri[:, 0] == tri[:, 1]) | (tri[:, 1] == tri[:, 2]) | (tri[:, 0] == tri[:, 2])
    owner = np.tile(np.nonzero(~degenerate)[0], 3)
    inverse, counts, ways = edge_uses(tri[~degenerate])
    # per undirected edge met twice: the two uses must run opposite ways
    bad_edge = (counts == 1) | (counts > 2) | ((counts == 2) & (ways != 1))
    c = corners.astype(np.float64)
    volume = float(np.einsum("ij,ij->i", c[:, 0], np.cross(c[:, 1], c[:, 2])).sum() / 6.0)
    named: tuple = ()
    if faces is not None:
        faces = np.asarray(faces)
        hit = np.union1d(owner[bad_edge[inverse]], np.nonzero(degenerate)[0])
        named = tuple(int(f) for f in np.unique(faces[hit]))
    return Closure(open=int((counts == 1).sum()), non_manifold=int((counts > 2).sum()),
                   inconsistent=int(((counts == 2) & (ways != 1)).sum()), degenerate=int(degenerate.sum()),
                   volume=volume, faces=named)


def faces_against_neighbours(tri: np.ndarray, labels: np.ndarray) -> list[int]:
    """The faces to turn so that every face of one closed solid agrees with its
    neighbours, from the connectivity alone: ``tri`` its welded triangles ``(T, 3)``,
    ``labels`` the face of each.  Two faces disagree across an edge their triangles both
    run the same way; faces are turned (the fewer of two consistent colourings, counted
    in triangles) so none disagrees.  Empty when they already agree, or when no turning
    of whole faces makes them agree (a face at odds with itself, a non-manifold edge):
    the judge then names them.

    >>> tri = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])   # a tetrahedron
    >>> faces_against_neighbours(tri, np.arange(4))
    []
    >>> faces_against_neighbours(np.vstack([tri[:3], tri[3, ::-1]]), np.arange(4))
    [3]
    """
    tri = np.asarray(tri)
    labels = np.asarray(labels)
    inverse, counts, _ = edge_uses(tri)
    directed = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    owner = np.tile(labels, 3)
    if (counts > 2).any():
        return []
    order = np.argsort(inverse, kind="stable")
    pairs = order[counts[inverse[order]] == 2].reshape(-1, 2)  # the two uses of each edge met twice
    fa, fb = owner[pairs[:, 0]], owner[pairs[:, 1]]
    same_way = directed[pairs[:, 0], 0] == directed[pairs[:, 1], 0]
    if not same_way.any() or (same_way & (fa == fb)).any():
        return []  # all agree; or a face at odds with itself, which no turning of whole faces mends
    links = np.unique(np.stack([fa, fb, same_way.astype(int)], axis=1)[fa != fb], axis=0)
    return consistent_turns(links.tolist(), dict(zip(*np.unique(labels, return_counts=True))))


def judge_stl(path, groups: list) -> list[tuple[str, Closure]]:
    """The groups of the STL at ``path`` that are not sound, as ``(name, verdict)``.
    ``groups`` are ``(name, count, faces)`` in file order: ``count`` facets named
    ``name`` (e.g. ``"solid 2"``) that must close, ``faces`` their B-rep face indices;
    ``None`` for a name skips facets that make no such promise (faces in no closed
    shell).  A file that does not hold as many facets as the groups raises
    ``KernelError`` (the writer failed)."""
    corners = read_stl(path)
    total = sum(count for _, count, _ in groups)
    if total != len(corners):
        raise KernelError(f"STL writer: {len(corners)} facets read back from {path}, {total} written")
    failing, start = [], 0
    for name, count, faces in groups:
        if name is not None:
            verdict = closure(corners[start:start + count], faces)
            if not verdict.sound:
                failing.append((name, verdict))
        start += count
    return failing
