"""Faces from surfaces (``BRepBuilderAPI_MakeFace``) trimmed by loops of p-curves."""

from __future__ import annotations

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
from OCP.BRepLib import BRepLib
from OCP.Geom2d import Geom2d_BSplineCurve
from OCP.gp import gp_Pnt2d
from OCP.ShapeFix import ShapeFix_Face

from . import arrays
from .guard import check_done, kernel
from .bindings import MakeSegment2d, TColgp_Array1OfPnt2d


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
            MakeSegment2d(gp_Pnt2d(float(a[0]), float(a[1])), gp_Pnt2d(float(b[0]), float(b[1]))).Value()
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
