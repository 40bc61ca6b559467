"""``Mesh``: the plain vertex/face container shared by meshing, subdivision and export."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import checks, pictures
from ..errors import SurfmodError
from .closure import edge_uses


@dataclass(frozen=True)
class Mesh:
    """Vertices ``(V, 3)`` float and faces ``(F, k)`` int (triangles k=3 or quads k=4).

    ``info`` carries measured facts about how the mesh was made (e.g. the measured
    chordal deviation of a tessellation).

    >>> import surfmod as sm
    >>> m = sm.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> float(m.area)
    0.5
    """

    vertices: np.ndarray
    faces: np.ndarray
    info: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        v = checks.finite_array(self.vertices, "vertices", ndim=2, last=3)
        try:
            f = np.asarray(self.faces)
        except (TypeError, ValueError):
            raise SurfmodError("faces: expected an integer array (F, 3) or (F, 4)") from None
        if f.ndim != 2 or f.shape[1] not in (3, 4) or (f.size and not np.issubdtype(f.dtype, np.integer)):
            raise SurfmodError(f"faces: expected an integer array (F, 3) or (F, 4), got shape {f.shape}")
        if f.size and (f.min() < 0 or f.max() >= len(v)):
            raise SurfmodError(f"faces: vertex index out of range 0..{len(v) - 1}")
        object.__setattr__(self, "vertices", checks.frozen(v))
        fi = np.array(f, dtype=np.int64, copy=True)
        fi.setflags(write=False)
        object.__setattr__(self, "faces", fi)

    def _repr_png_(self) -> bytes | None:
        """A shaded picture for Jupyter (see :func:`surfmod.meshing.render.png_bytes`)."""
        return pictures.repr_png(self)

    def triangles(self) -> np.ndarray:
        """Faces as triangles (quads split along their 0-2 diagonal)."""
        if self.faces.shape[1] == 3:
            return self.faces
        f = self.faces
        return np.concatenate([f[:, [0, 1, 2]], f[:, [0, 2, 3]]])

    def triangulated(self) -> Mesh:
        return Mesh(self.vertices, self.triangles(), dict(self.info))

    @property
    def area(self) -> float:
        t = self.vertices[self.triangles()]
        return float(np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum() / 2)

    def edge_use(self) -> tuple[bool, bool]:
        """``(watertight, winding_consistent)`` of the triangles as indexed: every edge is
        shared by exactly two triangles, and each shared edge runs opposite ways in its
        two (trimesh's ``is_watertight`` and ``is_winding_consistent`` without loading
        trimesh, whose import costs a command a second).

        >>> import surfmod as sm
        >>> tet = sm.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        >>> tet.edge_use(), Mesh(tet.vertices, tet.faces[:3]).edge_use()
        ((True, True), (False, True))
        >>> Mesh(tet.vertices, [[0, 1, 2], [0, 1, 3], [0, 3, 2], [1, 2, 3]]).edge_use()
        (True, False)
        """
        tri = self.triangles()
        if not len(tri):
            return False, False
        _, counts, forward = edge_uses(tri)
        shared = counts == 2
        return bool(shared.all()), bool((forward[shared] == 1).all())

    def to_trimesh(self):
        """A ``trimesh.Trimesh`` (no processing, so vertex order is kept)."""
        import trimesh

        return trimesh.Trimesh(self.vertices, self.triangles(), process=False)


def weld(vertices: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Merge vertices with identical coordinates and drop the triangles that collapse:
    ``(vertices, triangles, kept)``, ``kept`` the mask of the triangles left.

    BRepMesh repeats the nodes of a shared edge in every face's triangulation, bit for
    bit, so exact equality is the right test (no distance threshold to choose).

    >>> v, t, kept = weld(np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0]]),
    ...                   np.array([[0, 1, 2], [3, 4, 2], [1, 3, 0]]))
    >>> len(v), t.tolist(), kept.tolist()
    (4, [[0, 2, 1], [2, 3, 1]], [True, True, False])
    """
    # np.unique(axis=0)'s result (rows in lexicographic order) at half its cost: one
    # lexsort, then a new vertex wherever a sorted row differs from the one before
    order = np.lexsort(vertices.T[::-1])
    rows = vertices[order]
    new = np.ones(len(rows), bool)
    new[1:] = np.any(rows[1:] != rows[:-1], axis=1)
    inverse = np.empty(len(rows), np.int64)
    inverse[order] = np.cumsum(new) - 1
    unique = rows[new]
    tri = inverse[triangles]
    keep = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    return unique, tri[keep], keep
