"""OCCT side of the manipulation operations (issue 6): transforms, segments, trimmed faces,
intersections, projections and hidden-line outlines.

These are the kernel twins of :mod:`surfmod.ops`; the NumPy implementations are checked
against them.  Loops here are plain per-item OCCT calls (reference side, not an
evaluation path).
"""

from __future__ import annotations

import math

import numpy as np
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_GTrsf, gp_Lin, gp_Mat, gp_Pnt, gp_Trsf, gp_XYZ

from ..errors import SurfmodError
from . import arrays
from .geom import downcast_surface
from .guard import check_done, kernel
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.BRepLib import BRepLib
from OCP.GCE2d import GCE2d_MakeSegment
from OCP.GCPnts import GCPnts_AbscissaPoint
from OCP.GProp import GProp_GProps
from OCP.Geom import Geom_Line, Geom_Plane, Geom_RectangularTrimmedSurface
from OCP.Geom2d import Geom2d_BSplineCurve
from OCP.GeomAPI import GeomAPI_IntCS, GeomAPI_IntSS, GeomAPI_ProjectPointOnSurf
from OCP.GeomAdaptor import GeomAdaptor_Curve
from OCP.HLRAlgo import HLRAlgo_Projector
from OCP.HLRBRep import HLRBRep_Algo, HLRBRep_HLRToShape
from OCP.ShapeFix import ShapeFix_Face
from OCP.TColgp import TColgp_Array1OfPnt2d
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Pnt2d
from .sample import distances_to_face

# -- transforms ---------------------------------------------------------------------------


def named_trsf(kind: str, *args) -> gp_Trsf:
    """An OCCT ``gp_Trsf`` built with its own named setters (independent of surfmod's matrices).

    ``kind``: ``"translation" (vector)``, ``"rotation" (origin, direction, degrees)``,
    ``"mirror" (point, normal)`` (plane symmetry), ``"scale" (center, factor)``.

    >>> named_trsf("translation", (1, 2, 3)).TranslationPart().Coord()
    (1.0, 2.0, 3.0)
    >>> named_trsf("shear", (1, 0, 0))
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: kind: expected translation, rotation, mirror or scale, got 'shear'
    """
    t = gp_Trsf()
    with kernel(f"gp_Trsf ({kind})"):
        if kind == "translation":
            t.SetTranslation(arrays.vec(args[0]))
        elif kind == "rotation":
            o, d, deg = args
            t.SetRotation(gp_Ax1(arrays.pnt(o), gp_Dir(*map(float, d))), math.radians(deg))
        elif kind == "mirror":
            p, n = args
            t.SetMirror(gp_Ax2(arrays.pnt(p), gp_Dir(*map(float, n))))
        elif kind == "scale":
            c, f = args
            t.SetScale(arrays.pnt(c), float(f))
        else:
            raise SurfmodError(f"kind: expected translation, rotation, mirror or scale, got {kind!r}")
    return t


def trsf_matrix(t: gp_Trsf) -> np.ndarray:
    """The 4x4 matrix of a ``gp_Trsf`` (as OCCT applies it to points)."""
    m = np.eye(4)
    for i in range(3):
        for j in range(4):
            m[i, j] = t.Value(i + 1, j + 1)
    return m


def geom_transformed(surf, t: gp_Trsf):
    """``surf.Transformed(t)`` downcast to its concrete ``Geom_*`` class."""
    with kernel("Geom_Surface.Transformed"):
        return downcast_surface(surf.Transformed(t))


def geom_gtransformed(surf, matrix):
    """A general affine map (``gp_GTrsf``, e.g. non-uniform scale) applied to the poles of a
    ``Geom_BSplineSurface`` / ``Geom_BezierSurface`` copy (weights unchanged)."""
    m = np.asarray(matrix, dtype=float)
    g = gp_GTrsf()
    with kernel("gp_GTrsf"):
        g.SetVectorialPart(gp_Mat(*map(float, m[:3, :3].ravel())))
        g.SetTranslationPart(gp_XYZ(*map(float, m[:3, 3])))
        out = downcast_surface(surf.Copy())
        for i in range(1, out.NbUPoles() + 1):
            for j in range(1, out.NbVPoles() + 1):
                xyz = out.Pole(i, j).XYZ()
                g.Transforms(xyz)
                out.SetPole(i, j, gp_Pnt(xyz))
    return out


# -- segmentation -------------------------------------------------------------------------


def segmented(surf, u0: float, u1: float, v0: float, v1: float):
    """A copy of a B-spline or Bézier ``surf`` cut down by OCCT's ``Segment``."""
    with kernel("Geom_BSplineSurface.Segment"):
        out = downcast_surface(surf.Copy())
        out.Segment(float(u0), float(u1), float(v0), float(v1))
    return out


# -- trimmed faces ------------------------------------------------------------------------


def _pcurves(loop):
    """``Geom2d`` curves for one loop: ``("polyline", (N, 2))`` (closed, last == first) gives
    one straight segment per side; ``("bspline", poles (N, 2), degree, flat knots, weights
    or None)`` one B-spline.

    (One C0 degree-1 B-spline for the whole polyline would be simpler, but
    ``BRepGProp`` integrates such an edge inaccurately: 3e-4 relative area error on a
    curved NURBS, where per-side segments agree with quadrature to 1e-11.)
    """
    if loop[0] == "polyline":
        pts = np.asarray(loop[1], dtype=float)
        return [
            GCE2d_MakeSegment(gp_Pnt2d(float(a[0]), float(a[1])), gp_Pnt2d(float(b[0]), float(b[1]))).Value()
            for a, b in zip(pts[:-1], pts[1:])
        ]
    _, p2, degree, knots, weights = loop
    poles = TColgp_Array1OfPnt2d(1, len(p2))
    for i, (x, y) in enumerate(np.asarray(p2, dtype=float), start=1):
        poles.SetValue(i, gp_Pnt2d(float(x), float(y)))
    k, mults = arrays.knots_and_mults(knots)
    if weights is None:
        return [Geom2d_BSplineCurve(poles, k, mults, int(degree), False)]
    return [Geom2d_BSplineCurve(poles, arrays.reals_1d(weights), k, mults, int(degree), False)]


def trimmed_face(surf, loops, tolerance: float = 1e-7):
    """A build123d ``Face`` on ``surf`` bounded by parameter-space loops (outer first, then
    holes; each already oriented: outer counter-clockwise, holes clockwise in (u, v)).

    Each loop is a wire of edges whose p-curves are the given 2-D curves; the 3-D curves are
    rebuilt from the p-curves with ``BRepLib.BuildCurves3d_s``.
    """
    import build123d as bd

    with kernel("trimmed face (BRepBuilderAPI_MakeFace with p-curve wires)"):
        wires = []
        for loop in loops:
            wire_maker = BRepBuilderAPI_MakeWire()
            for c2d in _pcurves(loop):
                edge_maker = BRepBuilderAPI_MakeEdge(c2d, surf, c2d.FirstParameter(), c2d.LastParameter())
                check_done(edge_maker, "BRepBuilderAPI_MakeEdge (p-curve)")
                wire_maker.Add(edge_maker.Edge())
            check_done(wire_maker, "BRepBuilderAPI_MakeWire")
            wires.append(wire_maker.Wire())
        face_maker = BRepBuilderAPI_MakeFace(surf, wires[0], True)
        check_done(face_maker, "BRepBuilderAPI_MakeFace")
        for w in wires[1:]:
            face_maker.Add(w)
        face = face_maker.Face()
        BRepLib.BuildCurves3d_s(face, tolerance)
        fixer = ShapeFix_Face(face)
        fixer.FixOrientation()
        face = fixer.Face()
    return bd.Face(face)


def face_area(face, eps: float = 1e-10) -> float:
    """Area of a face/shape by ``BRepGProp.SurfaceProperties_s`` at relative accuracy ``eps``."""
    props = GProp_GProps()
    with kernel("BRepGProp.SurfaceProperties_s"):
        BRepGProp.SurfaceProperties_s(getattr(face, "wrapped", face), props, eps, False)
        return float(props.Mass())


def face_is_valid(face) -> bool:
    """``BRepCheck_Analyzer`` verdict."""
    with kernel("BRepCheck_Analyzer"):
        return bool(BRepCheck_Analyzer(getattr(face, "wrapped", face)).IsValid())


# -- intersections ------------------------------------------------------------------------


def bounded(surf, bounds):
    """``Geom_RectangularTrimmedSurface`` over ``bounds = (u0, u1, v0, v1)``."""
    u0, u1, v0, v1 = map(float, bounds)
    with kernel("Geom_RectangularTrimmedSurface"):
        return Geom_RectangularTrimmedSurface(surf, u0, u1, v0, v1)


def infinite_plane(origin, normal):
    """``Geom_Plane`` through ``origin`` with ``normal``."""
    with kernel("Geom_Plane"):
        return Geom_Plane(arrays.pnt(origin), gp_Dir(*map(float, normal)))


def curve_length(curve, t0: float, t1: float, tol: float = 1e-10) -> float:
    """Arc length by ``GCPnts_AbscissaPoint.Length_s``."""
    with kernel("GCPnts_AbscissaPoint.Length_s"):
        return float(GCPnts_AbscissaPoint.Length_s(GeomAdaptor_Curve(curve, t0, t1), tol))


def sample_curve(curve, t0: float, t1: float, count: int) -> np.ndarray:
    """``count`` points equally spaced in parameter."""
    with kernel("Geom_Curve.Value"):
        return np.array([arrays.xyz(curve.Value(float(t))) for t in np.linspace(t0, t1, count)])


def intersect_surfaces(s1, s2, tolerance: float = 1e-7, samples: int = 200):
    """``GeomAPI_IntSS``: list of ``(points (samples, 3), length)`` per intersection curve."""
    out = []
    with kernel("GeomAPI_IntSS"):
        inter = GeomAPI_IntSS(s1, s2, float(tolerance))
        if not inter.IsDone():
            raise RuntimeError("GeomAPI_IntSS not done")
        for i in range(1, inter.NbLines() + 1):
            c = inter.Line(i)
            t0, t1 = c.FirstParameter(), c.LastParameter()
            out.append((sample_curve(c, t0, t1, samples), curve_length(c, t0, t1)))
    return out


def intersect_line(surf, origin, direction) -> np.ndarray:
    """``GeomAPI_IntCS`` of the line ``origin + w * unit(direction)``: ``(k, 3)`` rows ``(u, v, w)``."""
    with kernel("GeomAPI_IntCS"):
        line = Geom_Line(gp_Lin(arrays.pnt(origin), gp_Dir(*map(float, direction))))
        inter = GeomAPI_IntCS(line, surf)
        if not inter.IsDone():
            raise RuntimeError("GeomAPI_IntCS not done")
        rows = [inter.Parameters(i) for i in range(1, inter.NbPoints() + 1)]
    return np.array(rows, dtype=float).reshape(-1, 3)


def project_points(surf, bounds, points) -> np.ndarray:
    """``GeomAPI_ProjectPointOnSurf`` lower-distance solution per point: ``(N, 3)`` rows
    ``(u, v, distance)``; NaN where OCCT finds no orthogonal projection."""
    u0, u1, v0, v1 = map(float, bounds)
    out = np.full((len(points), 3), np.nan)
    with kernel("GeomAPI_ProjectPointOnSurf"):
        proj = GeomAPI_ProjectPointOnSurf()
        for a, q in enumerate(points):
            proj.Init(arrays.pnt(q), surf, u0, u1, v0, v1)
            if proj.NbPoints() > 0:
                u, v = proj.LowerDistanceParameters()
                out[a] = (u, v, proj.LowerDistance())
    return out


def face_distances(face, points) -> np.ndarray:
    """Distance from each point to a face (``BRepExtrema_DistShapeShape``), boundaries included."""
    return distances_to_face(getattr(face, "wrapped", face), np.asarray(points, dtype=float))


# -- hidden-line outlines -----------------------------------------------------------------


def hlr_outline(face, direction, samples_per_edge: int = 60):
    """Exact hidden-line removal (``HLRBRep_Algo``) of a face seen along ``direction``
    (parallel projection).  Returns ``(frame, {"outline": [...], "sharp": [...]})``: 2-D
    polylines in the projector frame ``frame = (origin, xdir, ydir)``; ``outline`` holds
    the silhouette (outline) edges, ``sharp`` the projected face boundary, visible and
    hidden alike."""
    d = np.asarray(direction, dtype=float)
    with kernel("HLRBRep_Algo"):
        ax = gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(*map(float, d)))
        frame = (np.zeros(3), arrays.xyz(ax.XDirection()), arrays.xyz(ax.YDirection()))
        algo = HLRBRep_Algo()
        algo.Add(getattr(face, "wrapped", face))
        algo.Projector(HLRAlgo_Projector(ax))
        algo.Update()
        algo.Hide()
        to_shape = HLRBRep_HLRToShape(algo)
        groups = {
            "outline": [to_shape.OutLineVCompound(), to_shape.OutLineHCompound()],
            "sharp": [to_shape.VCompound(), to_shape.HCompound()],
        }
        result = {}
        for key, shapes in groups.items():
            polylines = []
            for shape in shapes:
                if shape is None or shape.IsNull():
                    continue
                explorer = TopExp_Explorer(shape, TopAbs_EDGE)
                while explorer.More():
                    curve = BRepAdaptor_Curve(TopoDS.Edge_s(explorer.Current()))
                    ts = np.linspace(curve.FirstParameter(), curve.LastParameter(), samples_per_edge)
                    polylines.append(np.array([arrays.xyz(curve.Value(float(t)))[:2] for t in ts]))
                    explorer.Next()
            result[key] = polylines
    return frame, result
