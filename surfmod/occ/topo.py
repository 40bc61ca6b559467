"""Faces, edges and shapes: from ``Geom_*`` objects to build123d topology and back."""

from __future__ import annotations

from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace
from OCP.TopoDS import TopoDS

from ..errors import SurfmodError
from .guard import check_done, kernel

FACE_TOLERANCE = 1e-7


def face_from_surface(surf, u0, u1, v0, v1):
    """A build123d ``Face`` bounded by the parameter rectangle."""
    import build123d as bd

    with kernel("BRepBuilderAPI_MakeFace"):
        maker = BRepBuilderAPI_MakeFace(surf, u0, u1, v0, v1, FACE_TOLERANCE)
        check_done(maker, "BRepBuilderAPI_MakeFace")
        return bd.Face(maker.Face())


def edge_from_curve(curve, t0, t1):
    """A build123d ``Edge`` over ``[t0, t1]``."""
    import build123d as bd

    with kernel("BRepBuilderAPI_MakeEdge"):
        maker = BRepBuilderAPI_MakeEdge(curve, t0, t1)
        check_done(maker, "BRepBuilderAPI_MakeEdge")
        return bd.Edge(maker.Edge())


def wrapped(obj):
    """The ``TopoDS_Shape`` inside a build123d object, the shape itself, or None."""
    from OCP.TopoDS import TopoDS_Shape

    shape = getattr(obj, "wrapped", obj)
    return shape if isinstance(shape, TopoDS_Shape) else None


def _single(obj, kind: str):
    """The ``TopoDS_Shape`` of a build123d or OCP ``kind`` ("Face", "Edge"), else SurfmodError."""
    from OCP import TopAbs

    shape = wrapped(obj)
    if shape is None or shape.IsNull() or shape.ShapeType() != getattr(TopAbs, f"TopAbs_{kind.upper()}"):
        raise SurfmodError(f"{kind.lower()}: expected a build123d {kind} or TopoDS_{kind}, got {type(obj).__name__}")
    return shape


def face_surface(face):
    """``(Geom_Surface, (u0, u1, v0, v1), reversed)`` of a build123d or OCP face."""
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import TopAbs_REVERSED

    shape = _single(face, "Face")
    with kernel("BRep_Tool.Surface_s"):
        f = TopoDS.Face_s(shape)
        surf = BRep_Tool.Surface_s(f)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(f)
        return surf, (u0, u1, v0, v1), f.Orientation() == TopAbs_REVERSED


def curve_of_edge(edge):
    """``(Geom_Curve, t0, t1)`` of a build123d or OCP edge."""
    shape = _single(edge, "Edge")
    with kernel("BRep_Tool.Curve_s"):
        e = TopoDS.Edge_s(shape)
        curve = BRep_Tool.Curve_s(e, 0.0, 0.0)  # located copy; OCP returns only the curve
        if curve is None:
            raise SurfmodError("edge: has no 3-D curve")
        t0, t1 = BRep_Tool.Range_s(e)
        return curve, t0, t1


def faces_of(shape):
    """All faces of a shape (build123d object or TopoDS_Shape), in exploration order."""
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    shp = wrapped(shape)
    if shp is None:
        raise SurfmodError(f"shape: expected a build123d shape or TopoDS_Shape, got {type(shape).__name__}")
    out = []
    explorer = TopExp_Explorer(shp, TopAbs_FACE)
    while explorer.More():
        out.append(TopoDS.Face_s(explorer.Current()))
        explorer.Next()
    return out


def shape_bspline(shape):
    """The exact B-spline form of an edge's or a wire's 3-D curve (wires are joined
    edge by edge with ``GeomConvert_CompCurveToBSplineCurve``)."""
    from OCP.Geom import Geom_TrimmedCurve
    from OCP.GeomConvert import GeomConvert, GeomConvert_CompCurveToBSplineCurve
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_WIRE
    from OCP.BRepTools import BRepTools_WireExplorer

    s = wrapped(shape)
    if s is None or s.IsNull() or s.ShapeType() not in (TopAbs_EDGE, TopAbs_WIRE):
        raise SurfmodError(f"expected a build123d Edge or Wire, got {type(shape).__name__}")
    if s.ShapeType() == TopAbs_EDGE:
        edges = [TopoDS.Edge_s(s)]
    else:
        edges = []
        explorer = BRepTools_WireExplorer(TopoDS.Wire_s(s))
        while explorer.More():
            edges.append(explorer.Current())
            explorer.Next()
    with kernel("GeomConvert (edge to B-spline)"):
        joined = None
        for e in edges:
            curve, t0, t1 = curve_of_edge(e)
            piece = GeomConvert.CurveToBSplineCurve_s(Geom_TrimmedCurve(curve, t0, t1))
            from OCP.TopAbs import TopAbs_REVERSED

            if e.Orientation() == TopAbs_REVERSED:
                piece.Reverse()
            if joined is None:
                joined = GeomConvert_CompCurveToBSplineCurve(piece)
            elif not joined.Add(piece, 1e-6, True):
                raise SurfmodError("wire: edges are not connected end to end")
        return joined.BSplineCurve()
