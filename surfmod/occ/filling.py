"""OCCT's filling constructs (``GeomFill``, ``BRepOffsetAPI_MakeFilling``), used as the
reference beside surfmod's blends, fills and curve-network surfaces: the plate surface
through boundary edges (optionally tangent to support faces), the exact B-spline
conversion of a bounded surface, ``GeomFill_BSplineCurves`` (Coons style) and
build123d's Gordon surface (``Face.make_gordon_surface``), plus distances from curves to
a surface."""

from __future__ import annotations

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeFilling
from OCP.Geom import Geom_RectangularTrimmedSurface
from OCP.GeomAbs import GeomAbs_C0, GeomAbs_G1, GeomAbs_G2
from OCP.GeomConvert import GeomConvert
from OCP.GeomFill import GeomFill_BSplineCurves, GeomFill_FillingStyle
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopoDS import TopoDS

from ..errors import KernelError
from .geom import read_bspline_surface
from .guard import check_done, kernel
from .sample import distances_to_surface
from .topo import explore, wrapped


def bspline_over(geom, bounds) -> dict:
    """Exact B-spline data of ``geom`` restricted to ``bounds = (u0, u1, v0, v1)``
    (``GeomConvert`` on a ``Geom_RectangularTrimmedSurface``)."""
    u0, u1, v0, v1 = (float(x) for x in bounds)
    with kernel("GeomConvert.SurfaceToBSplineSurface_s"):
        trimmed = Geom_RectangularTrimmedSurface(geom, u0, u1, v0, v1)
        return read_bspline_surface(GeomConvert.SurfaceToBSplineSurface_s(trimmed))


def nearest_edge(face, point):
    """The edge of ``face`` whose midpoint is closest to ``point`` (a TopoDS_Edge)."""
    best, best_d = None, np.inf
    with kernel("BRepAdaptor_Curve"):
        for e in (TopoDS.Edge(x) for x in explore(wrapped(face), TopAbs_EDGE)):
            c = BRepAdaptor_Curve(e)
            p = c.Value(0.5 * (c.FirstParameter() + c.LastParameter()))
            d = float(np.linalg.norm(np.array([p.X(), p.Y(), p.Z()]) - point))
            if d < best_d:
                best, best_d = e, d
    return best


def make_filling(constraints, *, degree: int = 3, points_on_curve: int = 15, iterations: int = 2,
                 max_degree: int = 8, max_segments: int = 9):
    """``BRepOffsetAPI_MakeFilling`` through boundary ``constraints``: a list of
    ``(edge, support_face_or_None, order)`` with order ``"C0"``, ``"G1"`` or ``"G2"``
    (with ``"G2"`` OCCT's builder fails, "The continuity is not G0 G1 or G2", which the
    guard turns into ``KernelError``).  Returns the filling face (build123d ``Face``)."""
    import build123d as bd

    orders = {"C0": GeomAbs_C0, "G1": GeomAbs_G1, "G2": GeomAbs_G2}
    with kernel("BRepOffsetAPI_MakeFilling"):
        maker = BRepOffsetAPI_MakeFilling(degree, points_on_curve, iterations, False, 1e-5, 1e-5, 1e-4, 1e-2,
                                          max_degree, max_segments)
        for edge, face, order in constraints:
            e = TopoDS.Edge(wrapped(edge))
            if face is None:
                maker.Add(e, orders[order], True)
            else:
                maker.Add(e, TopoDS.Face(wrapped(face)), orders[order], True)
        maker.Build()
        check_done(maker, "BRepOffsetAPI_MakeFilling")
        return bd.Face(TopoDS.Face(maker.Shape()))


def bspline_curves_fill(c1, c2, c3, c4, style: str = "coons"):
    """``GeomFill_BSplineCurves(c1, c2, c3, c4, style)``: four ``Geom_BSplineCurve``
    handles forming a closed loop (OCCT arranges and orients them); returns the
    ``Geom_BSplineSurface``."""
    styles = {
        "coons": GeomFill_FillingStyle.GeomFill_CoonsStyle,
        "stretch": GeomFill_FillingStyle.GeomFill_StretchStyle,
        "curved": GeomFill_FillingStyle.GeomFill_CurvedStyle,
    }
    with kernel("GeomFill_BSplineCurves"):
        fill = GeomFill_BSplineCurves(c1, c2, c3, c4, styles[style])
        return fill.Surface()


def reversed_curve(curve):
    """OCCT's reversed copy of a ``Geom_BSplineCurve``."""
    with kernel("Geom_BSplineCurve.Reversed"):
        return curve.Reversed()


def gordon_face(profiles, guides, tolerance: float):
    """build123d's ``Face.make_gordon_surface`` (the ``ocp_gordon`` package) on the
    given build123d edges; raises ``KernelError`` when it fails."""
    import build123d as bd

    try:
        return bd.Face.make_gordon_surface(list(profiles), list(guides), tolerance=tolerance)
    except Exception as exc:  # ocp_gordon raises plain Python errors as well as OCCT ones
        raise KernelError(f"Face.make_gordon_surface: failed ({type(exc).__name__}: {exc})") from exc


def curve_to_surface_distances(surf, bounds, curve, samples: int) -> np.ndarray:
    """Distances from ``samples`` points along a ``Geom_Curve`` (uniform in its
    parameter) to a bounded ``Geom_Surface``, by OCCT point projection."""
    with kernel("Geom_Curve.Value"):
        t0, t1 = curve.FirstParameter(), curve.LastParameter()
        pts = np.array([curve.Value(float(t)).Coord() for t in np.linspace(t0, t1, samples)])
    return distances_to_surface(surf, pts, bounds)
