"""The lecture's m x n parameter mesh: m values of u, n of v, equal divisions."""

from __future__ import annotations

import numpy as np

from .. import checks
from ..surface import Surface, require_surface
from .polymesh import Mesh


def grid_faces(m: int, n: int, quads: bool = False) -> np.ndarray:
    """Faces of an ``m x n`` vertex grid (row-major, vertex ``i*n + j``), counter-clockwise
    in (u, v) so that they face along ``Su x Sv``."""
    i, j = np.meshgrid(np.arange(m - 1), np.arange(n - 1), indexing="ij")
    a = (i * n + j).ravel()
    b, c, d = a + n, a + n + 1, a + 1
    if quads:
        return np.stack([a, b, c, d], axis=1)
    return np.concatenate([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)])


def mesh(s: Surface, m: int, n: int, *, quads: bool = False, max_points: int = checks.MAX_POINTS) -> Mesh:
    """The m x n grid mesh of ``s``: vertices ``S(u_i, v_j)`` with ``m`` equally spaced
    values of u and ``n`` of v; faces are triangles (``quads=True`` keeps the quads).
    Meshes of more than ``max_points`` vertices (default ``checks.MAX_POINTS``, ten
    million) are refused before any work; pass a larger ``max_points`` to allow one.

    >>> import surfmod as sm
    >>> msh = sm.mesh(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), 3, 4)
    >>> msh.vertices.shape, msh.faces.shape
    ((12, 3), (12, 3))
    """
    s = require_surface(s, "s")
    max_points = checks.count(max_points, "max_points")
    m = checks.count(m, "m", minimum=2, maximum=max_points)
    n = checks.count(n, "n", minimum=2, maximum=max_points)
    checks.work(m * n, max_points, "max_points", f"the {m} x {n} grid mesh")
    (u0, u1), (v0, v1) = s.domain
    pts = s.grid(np.linspace(u0, u1, m), np.linspace(v0, v1, n), max_points=max_points)
    return Mesh(pts.reshape(-1, 3), grid_faces(m, n, quads), {"kind": "grid", "m": m, "n": n})
