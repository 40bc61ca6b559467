"""Plane sections of shapes (``BRepAlgoAPI_Section``, edges chained into wires) and the
planar faces lying in a plane: the same concept as :mod:`surfmod.uses.section`, one level
down (that module turns these wires into section curves and areas)."""

from __future__ import annotations

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
from OCP.GeomAbs import GeomAbs_Plane
from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopoDS import TopoDS

from ..errors import SurfmodError
from .arrays import xyz
from .guard import kernel
from .topo import explore as _explore
from .topo import faces_of
from .bindings import TopTools_HSequenceOfShape


def _cut(shape, pln) -> list:
    """The edges of ``BRepAlgoAPI_Section`` of ``shape`` by the plane ``pln``;
    ``SurfmodError`` when OCCT fails."""
    with kernel("BRepAlgoAPI_Section"):
        op = BRepAlgoAPI_Section(shape, pln, False)
        op.Approximation(False)
        op.ComputePCurveOn1(False)
        op.Build()
        if not op.IsDone():
            raise SurfmodError("obj: OCCT could not section this shape")
        return _explore(op.Shape(), TopAbs_EDGE)


def section_edges(shape, origin, normal, skipped: dict | None = None):
    """Section of ``shape`` by a plane: a list of build123d ``Wire``s (edges chained
    end to end with ``ShapeAnalysis_FreeBounds``).

    When OCCT cannot section the whole shape and ``skipped`` is a dict, the shape is
    sectioned face by face (one Boolean a face): the faces OCCT cannot intersect go into
    ``skipped`` as ``{index: reason}`` and the others' curves are returned; without
    ``skipped``, or when no face can be sectioned, the failure is raised."""
    import build123d as bd

    pln = gp_Pln(gp_Pnt(*map(float, origin)), gp_Dir(*map(float, normal)))
    try:
        edges = _cut(shape, pln)
    except SurfmodError:
        if skipped is None:
            raise
        faces, edges, lost = faces_of(shape), [], {}
        for i, face in enumerate(faces):
            try:
                edges.extend(_cut(face, pln))
            except SurfmodError as exc:
                lost[i] = " ".join(str(exc).split())
        if len(lost) == len(faces):
            raise
        skipped.update(lost)
    if not edges:
        return []
    with kernel("ShapeAnalysis_FreeBounds (section wires)"):
        seq = TopTools_HSequenceOfShape()
        for e in edges:
            seq.Append(e)
        wires = TopTools_HSequenceOfShape()
        ShapeAnalysis_FreeBounds.ConnectEdgesToWires_s(seq, 1e-6, False, wires)
        return [bd.Wire(TopoDS.Wire(wires.Value(i))) for i in range(1, wires.Length() + 1)]


def planar_faces_on(shape, origin, normal, tol: float) -> list[int]:
    """Exploration indices of the planar faces of ``shape`` that lie in the plane
    ``(origin, normal)`` (parallel within 1e-9, offset within ``tol``): OCCT's plane of
    each face, with the face's location applied (``BRepAdaptor_Surface``)."""
    origin, normal = np.asarray(origin, dtype=float), np.asarray(normal, dtype=float)
    out = []
    with kernel("BRepAdaptor_Surface (planar faces)"):
        for i, face in enumerate(faces_of(shape)):
            adaptor = BRepAdaptor_Surface(face, False)
            if adaptor.GetType() != GeomAbs_Plane:
                continue
            ax = adaptor.Plane().Axis()
            z, o = xyz(ax.Direction()), xyz(ax.Location())
            if abs(abs(float(z @ normal)) - 1.0) < 1e-9 and abs(float((o - origin) @ normal)) < tol:
                out.append(i)
    return out
