"""Faces, edges and shapes: from ``Geom_*`` objects to build123d topology and back."""

from __future__ import annotations

import numpy as np
from OCP import TopAbs
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepBuilderAPI import (BRepBuilderAPI_Copy, BRepBuilderAPI_GTransform, BRepBuilderAPI_MakeEdge,
                                BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeVertex, BRepBuilderAPI_Transform)
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepTools import BRepTools, BRepTools_WireExplorer
from OCP.Geom import Geom_TrimmedCurve
from OCP.GeomConvert import GeomConvert, GeomConvert_CompCurveToBSplineCurve
from OCP.gp import gp_GTrsf, gp_Mat, gp_Pnt, gp_Pnt2d, gp_XYZ
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_OUT, TopAbs_REVERSED, TopAbs_SHELL, TopAbs_SOLID, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Compound, TopoDS_Shape

from .. import transforms
from ..errors import SurfmodError
from .analytic import trsf
from .arrays import xyz, xyz_many
from .guard import check_done, kernel
from .bindings import IntTools_FClass2d, TopTools_IndexedDataMapOfShapeListOfShape, TopTools_ListOfShape

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
    shape = getattr(obj, "wrapped", obj)
    return shape if isinstance(shape, TopoDS_Shape) else None


def _single(obj, kind: str):
    """The ``TopoDS_Shape`` of a build123d or OCP ``kind`` ("Face", "Edge"), else SurfmodError."""
    shape = wrapped(obj)
    if shape is None or shape.IsNull() or shape.ShapeType() != getattr(TopAbs, f"TopAbs_{kind.upper()}"):
        raise SurfmodError(f"{kind.lower()}: expected a build123d {kind} or TopoDS_{kind}, got {type(obj).__name__}")
    return shape


def single_face(face):
    """The ``TopoDS_Face`` of a build123d or OCP face; anything else raises ``SurfmodError``."""
    return TopoDS.Face(_single(face, "Face"))


def face_surface(face):
    """``(Geom_Surface, (u0, u1, v0, v1), reversed)`` of a build123d or OCP face (the
    surface with the face's location applied)."""
    shape = _single(face, "Face")
    with kernel("BRep_Tool.Surface_s"):
        f = TopoDS.Face(shape)
        surf = BRep_Tool.Surface_s(f)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(f)
        return surf, (u0, u1, v0, v1), f.Orientation() == TopAbs_REVERSED


def curve_of_edge(edge):
    """``(Geom_Curve, t0, t1)`` of a build123d or OCP edge."""
    shape = _single(edge, "Edge")
    with kernel("BRep_Tool.Curve_s"):
        e = TopoDS.Edge(shape)
        curve = BRep_Tool.Curve_s(e, 0.0, 0.0)  # located copy; OCP returns only the curve
        if curve is None:
            raise SurfmodError("edge: has no 3-D curve")
        t0, t1 = BRep_Tool.Range_s(e)
        return curve, t0, t1


def explore(shape, kind, avoid=TopAbs.TopAbs_SHAPE):
    """Sub-shapes of one ``TopAbs`` kind, none inside an ``avoid``, in exploration order (repeats as OCCT)."""
    out = []
    explorer = TopExp_Explorer(shape, kind, avoid)
    while explorer.More():
        out.append(explorer.Current())
        explorer.Next()
    return out


def faces_of(shape):
    """All faces of a shape (build123d object or TopoDS_Shape), in exploration order."""
    shp = wrapped(shape)
    if shp is None:
        raise SurfmodError(f"shape: expected a build123d shape or TopoDS_Shape, got {type(shape).__name__}")
    return [TopoDS.Face(f) for f in explore(shp, TopAbs_FACE)]


def loose_faces(shape):
    """The faces of ``shape`` in no solid (loose faces, open shells), in exploration order."""
    return [TopoDS.Face(f) for f in explore(shape, TopAbs_FACE, TopAbs_SOLID)]


def solids_of(shape):
    return [TopoDS.Solid(s) for s in explore(shape, TopAbs_SOLID)]


def shells_of(shape):
    return [TopoDS.Shell(s) for s in explore(shape, TopAbs_SHELL)]


def transformed_face(face, matrix):
    """A face mapped by a 4x4 affine matrix: ``BRepBuilderAPI_Transform`` for
    similarities (the surface type is kept), ``BRepBuilderAPI_GTransform`` otherwise."""
    m = transforms.affine(matrix)
    shape = single_face(face)
    with kernel("BRepBuilderAPI_Transform"):
        if transforms.is_similarity(m) and np.linalg.det(m[:3, :3]) > 0:
            out = BRepBuilderAPI_Transform(shape, trsf(m), True).Shape()
        else:
            g = gp_GTrsf(gp_Mat(*map(float, m[:3, :3].ravel())), gp_XYZ(*map(float, m[:3, 3])))
            out = BRepBuilderAPI_GTransform(shape, g, True).Shape()
        return TopoDS.Face(out)


def classify_uv(face, u, v, tolerance=None):
    """Boolean array: ``(u[i], v[i])`` inside the face or on its boundary
    (``IntTools_FClass2d`` at ``tolerance``, default the face's own tolerance)."""
    f = single_face(face)
    with kernel("IntTools_FClass2d"):
        tol = BRep_Tool.Tolerance_s(f) if tolerance is None else float(tolerance)
        classifier = IntTools_FClass2d(f, tol)
        return np.array([classifier.Perform(gp_Pnt2d(float(a), float(b)), False) != TopAbs_OUT for a, b in zip(u, v)],
                        dtype=bool)


def closest_on_face(face, points):
    """``(distances (N,), points (N, 3))``: closest points on a trimmed face (or any
    shape of faces: shell, compound), boundary included (``BRepExtrema_DistShapeShape``)."""
    f = wrapped(face)
    if f is None or f.IsNull():
        raise SurfmodError(f"face: expected a build123d shape or TopoDS_Shape, got {type(face).__name__}")
    dist = np.empty(len(points))
    near = np.empty((len(points), 3))
    with kernel("BRepExtrema_DistShapeShape"):
        # BRepExtrema answers from a stored triangulation when the face has one: after a
        # coarse BRepMesh (10x a tolerance) it put a point inside a face's trim 0.0038 off
        # it, judging it outside by a hole's chords (test_occt_quirks).  A copy without the
        # mesh (geometry shared) is measured against the exact face.
        f = BRepBuilderAPI_Copy(f, False, False).Shape()
        ext = BRepExtrema_DistShapeShape()
        ext.LoadS1(f)
        for i, q in enumerate(points):
            ext.LoadS2(BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, q))).Vertex())
            ext.Perform()
            if not ext.IsDone() or ext.NbSolution() == 0:
                raise SurfmodError("s: OCCT found no closest point on the face")
            dist[i] = ext.Value()
            near[i] = xyz(ext.PointOnShape1(1))
    return dist, near


def face_wires_uv(face, samples: int):
    """The face's wires as ``(N, 2)`` arrays in ``(u, v)`` (outer wire first), each edge
    sampled at ``samples`` points of its p-curve in the wire's order."""
    f = single_face(face)
    out = []
    with kernel("BRepAdaptor_Curve2d (face wires)"):
        outer = BRepTools.OuterWire_s(f)
        wires = [TopoDS.Wire(w) for w in explore(f, TopAbs_WIRE)]
        wires.sort(key=lambda w: not w.IsSame(outer))
        for w in wires:
            pts = []
            ex = BRepTools_WireExplorer(w, f)
            while ex.More():
                edge = ex.Current()
                pc = BRepAdaptor_Curve2d(edge, f)
                t = np.linspace(pc.FirstParameter(), pc.LastParameter(), samples)
                if edge.Orientation() == TopAbs_REVERSED:
                    t = t[::-1]
                q = np.array([(p.X(), p.Y()) for p in (pc.Value(float(x)) for x in t)])
                pts.append(q if not pts else q[1:])
                ex.Next()
            if pts:
                out.append(np.concatenate(pts))
    return out


def shape_bspline(shape):
    """The exact B-spline form of an edge's or a wire's 3-D curve (wires are joined
    edge by edge with ``GeomConvert_CompCurveToBSplineCurve``)."""
    s = wrapped(shape)
    if s is None or s.IsNull() or s.ShapeType() not in (TopAbs_EDGE, TopAbs_WIRE):
        raise SurfmodError(f"expected a build123d Edge or Wire, got {type(shape).__name__}")
    if s.ShapeType() == TopAbs_EDGE:
        edges = [TopoDS.Edge(s)]
    else:
        edges = []
        explorer = BRepTools_WireExplorer(TopoDS.Wire(s))
        while explorer.More():
            edges.append(explorer.Current())
            explorer.Next()
    with kernel("GeomConvert (edge to B-spline)"):
        joined = None
        for e in edges:
            curve, t0, t1 = curve_of_edge(e)
            piece = GeomConvert.CurveToBSplineCurve_s(Geom_TrimmedCurve(curve, t0, t1))

            if e.Orientation() == TopAbs_REVERSED:
                piece.Reverse()
            if joined is None:
                joined = GeomConvert_CompCurveToBSplineCurve(piece)
            elif not joined.Add(piece, 1e-6, True):
                raise SurfmodError("wire: edges are not connected end to end")
        return joined.BSplineCurve()


def pcurve_points(edge, face, samples: int):
    """The parameters of ``samples`` equally spaced points of ``edge``'s p-curve on ``face``
    and their images on the face's surface, ``(t, (samples, 3) points)``: what an edge's
    3-D curve is measured against (``BRepCheck`` samples the same way)."""
    pc = BRepAdaptor_Curve2d(edge, face)
    surf = BRepAdaptor_Surface(face, False)
    t = np.linspace(pc.FirstParameter(), pc.LastParameter(), samples)
    value, at = surf.Value, pc.Value
    return t, xyz_many((value(*at(x).Coord()) for x in t.tolist()), samples)


def shape_list(shapes) -> list:
    """The items of a ``TopTools_ListOfShape`` as a Python list.  Not by iterating it:
    OCP's ``iter`` over one of two items costs about 190 µs (2000 times ``First``), which
    made a map of every edge's faces half of ``surfmod check``'s time on a 417-face part.

    >>> import build123d as bd
    >>> from surfmod.occ.bindings import TopTools_ListOfShape
    >>> faces, lst = bd.Box(1, 1, 1).faces()[:3], TopTools_ListOfShape()
    >>> for f in faces:
    ...     _ = lst.Append(f.wrapped)
    >>> [g.IsSame(f.wrapped) for g, f in zip(shape_list(lst), faces)]
    [True, True, True]
    """
    n = shapes.Size()
    if n <= 2:  # an edge's faces: nearly always two, one on a free edge
        return [shapes.First(), shapes.Last()][2 - n:] if n else []
    rest = TopTools_ListOfShape()
    rest.Assign(shapes)
    out = []
    while not rest.IsEmpty():
        out.append(rest.First())
        rest.RemoveFirst()
    return out


def geometric_edges(shape):
    """``(index, edge, faces)`` for every edge of ``shape`` that has a 3-D curve and is not
    degenerate: its index in ``TopExp``'s edge map (from 0) and the faces that hold it (a
    seam's face twice), the edges whose curves can be measured against their p-curves."""
    emap = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, emap)
    for k in range(1, emap.Extent() + 1):
        edge = TopoDS.Edge(emap.FindKey(k))
        if BRep_Tool.Degenerated_s(edge) or not BRep_Tool.IsGeometric_s(edge):
            continue
        yield k - 1, edge, [TopoDS.Face(f) for f in shape_list(emap.FindFromIndex(k))]


def compound(shapes):
    """One TopoDS_Compound of the given TopoDS shapes."""
    builder = BRep_Builder()
    comp = TopoDS_Compound()
    builder.MakeCompound(comp)
    for shape in shapes:
        builder.Add(comp, shape)
    return comp
