"""Tessellation of surfaces and shapes to a chordal tolerance."""

from __future__ import annotations

from .. import checks
from .polymesh import Mesh


def tessellate(obj, tolerance: float) -> Mesh:
    """Triangle mesh of a surfmod surface or a build123d shape within ``tolerance``.

    Faces of a shape share their boundary vertices, so a closed solid gives a
    watertight mesh.
    """
    from ..occ.exchange import triangulate
    from ..surface import Surface

    tolerance = checks.positive(tolerance, "tolerance")
    shape = obj.face().wrapped if isinstance(obj, Surface) else getattr(obj, "wrapped", obj)
    verts, tris = triangulate(shape, tolerance)
    return Mesh(verts, tris, {"kind": "brepmesh", "tolerance": tolerance})
