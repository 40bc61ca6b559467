"""Polylines and triangle meshes as build123d shapes with a colour and a label
(``BRepBuilderAPI_MakePolygon``, ``BRepBuilderAPI_MakeFace``).

The OCP CAD Viewer (``ocp_vscode.show``) draws build123d shapes and walks the
``children`` of a compound as a tree, each node with its ``label`` and ``color``.  Tool
paths and meshes are plain arrays in surfmod; these builders turn them into such nodes:
a polyline into one wire (``BRepBuilderAPI_MakePolygon``), triangles into planar
triangle faces in one compound.  What a surfmod object is made of is decided above the
door (:mod:`surfmod.io.viewer`).

>>> import numpy as np
>>> w = polyline(np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]]), color="orange", label="path")
>>> (type(w).__name__, len(w.edges()), w.label)
('Wire', 2, 'path')
"""

from __future__ import annotations

import build123d as bd
import numpy as np
from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
from OCP.gp import gp_Pnt
from OCP.TopoDS import TopoDS_Compound

from ..errors import SurfmodError
from .guard import kernel

#: triangles one mesh may turn into faces: each costs about 30 us and 2 kB in OCCT
MAX_TRIANGLES = 200_000


def dress(shape, color=None, label: str | None = None):
    """``shape`` with its viewer ``color`` (a build123d ``Color`` argument) and ``label`` set
    where given."""
    if label is not None:
        shape.label = label
    if color is not None:
        shape.color = bd.Color(color)
    return shape


def as_shape(obj):
    """A build123d shape for ``obj``: build123d shapes as they are, OCCT shapes cast."""
    return obj if hasattr(obj, "wrapped") else bd.Shape.cast(obj)


def polyline(points: np.ndarray, *, color=None, label: str = "") -> bd.Wire | None:
    """One wire through ``points`` ``(N, 3)``, or None when fewer than two distinct points
    remain.  A point within OCCT's confusion distance (1e-7) of the one before it adds no
    edge: ``BRepBuilderAPI_MakePolygon`` skips it."""
    with kernel("BRepBuilderAPI_MakePolygon"):
        poly = _polygon(np.asarray(points, dtype=float).tolist())
        if not poly.IsDone():  # fewer than two distinct points
            return None
        wire = bd.Wire(poly.Wire())
    return dress(wire, color, label)


def _polygon(points: list, closed: bool = False) -> BRepBuilderAPI_MakePolygon:
    """OCCT's polygon through ``points`` (a list of ``(x, y, z)``), closed if asked."""
    poly = BRepBuilderAPI_MakePolygon()
    for x, y, z in points:
        poly.Add(gp_Pnt(x, y, z))
    if closed:
        poly.Close()
    return poly


def triangles(vertices: np.ndarray, faces: np.ndarray, *, color=None, label: str = "",
              max_triangles: int = MAX_TRIANGLES) -> bd.Compound:
    """The triangles ``faces`` ``(F, 3)`` (or quads ``(F, 4)``) over ``vertices`` as planar
    faces in one compound; degenerate ones are left out.  Raises ``SurfmodError`` naming
    ``max_triangles`` above it (the work is known before it starts)."""
    v = np.asarray(vertices, dtype=float)
    f = np.asarray(faces, dtype=np.int64)
    if len(f) > max_triangles:
        raise SurfmodError(f"max_triangles: the mesh has {len(f)} faces, above {max_triangles}; "
                           "pass a larger max_triangles or a coarser mesh")
    builder, out = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(out)
    with kernel("BRepBuilderAPI_MakeFace"):
        for corners in v[f].tolist():
            poly = _polygon(corners, closed=True)
            if not poly.IsDone():
                continue
            face = BRepBuilderAPI_MakeFace(poly.Wire(), True)
            if face.IsDone():
                builder.Add(out, face.Face())
    return dress(bd.Compound(out), color, label)


def group(children, *, color=None, label: str = "") -> bd.Compound:
    """A compound whose ``children`` are the given shapes (a node of the viewer's tree)."""
    return dress(bd.Compound(children=list(children)), color, label)
